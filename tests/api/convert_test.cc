// The proto <-> planner edge: map decoding and validation, request
// validation, plan round trips and the JSON shape of plan.json.
#include "api/convert.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/assembly/builtin_planners.h"
#include "planner/boustrophedon/boustrophedon_planner.h"
#include "planner/engine/artifact_cache.h"
#include "planner/grid/grid.h"
#include "planner/oarp/oarp_planner.h"
#include "planner/stc/stc_planner.h"
#include "tests/testing/test_maps.h"

namespace covplan {
namespace {

using ::covplan::testing::AsciiToPgm;
using ::covplan::testing::RasterMap;
using ::covplan::testing::TwoRooms;
using ::testing::HasSubstr;

MATCHER_P2(StatusIs, code, substring, "") {
  const absl::Status& s = arg.status();
  if (s.code() != code) {
    *result_listener << "code " << absl::StatusCodeToString(s.code()) << ": " << s.message();
    return false;
  }
  if (std::string(s.message()).find(substring) == std::string::npos) {
    *result_listener << "message: " << s.message();
    return false;
  }
  return true;
}

v1::PlanRequest RequestWithTool(double tool) {
  v1::PlanRequest request;
  request.mutable_robot()->set_tool_width_m(tool);
  return request;
}

TEST(MapFromProtoTest, DecodesAsciiPgmWithRowsFlipped) {
  const std::string pgm = AsciiToPgm({"#..", "..."}, 2);
  absl::StatusOr<OccupancyMap> map = MapFromProto(RasterMap(pgm, 0.1), EngineLimits());
  ASSERT_TRUE(map.ok()) << map.status();
  EXPECT_EQ(map->width(), 6);
  EXPECT_EQ(map->height(), 4);
  EXPECT_DOUBLE_EQ(map->resolution(), 0.1);
  // Image top-left is occupied; map row 0 is the bottom, so it is the top row.
  EXPECT_EQ(map->at(3, 0), CellState::kOccupied);
  EXPECT_EQ(map->at(0, 0), CellState::kFree);
  EXPECT_EQ(map->CountFree(), 24 - 4);
}

TEST(MapFromProtoTest, YamlSuppliesResolutionAndOriginAndIgnoresImageKey) {
  v1::Map map;
  map.mutable_raster()->set_image(AsciiToPgm({"...", "..."}, 1));
  map.mutable_raster()->set_yaml(
      "image: does_not_exist.pgm\nresolution: 0.5\norigin: [1.0, -2.0, 0.0]\n"
      "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n");
  absl::StatusOr<OccupancyMap> decoded = MapFromProto(map, EngineLimits());
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  EXPECT_DOUBLE_EQ(decoded->resolution(), 0.5);
  EXPECT_DOUBLE_EQ(decoded->origin().x, 1.0);
  EXPECT_DOUBLE_EQ(decoded->origin().y, -2.0);
  // An explicit override wins over the YAML.
  map.mutable_raster()->set_resolution(0.25);
  decoded = MapFromProto(map, EngineLimits());
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  EXPECT_DOUBLE_EQ(decoded->resolution(), 0.25);
}

TEST(MapFromProtoTest, RejectsBadMapsWithUsefulMessages) {
  const std::string pgm = AsciiToPgm(TwoRooms(), 4);
  const EngineLimits limits;
  const auto kInvalid = absl::StatusCode::kInvalidArgument;
  EXPECT_THAT(MapFromProto(v1::Map(), limits), StatusIs(kInvalid, "no source"));
  EXPECT_THAT(MapFromProto(RasterMap("", 0.1), limits), StatusIs(kInvalid, "empty"));
  EXPECT_THAT(MapFromProto(RasterMap(pgm, 0.0), limits), StatusIs(kInvalid, "resolution"));
  EXPECT_THAT(MapFromProto(RasterMap(pgm, -0.1), limits), StatusIs(kInvalid, "resolution"));
  EXPECT_THAT(MapFromProto(RasterMap(pgm, std::nan("")), limits), StatusIs(kInvalid, "resolution"));
  EXPECT_THAT(MapFromProto(RasterMap("GIF89a....", 0.1), limits),
              StatusIs(kInvalid, "neither a PGM"));
  EXPECT_THAT(MapFromProto(RasterMap(pgm.substr(0, pgm.size() / 2), 0.1), limits),
              StatusIs(kInvalid, "map.raster.image"));
  static const char kTruncatedPng[] = "\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0";
  EXPECT_THAT(
      MapFromProto(RasterMap(std::string(kTruncatedPng, sizeof(kTruncatedPng) - 1), 0.1), limits),
      StatusIs(kInvalid, "map.raster.image"));
  EXPECT_THAT(MapFromProto(RasterMap(AsciiToPgm({"###", "###"}, 2), 0.1), limits),
              StatusIs(kInvalid, "no free pixel"));

  v1::Map bare = RasterMap(pgm, 0.1);
  bare.mutable_raster()->clear_resolution();
  EXPECT_THAT(MapFromProto(bare, limits), StatusIs(kInvalid, "resolution is required"));

  v1::Map bad_yaml = bare;
  bad_yaml.mutable_raster()->set_yaml("image: [unclosed\n  resolution: :\n");
  EXPECT_THAT(MapFromProto(bad_yaml, limits), StatusIs(kInvalid, "map.raster.yaml"));

  v1::Map thresholds = RasterMap(pgm, 0.1);
  thresholds.mutable_raster()->set_free_thresh(0.9);
  EXPECT_THAT(MapFromProto(thresholds, limits), StatusIs(kInvalid, "free_thresh"));
}

// Every CLI command reads map files through MapProtoFromFile: a bare image
// without --resolution is refused there, before anything is sent or planned.
TEST(MapProtoFromFileTest, ABareImageNeedsAResolution) {
  const std::string path =
      (std::filesystem::temp_directory_path() / absl::StrCat("covplan_bare_", getpid(), ".pgm"))
          .string();
  std::ofstream(path, std::ios::binary) << AsciiToPgm(TwoRooms(), 4);
  absl::StatusOr<v1::Map> bare = MapProtoFromFile(path, MapFileOverrides(), EngineLimits());
  EXPECT_THAT(bare, StatusIs(absl::StatusCode::kInvalidArgument,
                             "is a bare image: --resolution M (metres per pixel) is required"));
  EXPECT_THAT(bare.status().message(), HasSubstr(path));
  MapFileOverrides with;
  with.resolution = 0.1;
  absl::StatusOr<v1::Map> ok = MapProtoFromFile(path, with, EngineLimits());
  ASSERT_TRUE(ok.ok()) << ok.status();
  EXPECT_EQ(ok->raster().resolution(), 0.1);
  EXPECT_TRUE(MapFromProto(*ok, EngineLimits()).ok());
  std::filesystem::remove(path);
}

TEST(MapFromProtoTest, EnforcesSizeLimits) {
  const std::string pgm = AsciiToPgm(TwoRooms(), 4);  // 48 x 32 pixels
  EngineLimits limits;
  limits.max_image_bytes = 100;
  EXPECT_THAT(MapFromProto(RasterMap(pgm, 0.1), limits),
              StatusIs(absl::StatusCode::kInvalidArgument, "too large"));
  limits = EngineLimits();
  limits.max_map_pixels = 1000;
  EXPECT_THAT(MapFromProto(RasterMap(pgm, 0.1), limits),
              StatusIs(absl::StatusCode::kInvalidArgument, "48 x 32 = 1536 pixels"));
  // A header claiming a huge image is rejected before any decoding.
  EXPECT_THAT(MapFromProto(RasterMap("P5\n100000 100000\n255\n", 0.1), EngineLimits()),
              StatusIs(absl::StatusCode::kInvalidArgument, "too large"));
  // Claims whose product overflows 64 bits (found by plan_request_fuzzer) are
  // refused the same way, with the product in the message.
  EXPECT_THAT(MapFromProto(RasterMap("P5\n400000000000 800000400\n255\n", 0.1), EngineLimits()),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       "400000000000 x 800000400 = 320000160000000000000 pixels"));
}

TEST(PlanRequestFromProtoTest, ValidatesRobotAndSolvers) {
  const auto kInvalid = absl::StatusCode::kInvalidArgument;
  EXPECT_THAT(PlanRequestFromProto(RequestWithTool(0)), StatusIs(kInvalid, "tool_width_m"));
  EXPECT_THAT(PlanRequestFromProto(RequestWithTool(-1)), StatusIs(kInvalid, "tool_width_m"));
  EXPECT_THAT(PlanRequestFromProto(RequestWithTool(std::nan(""))),
              StatusIs(kInvalid, "tool_width_m"));
  EXPECT_THAT(PlanRequestFromProto(RequestWithTool(std::numeric_limits<double>::infinity())),
              StatusIs(kInvalid, "tool_width_m"));
  v1::PlanRequest request = RequestWithTool(0.5);
  request.mutable_robot()->set_max_speed_mps(0);
  EXPECT_THAT(PlanRequestFromProto(request), StatusIs(kInvalid, "max_speed_mps"));
  request = RequestWithTool(0.5);
  request.set_time_limit_s(-1);
  EXPECT_THAT(PlanRequestFromProto(request), StatusIs(kInvalid, "time_limit_s"));
  request = RequestWithTool(0.5);
  request.set_min_free_fraction(1.5);
  EXPECT_THAT(PlanRequestFromProto(request), StatusIs(kInvalid, "min_free_fraction"));
  request = RequestWithTool(0.5);
  request.set_partition_solver(static_cast<v1::PartitionSolver>(42));
  EXPECT_THAT(PlanRequestFromProto(request), StatusIs(kInvalid, "partition_solver"));

  // Unset, the planner's default solver: push-relabel.
  request = RequestWithTool(0.5);
  absl::StatusOr<PlanRequest> unset = PlanRequestFromProto(request);
  ASSERT_TRUE(unset.ok()) << unset.status();
  EXPECT_EQ(dynamic_cast<const OarpOptions*>(unset->options.get())->partition_solver,
            PartitionSolver::kPushRelabel);

  request = RequestWithTool(0.5);
  request.set_partition_solver(v1::LP);
  request.set_tour_solver(v1::GREEDY);
  request.mutable_robot()->set_turn_rate_deg_s(90);
  request.set_seed(11);
  absl::StatusOr<PlanRequest> options = PlanRequestFromProto(request);
  ASSERT_TRUE(options.ok()) << options.status();
  EXPECT_EQ(options->planner, "oarp");
  const auto* oarp = dynamic_cast<const OarpOptions*>(options->options.get());
  ASSERT_NE(oarp, nullptr);
  EXPECT_EQ(oarp->partition_solver, PartitionSolver::kLp);
  EXPECT_EQ(oarp->tour_solver, TourSolver::kGreedy);
  EXPECT_DOUBLE_EQ(options->common.robot.turn_rate_deg_s, 90);
  EXPECT_DOUBLE_EQ(options->common.robot.tool_width_m, 0.5);
  EXPECT_EQ(options->common.seed, 11u);

  request.set_partition_solver(v1::MATCHING);
  options = PlanRequestFromProto(request);
  ASSERT_TRUE(options.ok()) << options.status();
  EXPECT_EQ(dynamic_cast<const OarpOptions*>(options->options.get())->partition_solver,
            PartitionSolver::kMatching);
  request.set_partition_solver(v1::PUSH_RELABEL);
  options = PlanRequestFromProto(request);
  ASSERT_TRUE(options.ok()) << options.status();
  EXPECT_EQ(dynamic_cast<const OarpOptions*>(options->options.get())->partition_solver,
            PartitionSolver::kPushRelabel);
  request.set_partition_solver(v1::LP);

  // The oneof wins over the top-level solver fields, and its errors name it.
  request.mutable_oarp()->set_partition_solver(v1::MINCUT);
  options = PlanRequestFromProto(request);
  ASSERT_TRUE(options.ok()) << options.status();
  EXPECT_EQ(dynamic_cast<const OarpOptions*>(options->options.get())->partition_solver,
            PartitionSolver::kMinCut);
  request.mutable_oarp()->set_tour_solver(static_cast<v1::TourSolver>(9));
  EXPECT_THAT(PlanRequestFromProto(request), StatusIs(kInvalid, "oarp.tour_solver"));
}

TEST(PlanRequestFromProtoTest, CarriesPlannerAndZones) {
  v1::PlanRequest request = RequestWithTool(0.5);
  request.set_planner("stc");
  v1::Polygon* zone = request.add_no_go();
  for (auto [x, y] : {std::pair{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.0, 0.0}}) {
    v1::Point2* p = zone->mutable_outer()->add_points();
    p->set_x(x);
    p->set_y(y);
  }
  absl::StatusOr<PlanRequest> r = PlanRequestFromProto(request);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->planner, "stc");
  EXPECT_EQ(r->options, nullptr);  // not OARP: no OARP options
  ASSERT_EQ(r->no_go.size(), 1u);
  EXPECT_EQ(r->no_go[0].outer.size(), 4u);
  EXPECT_DOUBLE_EQ(r->no_go[0].outer[2].y, 1.0);
}

