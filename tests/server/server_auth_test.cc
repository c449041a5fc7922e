// Bearer tokens and tenants on a real covplan-server process: without a
// valid token every CoveragePlanner call is UNAUTHENTICATED while health and
// reflection stay open; a tenant sees only its own maps and plans, and
// another tenant's id answers exactly like an id that does not exist; SIGHUP
// rereads the token file; the `covplan` CLI reaches a TLS + token server
// with --tls-ca and --token / --token-file; the tenant labels the request
// metrics and the log lines.
#include <grpcpp/grpcpp.h>
#include <signal.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "absl/time/clock.h"
#include "api/digest.h"
#include "client/health_command.h"
#include "client/plan_command.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/server/grpc_probe.h"
#include "tests/server/server_process.h"
#include "tests/testing/test_maps.h"

namespace covplan {
namespace {

using ::covplan::testing::AsciiToPgm;
using ::covplan::testing::HealthStatus;
using ::covplan::testing::HttpGet;
using ::covplan::testing::PillarField;
using ::covplan::testing::PlanRequestFor;
using ::covplan::testing::RasterMap;
using ::covplan::testing::ReflectionServices;
using ::covplan::testing::ServerProcess;
using ::covplan::testing::TwoRooms;
using ::testing::HasSubstr;

constexpr char kAlpha[] = "alpha-secret-token";
constexpr char kBeta[] = "beta-secret-token";

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void WriteFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

std::string TokenLine(const std::string& token, const std::string& tenant) {
  return absl::StrCat(Sha256Hex(token), " ", tenant, "\n");
}

class ServerAuthTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (std::filesystem::temp_directory_path() / "covplan_auth_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    tokens_ = dir_ + "/tokens.txt";
    WriteFile(tokens_, "# test tokens\n" + TokenLine(kAlpha, "alpha") + TokenLine(kBeta, "beta"));
  }
  void TearDown() override {
    server_.reset();
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  void StartServer(std::vector<std::string> extra = {}) {
    server_ = std::make_unique<ServerProcess>();
    std::vector<std::string> args = {"--metrics_port=-1", "--drain_notice_s=0",
                                     "--token_file=" + tokens_};
    args.insert(args.end(), extra.begin(), extra.end());
    const absl::Status started = server_->Start(dir_ + "/maps", args);
    ASSERT_TRUE(started.ok()) << started << server_->log();
    channel_ = grpc::CreateChannel(server_->target(), grpc::InsecureChannelCredentials());
    stub_ = v1::CoveragePlanner::NewStub(channel_);
  }
  // A context carrying `token` (none when empty), with a deadline.
  static std::unique_ptr<grpc::ClientContext> Ctx(const std::string& token) {
    auto context = std::make_unique<grpc::ClientContext>();
    context->set_deadline(absl::ToChronoTime(absl::Now() + absl::Seconds(20)));
    if (!token.empty()) context->AddMetadata("authorization", "Bearer " + token);
    return context;
  }
  grpc::Status PutMap(const std::string& token, v1::PutMapResponse* response) {
    v1::PutMapRequest request;
    *request.mutable_map() = RasterMap(AsciiToPgm(TwoRooms(), 4), 0.05);
    request.set_name("two rooms");
    return stub_->PutMap(Ctx(token).get(), request, response);
  }
  grpc::Status GetMap(const std::string& token, const std::string& map_id) {
    v1::GetMapRequest request;
    request.set_map_id(map_id);
    v1::GetMapResponse response;
    return stub_->GetMap(Ctx(token).get(), request, &response);
  }
  grpc::Status ListMaps(const std::string& token, std::vector<std::string>* ids) {
    v1::ListMapsRequest request;
    v1::ListMapsResponse response;
    grpc::Status status = stub_->ListMaps(Ctx(token).get(), request, &response);
    for (const v1::MapInfo& info : response.maps()) ids->push_back(info.map_id());
    return status;
  }
  // Scrapes /metrics and expects each of `series` ("name{labels} value").
  void ExpectSeries(std::initializer_list<const char*> series) {
    absl::StatusOr<std::string> metrics = HttpGet(server_->metrics_port(), "/metrics");
    ASSERT_TRUE(metrics.ok()) << metrics.status();
    for (const char* one : series) {
      EXPECT_NE(metrics->find(one), std::string::npos) << one << " missing from\n" << *metrics;
    }
    EXPECT_EQ(metrics->find(R"(tenant="")"), std::string::npos);
  }
  grpc::Status Plan(const std::string& token, const std::string& map_id,
                    v1::PlanResponse* response) {
    return stub_->Plan(Ctx(token).get(), PlanRequestFor(map_id, 0.3), response);
  }

  std::string dir_;
  std::string tokens_;
  std::unique_ptr<ServerProcess> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::CoveragePlanner::Stub> stub_;
};

TEST_F(ServerAuthTest, CallsWithoutAValidTokenAreUnauthenticatedHealthStaysOpen) {
  StartServer();
  std::vector<std::string> ids;
  EXPECT_EQ(ListMaps("", &ids).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(ListMaps("not-a-known-token", &ids).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  {  // a known token, but not as a bearer token
    v1::ListMapsResponse response;
    auto context = Ctx("");
    context->AddMetadata("authorization", kAlpha);
    EXPECT_EQ(stub_->ListMaps(context.get(), v1::ListMapsRequest(), &response).error_code(),
              grpc::StatusCode::UNAUTHENTICATED);
  }
  v1::PutMapResponse put;
  const grpc::Status refused = PutMap("", &put);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_NE(refused.error_message().find("Bearer"), std::string::npos) << refused.error_message();
  {  // the Drive stream too
    auto context = Ctx("");
    auto stream = stub_->Drive(context.get());
    v1::DriveRequest first;
    first.set_plan_id("p-0");
    stream->Write(first);
    v1::DriveEvent event;
    EXPECT_FALSE(stream->Read(&event));
    EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::UNAUTHENTICATED);
  }
  EXPECT_TRUE(ids.empty());
  // Health and reflection need no token.
  absl::StatusOr<int> health = HealthStatus(channel_, "");
  ASSERT_TRUE(health.ok()) << health.status();
  EXPECT_EQ(*health, 1);
  absl::StatusOr<std::vector<std::string>> services = ReflectionServices(channel_);
  ASSERT_TRUE(services.ok()) << services.status();
  EXPECT_NE(std::find(services->begin(), services->end(), "covplan.v1.CoveragePlanner"),
            services->end());
  // A valid token is served.
  EXPECT_TRUE(ListMaps(kAlpha, &ids).ok());
}

// The token is checked by the transport before gRPC reads the request:
// a request that is not even a valid protobuf, sent without a valid token,
// is UNAUTHENTICATED (a handler, or gRPC's own parsing, would have answered
// INVALID_ARGUMENT), and the refusal is counted and logged as refused at the
// transport. With alpha's token the same bytes reach the parsing and are
// INVALID_ARGUMENT.
TEST_F(ServerAuthTest, TokensAreCheckedAtTheTransportBeforeTheRequestIsRead) {
  StartServer({"--metrics_port=0"});
  const std::string junk = "\xff\xff\xff\xff not a protobuf";
  const std::string put_map = "/covplan.v1.CoveragePlanner/PutMap";
  for (const std::string& authorization :
       {std::string(), std::string("Bearer not-a-known-token"), std::string(kAlpha)}) {
    absl::StatusOr<std::string> reply =
        testing::RawUnaryCall(channel_, put_map, junk, authorization);
    ASSERT_FALSE(reply.ok());
    EXPECT_EQ(reply.status().code(), absl::StatusCode::kUnauthenticated)
        << "authorization '" << authorization << "': " << reply.status();
  }
  absl::StatusOr<std::string> served =
      testing::RawUnaryCall(channel_, put_map, junk, absl::StrCat("Bearer ", kAlpha));
  ASSERT_FALSE(served.ok());
  EXPECT_EQ(served.status().code(), absl::StatusCode::kInvalidArgument) << served.status();
  // Unknown methods need a token too (a refusal, not UNIMPLEMENTED), labelled "unknown".
  absl::StatusOr<std::string> unknown = testing::RawUnaryCall(channel_, "/x.Y/Z", "");
  EXPECT_EQ(unknown.status().code(), absl::StatusCode::kUnauthenticated) << unknown.status();

  ExpectSeries({
      R"(covplan_requests_total{code="UNAUTHENTICATED",method="PutMap",tenant="unauthenticated"} 3)",
      R"(covplan_requests_total{code="UNAUTHENTICATED",method="unknown",tenant="unauthenticated"} 1)",
  });
  int at_transport = 0;
  std::istringstream log(server_->log());
  for (std::string line; std::getline(log, line);) {
    if (line.find("refused_at=transport") != std::string::npos &&
        line.find("code=UNAUTHENTICATED") != std::string::npos)
      ++at_transport;
  }
  EXPECT_EQ(at_transport, 4) << server_->log();
}

TEST_F(ServerAuthTest, TenantsSeeOnlyTheirOwnMapsAndPlans) {
  StartServer();
  v1::PutMapResponse alpha_put, beta_put;
  ASSERT_TRUE(PutMap(kAlpha, &alpha_put).ok());
  ASSERT_TRUE(PutMap(kBeta, &beta_put).ok());
  const std::string a = alpha_put.map_id();
  const std::string b = beta_put.map_id();
  // The same content, two maps: each tenant has its own.
  EXPECT_NE(a, b);
  EXPECT_TRUE(alpha_put.created());
  EXPECT_TRUE(beta_put.created());

  std::vector<std::string> alpha_ids, beta_ids;
  ASSERT_TRUE(ListMaps(kAlpha, &alpha_ids).ok());
  ASSERT_TRUE(ListMaps(kBeta, &beta_ids).ok());
  EXPECT_EQ(alpha_ids, std::vector<std::string>{a});
  EXPECT_EQ(beta_ids, std::vector<std::string>{b});

  // Another tenant's map answers exactly as a map that does not exist.
  const std::string missing(64, 'c');
  const auto same_as_missing = [&](const grpc::Status& foreign, const grpc::Status& absent,
                                   const std::string& foreign_id) {
    EXPECT_EQ(foreign.error_code(), grpc::StatusCode::NOT_FOUND) << foreign.error_message();
    EXPECT_EQ(absent.error_code(), grpc::StatusCode::NOT_FOUND) << absent.error_message();
    EXPECT_EQ(absl::StrReplaceAll(foreign.error_message(), {{foreign_id, "<id>"}}),
              absl::StrReplaceAll(absent.error_message(), {{missing, "<id>"}}));
  };
  same_as_missing(GetMap(kBeta, a), GetMap(kBeta, missing), a);
  v1::PlanResponse foreign_plan, absent_plan;
  same_as_missing(Plan(kBeta, a, &foreign_plan), Plan(kBeta, missing, &absent_plan), a);
  EXPECT_TRUE(GetMap(kAlpha, a).ok());
  EXPECT_EQ(GetMap(kBeta, "not-an-id").error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  // Plans: alpha's plan is not beta's.
  v1::PlanResponse plan;
  const grpc::Status planned = Plan(kAlpha, a, &plan);
  ASSERT_TRUE(planned.ok()) << planned.error_message();
  {
    v1::GetPlanRequest request;
    v1::PlanResponse response;
    request.set_plan_id(plan.plan_id());
    EXPECT_TRUE(stub_->GetPlan(Ctx(kAlpha).get(), request, &response).ok());
    const grpc::Status foreign = stub_->GetPlan(Ctx(kBeta).get(), request, &response);
    const std::string absent_id = "p-00000000000000000000000000000000";
    request.set_plan_id(absent_id);
    const grpc::Status absent = stub_->GetPlan(Ctx(kBeta).get(), request, &response);
    EXPECT_EQ(foreign.error_code(), grpc::StatusCode::NOT_FOUND);
    EXPECT_EQ(absl::StrReplaceAll(foreign.error_message(), {{plan.plan_id(), "<id>"}}),
              absl::StrReplaceAll(absent.error_message(), {{absent_id, "<id>"}}));
  }
  {
    v1::ReplanRequest request;
    request.set_plan_id(plan.plan_id());
    request.mutable_progress()->set_distance_m(0.5);
    v1::ReplanResponse response;
    EXPECT_EQ(stub_->Replan(Ctx(kBeta).get(), request, &response).error_code(),
              grpc::StatusCode::NOT_FOUND);
    v1::ResumeRequest resume;
    resume.set_plan_id(plan.plan_id());
    resume.mutable_pose()->set_x(1.0);
    resume.mutable_pose()->set_y(1.0);
    EXPECT_EQ(stub_->Resume(Ctx(kBeta).get(), resume, &response).error_code(),
              grpc::StatusCode::NOT_FOUND);
  }

  {  // Drive: alpha adopts its plan, beta's session on it ends NOT_FOUND
    const auto drive = [&](const std::string& token, v1::DriveEvent* event) {
      auto context = Ctx(token);
      auto stream = stub_->Drive(context.get());
      v1::DriveRequest first;
      first.set_plan_id(plan.plan_id());
      stream->Write(first);
      const bool read = stream->Read(event);
      if (read) context->TryCancel();
      const grpc::Status status = stream->Finish();
      return read ? grpc::Status::OK : status;
    };
    v1::DriveEvent event;
    ASSERT_TRUE(drive(kAlpha, &event).ok());
    EXPECT_EQ(event.ready().plan_id(), plan.plan_id());
    EXPECT_EQ(drive(kBeta, &event).error_code(), grpc::StatusCode::NOT_FOUND);
  }

  // Beta cannot delete alpha's map (answered as for a missing map), but its own.
  {
    v1::DeleteMapRequest request;
    v1::DeleteMapResponse response;
    request.set_map_id(a);
    ASSERT_TRUE(stub_->DeleteMap(Ctx(kBeta).get(), request, &response).ok());
    EXPECT_FALSE(response.deleted());
    request.set_map_id(b);
    ASSERT_TRUE(stub_->DeleteMap(Ctx(kBeta).get(), request, &response).ok());
    EXPECT_TRUE(response.deleted());
  }
  EXPECT_TRUE(GetMap(kAlpha, a).ok());
  EXPECT_EQ(GetMap(kBeta, b).error_code(), grpc::StatusCode::NOT_FOUND);
}

TEST_F(ServerAuthTest, ListMapsPagesOverOnlyTheCallersMaps) {
  StartServer();
  std::set<std::string> alpha_maps;
  for (int i = 0; i < 5; ++i) {  // interleaved: alpha 0, 2, 4; beta 1, 3
    v1::PutMapRequest request;
    *request.mutable_map() = RasterMap(AsciiToPgm(TwoRooms(), 4), 0.05 + 0.01 * i);
    v1::PutMapResponse response;
    const std::string& token = i % 2 == 0 ? kAlpha : kBeta;
    ASSERT_TRUE(stub_->PutMap(Ctx(token).get(), request, &response).ok());
    if (i % 2 == 0) alpha_maps.insert(response.map_id());
  }
  std::set<std::string> seen;
  std::string page_token;
  int pages = 0;
  do {
    v1::ListMapsRequest request;
    request.set_page_size(2);
    request.set_page_token(page_token);
    v1::ListMapsResponse response;
    ASSERT_TRUE(stub_->ListMaps(Ctx(kAlpha).get(), request, &response).ok());
    EXPECT_LE(response.maps_size(), 2);
    for (const v1::MapInfo& info : response.maps()) EXPECT_TRUE(seen.insert(info.map_id()).second);
    page_token = response.next_page_token();
    ASSERT_LT(++pages, 10);
  } while (!page_token.empty());
  EXPECT_EQ(seen, alpha_maps);
  EXPECT_EQ(pages, 2);
}

// The caller's tenant labels its call's request metrics and is a field of
// the call's log line; a call without a valid token is "unauthenticated".
TEST_F(ServerAuthTest, TheTenantLabelsTheRequestMetricsAndTheLogLine) {
  StartServer({"--metrics_port=0"});
  v1::PutMapResponse put;
  ASSERT_TRUE(PutMap(kAlpha, &put).ok());
  std::vector<std::string> ids;
  ASSERT_TRUE(ListMaps(kBeta, &ids).ok());
  ASSERT_EQ(ListMaps("", &ids).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  ExpectSeries({
      R"(covplan_requests_total{code="OK",method="PutMap",tenant="alpha"} 1)",
      R"(covplan_requests_total{code="OK",method="ListMaps",tenant="beta"} 1)",
      R"(covplan_requests_total{code="UNAUTHENTICATED",method="ListMaps",tenant="unauthenticated"} 1)",
      R"(covplan_request_duration_seconds_count{method="PutMap",tenant="alpha"} 1)",
  });
  // The log lines of the three calls, each with its tenant.
  std::set<std::string> seen;
  std::istringstream log(server_->log());
  for (std::string line; std::getline(log, line);) {
    if (line.find("msg=\"request finished\"") == std::string::npos) continue;
    for (const char* tenant : {"alpha", "beta", "unauthenticated"}) {
      if (line.find(absl::StrCat(" tenant=", tenant, " ")) != std::string::npos)
        seen.insert(tenant);
    }
  }
  EXPECT_EQ(seen, (std::set<std::string>{"alpha", "beta", "unauthenticated"})) << server_->log();
}

TEST_F(ServerAuthTest, SighupRereadsTheTokenFile) {
  WriteFile(tokens_, TokenLine(kAlpha, "alpha"));
  StartServer();
  std::vector<std::string> ids;
  EXPECT_TRUE(ListMaps(kAlpha, &ids).ok());
  EXPECT_EQ(ListMaps(kBeta, &ids).error_code(), grpc::StatusCode::UNAUTHENTICATED);

  // Beta added, alpha removed.
  WriteFile(tokens_, TokenLine(kBeta, "beta"));
  ASSERT_EQ(::kill(server_->pid(), SIGHUP), 0);
  const absl::Time until = absl::Now() + absl::Seconds(10);
  while (!ListMaps(kBeta, &ids).ok() && absl::Now() < until) absl::SleepFor(absl::Milliseconds(50));
  EXPECT_TRUE(ListMaps(kBeta, &ids).ok()) << server_->log();
  EXPECT_EQ(ListMaps(kAlpha, &ids).error_code(), grpc::StatusCode::UNAUTHENTICATED);

  // A malformed file is refused and the tokens in force stay.
  WriteFile(tokens_, "not a token line\n");
  ASSERT_EQ(::kill(server_->pid(), SIGHUP), 0);
  const absl::Time logged = absl::Now() + absl::Seconds(10);
  while (server_->log().find("token file not reloaded") == std::string::npos &&
         absl::Now() < logged) {
    absl::SleepFor(absl::Milliseconds(50));
  }
  EXPECT_NE(server_->log().find("token file not reloaded"), std::string::npos) << server_->log();
  EXPECT_TRUE(ListMaps(kBeta, &ids).ok());
  EXPECT_EQ(server_->Stop(), 0);
}

// Issue 30, item 1: a token file changed on disk is reread within the
// store probe's interval (2 s) without a SIGHUP, so replicas that share the
// file (or get it rolled out) agree on a revocation.
TEST_F(ServerAuthTest, AChangedTokenFileIsRereadWithoutASignal) {
  WriteFile(tokens_, TokenLine(kAlpha, "alpha"));
  StartServer();
  std::vector<std::string> ids;
  ASSERT_TRUE(ListMaps(kAlpha, &ids).ok());
  // Beta added, alpha revoked.
  WriteFile(tokens_, TokenLine(kBeta, "beta"));
  const absl::Time changed = absl::Now();
  while (ListMaps(kAlpha, &ids).ok() && absl::Now() - changed < absl::Seconds(15)) {
    absl::SleepFor(absl::Milliseconds(50));
  }
  EXPECT_EQ(ListMaps(kAlpha, &ids).error_code(), grpc::StatusCode::UNAUTHENTICATED)
      << server_->log();
  EXPECT_TRUE(ListMaps(kBeta, &ids).ok());
  // The bound is 2 s; the slack is for a loaded machine.
  EXPECT_LT(absl::Now() - changed, absl::Seconds(8));
  EXPECT_NE(server_->log().find("token file changed on disk"), std::string::npos);
}

TEST_F(ServerAuthTest, ABadTokenFileStopsStartup) {
  WriteFile(tokens_, "abc alpha\n");
  ServerProcess server;
  EXPECT_FALSE(server.Start(dir_ + "/maps", {"--metrics_port=-1", "--token_file=" + tokens_}).ok());
  EXPECT_NE(server.log().find("line 1"), std::string::npos) << server.log();
  ServerProcess missing;
  EXPECT_FALSE(
      missing.Start(dir_ + "/maps", {"--metrics_port=-1", "--token_file=" + dir_ + "/none"}).ok());
  EXPECT_NE(missing.log().find("cannot read"), std::string::npos) << missing.log();
}

// Issue 30, item 4: a tenant stores no more new maps than its max_maps (a
// map it already has may be put again); others are not affected; SIGHUP
// rereads the quota file.
TEST_F(ServerAuthTest, ATenantStoresNoMoreMapsThanItsQuota) {
  const std::string quotas = dir_ + "/quotas.txt";
  WriteFile(quotas, "alpha max_maps=1\n");
  StartServer({"--tenant_quota_file=" + quotas});
  const auto put = [&](const std::string& token, double resolution, v1::PutMapResponse* out) {
    v1::PutMapRequest request;
    *request.mutable_map() = RasterMap(AsciiToPgm(TwoRooms(), 4), resolution);
    return stub_->PutMap(Ctx(token).get(), request, out);
  };
  v1::PutMapResponse first;
  v1::PutMapResponse again;
  v1::PutMapResponse refused;
  ASSERT_TRUE(put(kAlpha, 0.05, &first).ok());
  ASSERT_TRUE(put(kAlpha, 0.05, &again).ok());
  EXPECT_FALSE(again.created());
  const grpc::Status over = put(kAlpha, 0.06, &refused);
  EXPECT_EQ(over.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(over.error_message(), HasSubstr("tenant alpha stores 1 maps, its quota of 1"));
  EXPECT_THAT(over.error_message(), HasSubstr("--tenant_max_maps"));
  for (double resolution : {0.06, 0.07}) {
    v1::PutMapResponse beta;
    EXPECT_TRUE(put(kBeta, resolution, &beta).ok());
  }
  std::vector<std::string> ids;
  ASSERT_TRUE(ListMaps(kAlpha, &ids).ok());
  EXPECT_EQ(ids, std::vector<std::string>{first.map_id()});
  // Deleting one makes room.
  v1::DeleteMapRequest del;
  del.set_map_id(first.map_id());
  v1::DeleteMapResponse deleted;
  ASSERT_TRUE(stub_->DeleteMap(Ctx(kAlpha).get(), del, &deleted).ok());
  v1::PutMapResponse second;
  ASSERT_TRUE(put(kAlpha, 0.06, &second).ok());
  // A raised quota after SIGHUP.
  WriteFile(quotas, "alpha max_maps=2\n");
  ASSERT_EQ(::kill(server_->pid(), SIGHUP), 0);
  const absl::Time until = absl::Now() + absl::Seconds(10);
  while (server_->log().find("tenant quotas reloaded") == std::string::npos &&
         absl::Now() < until) {
    absl::SleepFor(absl::Milliseconds(50));
  }
  v1::PutMapResponse third;
  EXPECT_TRUE(put(kAlpha, 0.07, &third).ok()) << server_->log();
}

// Issue 30, item 4: solves are admitted per tenant when the call arrives. A
// tenant flooding the server past max_solves + max_queued is refused at once
// naming its quota, and another tenant's Plan is still answered.
TEST_F(ServerAuthTest, ATenantOverItsSolveQuotaIsRefusedAndAnotherIsServed) {
  const std::string quotas = dir_ + "/quotas.txt";
  WriteFile(quotas, "alpha max_solves=1 max_queued=1\n");
  // Dense transitions keep each solve busy for its whole time limit.
  StartServer({"--tenant_quota_file=" + quotas, "--threads=2", "--dense_transition_mb=1024"});
  v1::PutMapRequest busy;
  *busy.mutable_map() = RasterMap(AsciiToPgm(PillarField(120, 90, 200, 3), 4), 0.05);
  v1::PutMapResponse alpha_map;
  ASSERT_TRUE(stub_->PutMap(Ctx(kAlpha).get(), busy, &alpha_map).ok());
  v1::PutMapResponse beta_map;
  ASSERT_TRUE(PutMap(kBeta, &beta_map).ok());
  v1::PutMapResponse alpha_small;
  ASSERT_TRUE(PutMap(kAlpha, &alpha_small).ok());
  v1::PlanResponse alpha_plan;
  ASSERT_TRUE(Plan(kAlpha, alpha_small.map_id(), &alpha_plan).ok());
  constexpr int kAlphaCalls = 6;
  std::vector<grpc::Status> alpha(kAlphaCalls);
  std::vector<absl::Time> alpha_done(kAlphaCalls);
  std::vector<std::thread> callers;
  std::atomic<int> refused_so_far{0};
  for (int i = 0; i < kAlphaCalls; ++i) {
    callers.emplace_back([&, i] {
      v1::PlanRequest request = PlanRequestFor(alpha_map.map_id(), 0.3);
      request.set_time_limit_s(2.0);
      request.mutable_robot()->mutable_start()->set_theta(0.1 * i);  // not a repeat
      v1::PlanResponse response;
      alpha[i] = stub_->Plan(Ctx(kAlpha).get(), request, &response);
      alpha_done[i] = absl::Now();
      if (alpha[i].error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED) ++refused_so_far;
    });
  }
  // Every call has arrived once all but the quota's two are refused (at
  // once); those two hold alpha's quota for their 2 s.
  const absl::Time arrived_by = absl::Now() + absl::Seconds(10);
  while (refused_so_far.load() < kAlphaCalls - 2 && absl::Now() < arrived_by) {
    absl::SleepFor(absl::Milliseconds(10));
  }
  {  // alpha's Drive session needs a solve too: refused naming the tenant
    auto context = Ctx(kAlpha);
    auto stream = stub_->Drive(context.get());
    v1::DriveRequest first;
    first.set_plan_id(alpha_plan.plan_id());
    stream->Write(first);
    v1::DriveEvent event;
    while (stream->Read(&event)) {
    }
    const grpc::Status drive = stream->Finish();
    EXPECT_EQ(drive.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << drive.error_message();
    EXPECT_THAT(drive.error_message(), HasSubstr("tenant alpha is over its quota"));
  }
  v1::PlanResponse beta;
  const grpc::Status beta_status = Plan(kBeta, beta_map.map_id(), &beta);
  const absl::Time beta_done = absl::Now();
  for (std::thread& t : callers) t.join();
  EXPECT_TRUE(beta_status.ok()) << beta_status.error_message() << server_->log();
  // Beta ran on the worker alpha's quota leaves free: answered before any of
  // alpha's 2 s solves (in one FIFO queue it waited behind them).
  for (int i = 0; i < kAlphaCalls; ++i) {
    if (alpha[i].ok()) {
      EXPECT_LT(beta_done, alpha_done[i]) << i;
    }
  }
  int ok = 0;
  int refused = 0;
  for (const grpc::Status& s : alpha) {
    ok += s.ok();
    if (s.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED) {
      ++refused;
      EXPECT_THAT(s.error_message(),
                  HasSubstr("tenant alpha is over its quota of 1 running and 1 queued solves"));
    }
  }
  EXPECT_EQ(ok, 2) << server_->log();
  EXPECT_EQ(refused, kAlphaCalls - 2);
}

TEST_F(ServerAuthTest, CliReachesATlsServerWithATokenAndACa) {
  const std::string script =
      absl::StrCat("set -e; cd ", dir_, "; exec >openssl.log 2>&1\n",
                   "key() { openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:prime256v1 "
                   "-out $1.key; }\n",
                   "key ca; openssl req -x509 -new -key ca.key -out ca.pem -days 2 -subj /CN=ca\n",
                   "printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\\n' > san.cnf\n",
                   "key server; openssl req -new -key server.key -out server.csr -subj /CN=server; "
                   "openssl x509 -req -in server.csr -CA ca.pem -CAkey ca.key -CAcreateserial -out "
                   "server.pem -days 2 "
                   "-extfile san.cnf\n");
  if (std::system(("bash -c '" + script + "'").c_str()) != 0) {
    GTEST_SKIP() << "openssl could not make test certificates: " << ReadFile(dir_ + "/openssl.log");
  }
  StartServer({"--tls_cert=" + dir_ + "/server.pem", "--tls_key=" + dir_ + "/server.key"});
  const std::string map = dir_ + "/rooms.pgm";
  WriteFile(map, AsciiToPgm(TwoRooms(), 4));
  WriteFile(dir_ + "/alpha.token", std::string(kAlpha) + "\n");
  const std::string out = dir_ + "/plan.json";
  const std::vector<std::string> plan = {
      "--map", map,        "--resolution",    "0.05",     "--tool-width",
      "0.3",   "--server", server_->target(), "--tls-ca", dir_ + "/ca.pem",
      "--out", out};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = plan;
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  EXPECT_NE(RunPlanCommand(plan), 0);  // no token
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_NE(RunPlanCommand(with({"--token", "wrong"})), 0);
  EXPECT_EQ(RunPlanCommand(with({"--token", kAlpha})), 0);
  EXPECT_NE(ReadFile(out).find("\"plan_id\": \"p-"), std::string::npos) << ReadFile(out);
  std::filesystem::remove(out);
  EXPECT_EQ(RunPlanCommand(with({"--token-file", dir_ + "/alpha.token"})), 0);
  EXPECT_TRUE(std::filesystem::exists(out));
  // Plaintext to the TLS port fails; bad connection flags are clear errors.
  EXPECT_NE(RunPlanCommand({"--map", map, "--resolution", "0.05", "--server", server_->target(),
                            "--token", kAlpha}),
            0);
  EXPECT_NE(RunPlanCommand(with({"--token", kAlpha, "--token-file", dir_ + "/alpha.token"})), 0);
  EXPECT_NE(RunPlanCommand(with({"--tls-cert", dir_ + "/server.pem"})), 0);  // without --tls-key
  // Health over TLS needs no token.
  EXPECT_EQ(RunHealthCommand({"--server", server_->target(), "--tls-ca", dir_ + "/ca.pem"}), 0);
  EXPECT_NE(RunHealthCommand({"--server", server_->target()}), 0);
}

}  // namespace
}  // namespace covplan