// Checks that need the map happen in the engine, reached through the same
// conversion the server and the CLI use.
TEST(EngineValidationTest, ToolMustFitPixelAndMapAndZonesTheMap) {
  const v1::Map map = RasterMap(AsciiToPgm(TwoRooms(), 4), 0.1);  // 4.8 m x 3.2 m
  const PlannerRegistry registry = BuiltinPlanners();
  auto check = [&](double tool, const EngineLimits& limits,
                   v1::PlanRequest request) -> absl::Status {
    LocalArtifactCache cache;
    PlanningEngine engine(&registry, &cache, limits);
    request.mutable_robot()->set_tool_width_m(tool);
    request.set_time_limit_s(0.1);
    absl::StatusOr<PlanRequest> r = PlanRequestFromProto(request);
    if (!r.ok()) return r.status();
    MapSource source{ComputeMapId(map), [&] { return SiteFromProto(map, limits); }};
    return engine.Plan(source, *r).status();
  };
  const EngineLimits limits;
  EXPECT_TRUE(check(0.4, limits, {}).ok());
  EXPECT_THAT(absl::StatusOr<int>(check(0.05, limits, {})),
              StatusIs(absl::StatusCode::kInvalidArgument, "narrower than one map pixel"));
  EXPECT_THAT(absl::StatusOr<int>(check(3.5, limits, {})),
              StatusIs(absl::StatusCode::kInvalidArgument, "wider than the map"));
  EngineLimits tight;
  tight.max_grid_cells = 10;
  EXPECT_THAT(absl::StatusOr<int>(check(0.4, tight, {})),
              StatusIs(absl::StatusCode::kInvalidArgument, "above the limit"));
  v1::PlanRequest far;
  v1::Ring* ring = far.add_no_go()->mutable_outer();
  for (auto [x, y] : {std::pair{50.0, 50.0}, {51.0, 50.0}, {51.0, 51.0}, {50.0, 50.0}}) {
    v1::Point2* p = ring->add_points();
    p->set_x(x);
    p->set_y(y);
  }
  EXPECT_THAT(absl::StatusOr<int>(check(0.4, limits, far)),
              StatusIs(absl::StatusCode::kInvalidArgument, "no_go[0] lies outside the map"));
  v1::PlanRequest unknown;
  unknown.set_planner("nope");
  EXPECT_THAT(absl::StatusOr<int>(check(0.4, limits, unknown)),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       "unknown planner 'nope'; registered: boustrophedon, oarp"));
}

TEST(MapIdTest, ContentDerivedAndWellFormed) {
  const std::string pgm = AsciiToPgm(TwoRooms(), 4);
  const std::string a = ComputeMapId(RasterMap(pgm, 0.1));
  EXPECT_EQ(a, ComputeMapId(RasterMap(pgm, 0.1)));
  EXPECT_NE(a, ComputeMapId(RasterMap(pgm, 0.2)));
  EXPECT_NE(a, ComputeMapId(RasterMap(AsciiToPgm(TwoRooms(), 2), 0.1)));
  EXPECT_EQ(a.size(), 64u);
  EXPECT_TRUE(ValidateMapId(a).ok());
  EXPECT_THAT(absl::StatusOr<int>(ValidateMapId("../../etc/passwd")),
              StatusIs(absl::StatusCode::kInvalidArgument, "malformed"));
}

CoveragePlan SmallPlan() {
  CoveragePlan plan;
  plan.planner = "oarp";
  plan.grid = std::make_shared<const Grid>(Grid::FromAscii({"...", ".#."}, 0.5));
  auto oarp = std::make_shared<OarpDetail>();
  oarp->ranks = {Rank{Orientation::kHorizontal, {1, 0}, {1, 2}},
                 Rank{Orientation::kVertical, {0, 0}, {0, 0}},
                 Rank{Orientation::kVertical, {0, 2}, {0, 2}}};
  oarp->rank_order = {0, 2, 1};
  oarp->rank_reversed = {false, true, false};
  plan.detail = oarp;
  plan.sweeps = {CoverageSweep{1, {{1, 0}, {1, 1}, {1, 2}}}};
  plan.termination = Termination::LimitReached(TerminationLimit::kDeadline, "stopped");
  plan.path = {Waypoint{0.25, 0.75, 0, SegmentKind::kStart, -1},
               Waypoint{1.25, 0.75, 0, SegmentKind::kCoverage, 0},
               Waypoint{1.25, 0.25, -M_PI / 2, SegmentKind::kTransition, -1}};
  plan.stats.num_ranks = 3;
  plan.stats.num_turns = 1;
  plan.stats.coverage_length_m = 1.0;
  plan.stats.free_cells = 5;
  plan.stats.tour_cut_short = true;
  plan.stats.partition_solver = "mincut";
  return plan;
}

TEST(PlanProtoTest, RoundTripsThroughProto) {
  const CoveragePlan plan = SmallPlan();
  v1::PlanResponse response;
  PlanToProto(plan, &response);
  EXPECT_EQ(response.grid().rows(), 2);
  EXPECT_EQ(response.grid().cols(), 3);
  // Row 0 is the smallest y: the bottom row of the ASCII picture.
  EXPECT_EQ(response.grid().free_cells(0), "101");
  EXPECT_EQ(response.grid().free_cells(1), "111");
  EXPECT_EQ(response.ranks(1).orientation(), v1::VERTICAL);
  EXPECT_EQ(response.path(2).kind(), v1::TRANSITION);

  absl::StatusOr<CoveragePlan> back = PlanFromProto(response);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->grid->free_flags(), plan.grid->free_flags());
  const OarpDetail* oarp = back->detail_as<OarpDetail>();
  ASSERT_NE(oarp, nullptr);
  ASSERT_EQ(oarp->ranks.size(), 3u);
  EXPECT_EQ(oarp->ranks[0].last, (CellIndex{1, 2}));
  EXPECT_EQ(oarp->ranks[2].orientation, Orientation::kVertical);
  EXPECT_EQ(oarp->rank_order, plan.detail_as<OarpDetail>()->rank_order);
  EXPECT_EQ(oarp->rank_reversed, plan.detail_as<OarpDetail>()->rank_reversed);
  ASSERT_EQ(back->sweeps.size(), 1u);
  EXPECT_EQ(back->sweeps[0].cells[2], (CellIndex{1, 2}));
  EXPECT_EQ(back->termination.limit, TerminationLimit::kDeadline);
  EXPECT_EQ(back->termination.reason, TerminationReason::kFeasibleLimitReached);
  EXPECT_EQ(back->planner, "oarp");
  // Old callers' top-level fields and the oneof say the same.
  EXPECT_EQ(response.ranks_size(), response.oarp().ranks_size());
  EXPECT_EQ(response.sweeps(0).cells(2), 1 * 3 + 2);
  ASSERT_EQ(back->path.size(), 3u);
  EXPECT_EQ(back->path[1].kind, SegmentKind::kCoverage);
  EXPECT_DOUBLE_EQ(back->path[2].theta, -M_PI / 2);
  EXPECT_TRUE(back->stats.tour_cut_short);
  EXPECT_EQ(back->stats.partition_solver, "mincut");

  v1::PlanResponse again;
  PlanToProto(*back, &again);
  EXPECT_EQ(again.SerializeAsString(), response.SerializeAsString());
}

TEST(PlanProtoTest, RejectsInconsistentResponses) {
  v1::PlanResponse response;
  PlanToProto(SmallPlan(), &response);
  v1::PlanResponse broken = response;
  broken.mutable_grid()->set_free_cells(0, "10");
  EXPECT_THAT(PlanFromProto(broken), StatusIs(absl::StatusCode::kInvalidArgument, "row length"));
  broken = response;
  broken.mutable_oarp()->add_rank_order(7);
  EXPECT_THAT(PlanFromProto(broken), StatusIs(absl::StatusCode::kInvalidArgument, "rank_order"));
}

TEST(PlanJsonTest, SnakeCaseNamesEnumNamesAndDefaultsPrinted) {
  v1::PlanResponse response;
  PlanToProto(SmallPlan(), &response);
  response.set_plan_id("p-1");
  absl::StatusOr<std::string> json = PlanToJson(response);
  ASSERT_TRUE(json.ok());
  EXPECT_THAT(*json, HasSubstr("\"free_cells\": ["));
  EXPECT_THAT(*json, HasSubstr("\"cell_size_m\": 0.5"));
  EXPECT_THAT(*json, HasSubstr("\"orientation\": \"HORIZONTAL\""));
  EXPECT_THAT(*json, HasSubstr("\"orientation\": \"VERTICAL\""));
  EXPECT_THAT(*json, HasSubstr("\"kind\": \"COVERAGE\""));
  EXPECT_THAT(*json, HasSubstr("\"first_cell\""));
  EXPECT_THAT(*json, HasSubstr("\"num_ranks\": 3"));            // int32: a number, not a string
  EXPECT_THAT(*json, HasSubstr("\"transition_length_m\": 0"));  // primitive default printed
  EXPECT_THAT(*json, HasSubstr("\"tour_cut_short\": true"));
  EXPECT_THAT(*json, HasSubstr("\"map_id\": \"\""));
  EXPECT_THAT(*json, HasSubstr("\"reason\": \"FEASIBLE_LIMIT_REACHED\""));
  EXPECT_THAT(*json, HasSubstr("\"limit\": \"LIMIT_DEADLINE\""));
  EXPECT_THAT(*json, HasSubstr("\"planner\": \"oarp\""));
  EXPECT_THAT(*json, HasSubstr("\"sweeps\": ["));
  EXPECT_THAT(*json, ::testing::Not(HasSubstr("numRanks")));
}

// STC options reach the planner; a bad value or options for another
// planner are INVALID_ARGUMENT naming the proto field.
TEST(PlanRequestFromProtoTest, StcOptionsAndTheirErrors) {
  v1::PlanRequest request = RequestWithTool(0.5);
  request.set_planner("stc");
  request.mutable_stc()->set_tree(v1::STC_TREE_PRIM);
  request.mutable_stc()->set_sweep_direction(v1::STC_SWEEP_VERTICAL);
  absl::StatusOr<PlanRequest> ok = PlanRequestFromProto(request);
  ASSERT_TRUE(ok.ok()) << ok.status();
  const auto* stc = dynamic_cast<const StcOptions*>(ok->options.get());
  ASSERT_NE(stc, nullptr);
  EXPECT_EQ(stc->tree, StcTreeMethod::kPrim);
  EXPECT_EQ(stc->sweep_direction, SweepDirection::kVertical);
  EXPECT_EQ(stc->partial_cells, PartialCells::kCover);

  v1::PlanRequest bad = request;
  bad.mutable_stc()->set_tree(static_cast<v1::StcTree>(7));
  EXPECT_THAT(PlanRequestFromProto(bad),
              StatusIs(absl::StatusCode::kInvalidArgument, "stc.tree: unknown value 7"));
  bad = request;
  bad.mutable_stc()->set_sweep_direction(static_cast<v1::StcSweepDirection>(-2));
  EXPECT_THAT(PlanRequestFromProto(bad),
              StatusIs(absl::StatusCode::kInvalidArgument, "stc.sweep_direction"));
  bad = request;
  bad.mutable_stc()->set_partial_cells(static_cast<v1::StcPartialCells>(5));
  EXPECT_THAT(PlanRequestFromProto(bad),
              StatusIs(absl::StatusCode::kInvalidArgument, "stc.partial_cells"));
  bad = request;
  bad.mutable_stc()->set_tree(v1::STC_TREE_DFS);  // a direction without PRIM
  EXPECT_THAT(PlanRequestFromProto(bad),
              StatusIs(absl::StatusCode::kInvalidArgument, "stc.sweep_direction"));
  bad = request;
  bad.set_planner("oarp");
  EXPECT_THAT(PlanRequestFromProto(bad),
              StatusIs(absl::StatusCode::kInvalidArgument, "planner_options"));
}

TEST(PlanProtoTest, StcDetailRoundTrips) {
  CoveragePlan plan;
  plan.planner = "stc";
  plan.grid = std::make_shared<const Grid>(Grid::FromAscii({"..", ".."}));
  auto d = std::make_shared<StcDetail>();
  d->tree = StcTreeMethod::kPrim;
  d->offset = {1, 0};
  d->coarse_cells = 12;
  d->partial_coarse_cells = 3;
  d->extra_moves = 5;
  d->subcells_covered_twice = 4;
  plan.detail = d;
  v1::PlanResponse proto;
  PlanToProto(plan, &proto);
  ASSERT_TRUE(proto.has_stc());
  EXPECT_FALSE(proto.has_oarp());
  EXPECT_EQ(proto.stc().extra_moves(), 5);
  absl::StatusOr<CoveragePlan> back = PlanFromProto(proto);
  ASSERT_TRUE(back.ok()) << back.status();
  const StcDetail* e = back->detail_as<StcDetail>();
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->tree, StcTreeMethod::kPrim);
  EXPECT_EQ(e->offset, (CellIndex{1, 0}));
  EXPECT_EQ(e->coarse_cells, 12);
  EXPECT_EQ(e->partial_coarse_cells, 3);
  EXPECT_EQ(e->subcells_covered_twice, 4);
}

}  // namespace
}  // namespace covplan

namespace covplan {
namespace {

TEST(BatteryProtoTest, BatteryAndBoustrophedonOptionsAreConvertedAndValidated) {
  v1::PlanRequest request = RequestWithTool(0.5);
  request.set_planner("boustrophedon");
  request.mutable_boustrophedon()->set_sweep_axis(v1::SWEEP_AXIS_HORIZONTAL);
  v1::Battery* b = request.mutable_battery();
  b->set_capacity(100);
  b->set_reserve(10);
  b->mutable_station()->set_x(1.5);
  b->mutable_station()->set_y(2.5);
  b->mutable_energy()->set_per_turn(0.5);
  b->set_interruptible_units(true);
  absl::StatusOr<PlanRequest> r = PlanRequestFromProto(request);
  ASSERT_TRUE(r.ok()) << r.status();
  const auto* o = dynamic_cast<const BoustrophedonOptions*>(r->options.get());
  ASSERT_NE(o, nullptr);
  EXPECT_EQ(o->sweep_axis, BoustrophedonAxis::kHorizontal);
  ASSERT_TRUE(r->battery.has_value());
  EXPECT_DOUBLE_EQ(r->battery->budget(), 90.0);
  EXPECT_DOUBLE_EQ(r->battery->energy.per_metre, 1.0);  // unset: distance
  EXPECT_DOUBLE_EQ(r->battery->energy.per_turn, 0.5);
  EXPECT_TRUE(r->battery->interruptible_units);

  for (double cap : {0.0, -1.0, std::nan("")}) {
    v1::PlanRequest bad = request;
    bad.mutable_battery()->set_capacity(cap);
    EXPECT_THAT(PlanRequestFromProto(bad),
                StatusIs(absl::StatusCode::kInvalidArgument, "battery.capacity"));
  }
  v1::PlanRequest bad = request;
  bad.mutable_battery()->set_reserve(100);
  EXPECT_THAT(PlanRequestFromProto(bad),
              StatusIs(absl::StatusCode::kInvalidArgument, "battery.reserve"));
  bad = request;
  bad.mutable_battery()->clear_station();
  EXPECT_THAT(PlanRequestFromProto(bad),
              StatusIs(absl::StatusCode::kInvalidArgument, "battery.station"));
  bad = request;
  bad.mutable_boustrophedon()->set_sweep_axis(static_cast<v1::SweepAxis>(42));
  EXPECT_THAT(PlanRequestFromProto(bad),
              StatusIs(absl::StatusCode::kInvalidArgument, "boustrophedon.sweep_axis"));
}

TEST(BatteryProtoTest, BoustrophedonDetailRoundTrips) {
  CoveragePlan plan = SmallPlan();
  plan.planner = "boustrophedon";
  auto detail = std::make_shared<BoustrophedonDetail>();
  detail->cells.push_back({BcdCell{0, {{0, 1}}}, SweepAxis::kVertical, 1});
  detail->cells.push_back({BcdCell{1, {{1, 1}, {0, 1}}}, SweepAxis::kHorizontal, 2});
  detail->cell_order = {1, 0};
  detail->cell_reversed = {true, false};
  detail->cell_mirrored = {false, true};
  plan.detail = detail;
  v1::PlanResponse response;
  PlanToProto(plan, &response);
  ASSERT_TRUE(response.has_boustrophedon());
  EXPECT_EQ(response.boustrophedon().cells(1).axis(), v1::SWEEP_AXIS_HORIZONTAL);
  absl::StatusOr<CoveragePlan> back = PlanFromProto(response);
  ASSERT_TRUE(back.ok()) << back.status();
  const auto* d = back->detail_as<BoustrophedonDetail>();
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->cells[1].cell.columns[1].hi, 1);
  EXPECT_EQ(d->cell_order, detail->cell_order);
  EXPECT_EQ(d->cell_mirrored, detail->cell_mirrored);
  v1::PlanResponse again;
  PlanToProto(*back, &again);
  EXPECT_EQ(again.SerializeAsString(), response.SerializeAsString());
  response.mutable_boustrophedon()->mutable_cells(0)->set_row_hi(0, 7);
  EXPECT_THAT(PlanFromProto(response),
              StatusIs(absl::StatusCode::kInvalidArgument, "boustrophedon cell"));
}

TEST(BatteryProtoTest, ChargeCyclesRoundTripAndReachPlanJson) {
  CoveragePlan plan = SmallPlan();
  plan.cycles.push_back({0, 2, 1, 1, 12.5, 7.0, 3, false});
  plan.stats.charge_cycles = 1;
  plan.stats.energy_total = 12.5;
  v1::PlanResponse response;
  PlanToProto(plan, &response);
  ASSERT_EQ(response.cycles_size(), 1);
  EXPECT_DOUBLE_EQ(response.cycles(0).resume().x(), plan.path[1].x);
  absl::StatusOr<CoveragePlan> back = PlanFromProto(response);
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->cycles.size(), 1u);
  EXPECT_EQ(back->cycles[0].last_waypoint, 2);
  EXPECT_DOUBLE_EQ(back->cycles[0].energy_at_leave, 7.0);
  absl::StatusOr<std::string> json = PlanToJson(response);
  ASSERT_TRUE(json.ok());
  EXPECT_THAT(*json, HasSubstr("\"cycles\""));
  EXPECT_THAT(*json, HasSubstr("\"resume_waypoint\": 1"));
  response.mutable_cycles(0)->set_last_waypoint(99);
  EXPECT_THAT(PlanFromProto(response),
              StatusIs(absl::StatusCode::kInvalidArgument, "charge cycle"));
}

}  // namespace
}  // namespace covplan
