// Area: validation messages, union semantics, and the raster functions against independent
// references (per-cell Boost clipping, point sampling, point tests on pixel centres/corners).
#include "planner/geometry/area.h"

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;
using Ring = std::vector<Point2>;

Ring Box(double x0, double y0, double x1, double y1) {
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}, {x0, y0}};
}

Ring Reversed(Ring r) { return Ring(r.rbegin(), r.rend()); }

Area MustCreate(const std::vector<PolygonInput>& p) {
  absl::StatusOr<Area> a = Area::Create(p, "test");
  EXPECT_TRUE(a.ok()) << a.status();
  return a.ok() ? *std::move(a) : Area();
}

void ExpectInvalid(const std::vector<PolygonInput>& p, const std::string& field,
                   const std::string& message, const AreaLimits& limits = {}) {
  absl::StatusOr<Area> a = Area::Create(p, field, limits);
  ASSERT_FALSE(a.ok()) << "accepted, expected: " << message;
  EXPECT_EQ(a.status().code(), absl::StatusCode::kInvalidArgument) << a.status();
  EXPECT_THAT(std::string(a.status().message()), HasSubstr(message));
}

TEST(AreaValidationTest, RingNotClosed) {
  ExpectInvalid({{Box(0, 0, 1, 1), {}}, {{{0, 0}, {2, 0}, {2, 1}}, {}}}, "no_go",
                "no_go[1].outer: ring is not closed: first point (0, 0) differs from last point "
                "(2, 1)");
}

TEST(AreaValidationTest, TooFewDistinctPoints) {
  PolygonInput p{Box(0, 0, 10, 10), {Box(1, 1, 2, 2), Box(3, 3, 4, 4), {{5, 5}, {6, 6}, {5, 5}}}};
  ExpectInvalid({p}, "regions", "regions[0].holes[2]: ring has 2 distinct points; at least 3");
  ExpectInvalid({{{}, {}}}, "regions", "regions[0].outer: ring has 0 distinct points");
}

TEST(AreaValidationTest, NonFiniteCoordinate) {
  Ring r = {{0, 0}, {1, 0}, {2, 0}, {2, 1}, {1, 1}, {0, 0}};
  r[4].y = std::numeric_limits<double>::infinity();
  ExpectInvalid({{r, {}}}, "regions", "regions[0].outer vertex 4: coordinate is not a finite");
  r[4].y = std::nan("");
  ExpectInvalid({{r, {}}}, "regions", "regions[0].outer vertex 4: coordinate is not a finite");
}

TEST(AreaValidationTest, SelfIntersectionNamesPointAndEdges) {
  const Ring bad = {{0, 0}, {4, 0}, {4, 2}, {1, 2}, {1, 5}, {3, 4}, {0, 0}};
  ExpectInvalid(
      {{Box(10, 0, 11, 1), {}}, {Box(12, 0, 13, 1), {}}, {Box(14, 0, 15, 1), {}}, {bad, {}}},
      "map.polygons", "map.polygons[3].outer: ring intersects itself at (1.5, 2) (edges 2 and 5)");
  // A ring touching itself at a vertex (figure eight) and a spike are not simple either.
  ExpectInvalid({{{{0, 0}, {2, 0}, {1, 1}, {2, 2}, {0, 2}, {1, 1}, {0, 0}}, {}}}, "a",
                "a[0].outer: ring intersects itself at (1, 1) (edges 1 and 4)");
  ExpectInvalid({{{{0, 0}, {2, 0}, {2, 2}, {1, 2}, {1, 3}, {1, 2}, {0, 2}, {0, 0}}, {}}}, "a",
                "a[0].outer: ring intersects itself at (1, 2) (edges 2 and 4)");
  ExpectInvalid({{{{0, 0}, {2, 0}, {2, 2}, {1, 2}, {1, 3}, {1, 2.5}, {0, 2}, {0, 0}}, {}}}, "a",
                "a[0].outer: ring intersects itself at (1, 2.5) (edges 3 and 4)");
  // Repeated points are not edges.
  EXPECT_TRUE(
      Area::Create({{{{0, 0}, {1, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}, {0, 0}}, {}}}, "a").ok());
}

TEST(AreaValidationTest, ZeroArea) {
  ExpectInvalid({{{{0, 0}, {1, 0}, {2, 0}, {0, 0}}, {}}}, "z", "z[0].outer: ring has zero area");
  ExpectInvalid({{Box(0, 0, 4, 4), {{{1, 1}, {2, 2}, {3, 3}, {1, 1}}}}}, "z",
                "z[0].holes[0]: ring has zero area");
}

TEST(AreaValidationTest, HolesOutsideOrOverlapping) {
  ExpectInvalid({{Box(0, 0, 4, 4), {Box(5, 5, 6, 6)}}}, "no_go",
                "no_go[0].holes[0]: hole lies outside its outer ring");
  ExpectInvalid({{Box(0, 0, 4, 4), {Box(1, 1, 2, 2), Box(3, 3, 5, 5)}}}, "no_go",
                "no_go[0].holes[1]: hole lies partly outside its outer ring");
  ExpectInvalid({{Box(0, 0, 4, 4), {Box(1, 1, 2, 2), Box(1.5, 1.5, 3, 3)}}}, "no_go",
                "no_go[0].holes[1]: hole overlaps holes[0]");
  ExpectInvalid({{Box(0, 0, 4, 4), {Box(1, 1, 3, 3), Box(1.5, 1.5, 2, 2)}}}, "no_go",
                "no_go[0].holes[1]: hole overlaps holes[0]");
}

TEST(AreaValidationTest, VertexLimit) {
  PolygonInput big{Ring(123456, Point2{0, 0}), {}};
  ExpectInvalid({big}, "regions", "regions: 123456 vertices exceed the limit of 100000");
  AreaLimits limits;
  limits.max_vertices = 10;
  EXPECT_TRUE(Area::Create({{Box(0, 0, 1, 1), {}}, {Box(2, 0, 3, 1), {}}}, "r", limits).ok());
  ExpectInvalid({{Box(0, 0, 1, 1), {Box(0.2, 0.2, 0.5, 0.5)}}, {Box(2, 0, 3, 1), {}}}, "r",
                "r: 15 vertices exceed the limit of 10", limits);
}

// Found by fuzz/geojson_fuzzer: Boost's union cannot resolve 1 m features 1.9e9 m apart.
TEST(AreaValidationTest, TooFineForExtent) {
  const std::vector<PolygonInput> far = {{{{0, 0}, {1, 0}, {5, 4}, {0, 0}}, {}},
                                         {{{1, 1}, {3, 2}, {2, 4}, {1888888888, 3}, {1, 1}}, {}}};
  ExpectInvalid(far, "z", "z: the polygons span 1.88889e+09 m, more than the limit of 1e+06 m");
  AreaLimits unlimited;
  unlimited.max_extent_m = 1e10;
  ExpectInvalid(far, "z", "z[0] and 1 other polygon(s) overlapping it: too fine for their extent",
                unlimited);
  ExpectInvalid(
      {{{{0, 0}, {1, 0}, {2, 2}, {0, 2}, {0, 0}}, {}}, {{{1, 1}, {3, 1}, {388888, 3}, {1, 1}}, {}}},
      "z", "z[0] and 1 other polygon(s) overlapping it: too fine for their extent");
  // Far apart but not overlapping: nothing to union, nothing lost.
  Area apart = MustCreate({{Box(0, 0, 1, 1), {}}, {Box(9e5, 0, 9e5 + 1, 1), {}}});
  EXPECT_NEAR(apart.AreaM2(), 2.0, 1e-6);
}

TEST(AreaTest, EmptyInputGivesEmptyArea) {
  Area a = MustCreate({});
  EXPECT_TRUE(a.empty());
  EXPECT_EQ(a.AreaM2(), 0.0);
  EXPECT_FALSE(a.Contains({0, 0}));
  EXPECT_EQ(a.CanonicalText(), "MULTIPOLYGON EMPTY");
  EXPECT_EQ(CellOverlapFractions(a, 2, 3, 1.0, {0, 0}), std::vector<float>(6, 0.0f));
  EXPECT_EQ(RasterizeArea(a, 0.1, RasterRule::kCentre).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(AreaTest, OverlappingAndTouchingPolygonsAreUnioned) {
  Area a = MustCreate({{Box(0, 0, 2, 2), {}}, {Box(1, 1, 3, 3), {}}});
  EXPECT_NEAR(a.AreaM2(), 7.0, 1e-12);
  EXPECT_EQ(a.ToPolygons().size(), 1u);
  EXPECT_EQ(a.min_corner().x, 0.0);
  EXPECT_EQ(a.max_corner().y, 3.0);
  Area touching = MustCreate({{Box(0, 0, 1, 1), {}}, {Box(1, 0, 2, 1), {}}, {Box(5, 5, 6, 6), {}}});
  EXPECT_NEAR(touching.AreaM2(), 3.0, 1e-12);
  EXPECT_EQ(touching.ToPolygons().size(), 2u);
  EXPECT_TRUE(touching.InInterior({1.0, 0.5}));  // the shared edge is interior now
}

TEST(AreaTest, OrientationAndOrderDoNotMatter) {
  const Ring ccw = {{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 3}, {0, 3}, {0, 0}};
  Ring rotated = {{3, 1}, {1, 1}, {1, 3}, {0, 3}, {0, 0}, {3, 0}, {3, 1}};
  Area a = MustCreate({{ccw, {}}, {Box(5, 5, 6, 6), {}}});
  Area b = MustCreate({{Reversed(Box(5, 5, 6, 6)), {}}, {Reversed(rotated), {}}});
  EXPECT_NEAR(a.AreaM2(), 6.0, 1e-12);
  EXPECT_NEAR(b.AreaM2(), 6.0, 1e-12);
  EXPECT_EQ(a.CanonicalText(), b.CanonicalText());
  EXPECT_NE(a.CanonicalText(), MustCreate({{ccw, {}}}).CanonicalText());
  EXPECT_THAT(a.CanonicalText(), HasSubstr("MULTIPOLYGON(((0 0,"));
}

TEST(AreaTest, HoleReducesAreaAndPointTests) {
  Area a = MustCreate({{Box(0, 0, 10, 10), {Reversed(Box(2, 2, 4, 4))}}});
  EXPECT_NEAR(a.AreaM2(), 96.0, 1e-12);
  EXPECT_EQ(a.num_vertices(), 8);
  EXPECT_FALSE(a.Contains({3, 3}));
  EXPECT_TRUE(a.Contains({2, 3}));  // hole boundary
  EXPECT_FALSE(a.InInterior({2, 3}));
  EXPECT_TRUE(a.InInterior({1, 1}));
  EXPECT_TRUE(a.Contains({10, 10}));
  EXPECT_FALSE(a.InInterior({10, 10}));
  EXPECT_NEAR(a.BoxOverlapM2(-1, -1, 3, 3), 9.0 - 1.0, 1e-12);
  ASSERT_EQ(a.ToPolygons().size(), 1u);
  EXPECT_EQ(a.ToPolygons()[0].holes.size(), 1u);
}

TEST(AreaTest, SegmentLengthInInterior) {
  Area sq = MustCreate({{Box(0, 0, 4, 4), {}}});
  EXPECT_NEAR(sq.SegmentLengthInInterior({-1, 1}, {5, 1}), 4.0, 1e-12);  // crossing
  EXPECT_NEAR(sq.SegmentLengthInInterior({-1, 3}, {1, 5}), 0.0, 1e-9);   // touches corner
  EXPECT_NEAR(sq.SegmentLengthInInterior({-1, 0}, {5, 0}), 0.0, 1e-9);   // along an edge
  EXPECT_NEAR(sq.SegmentLengthInInterior({4, 1}, {4, 3}), 0.0, 1e-9);
  EXPECT_NEAR(sq.SegmentLengthInInterior({1, 1}, {3, 2}), std::sqrt(5.0), 1e-12);  // inside
  EXPECT_NEAR(sq.SegmentLengthInInterior({0, 0}, {4, 4}), std::sqrt(32.0), 1e-12);
  Area holed = MustCreate({{Box(0, 0, 4, 4), {Box(1, 1, 3, 3)}}});
  EXPECT_NEAR(holed.SegmentLengthInInterior({-1, 2}, {5, 2}), 2.0, 1e-12);     // through hole
  EXPECT_NEAR(holed.SegmentLengthInInterior({1, 0.5}, {1, 3.5}), 1.0, 1e-12);  // along hole side
  Area ell = MustCreate({{{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}, {0, 0}}, {}}});
  EXPECT_NEAR(ell.SegmentLengthInInterior({-1, 1}, {3, 1}), 1.0, 1e-12);  // then along an edge
  Area tri = MustCreate({{{{0, 0}, {3, 1}, {0, 1}, {0, 0}}, {}}});
  EXPECT_NEAR(tri.SegmentLengthInInterior({0.3, 0.1}, {2.7, 0.9}), 0.0, 1e-9);  // diagonal edge
}

// Star-shaped (so simple, usually concave) polygon around c with n >= 8 vertices.
Ring RandomStar(std::mt19937& rng, Point2 c, double r_min, double r_max, int n) {
  std::uniform_real_distribution<double> jitter(-0.4, 0.4), radius(r_min, r_max);
  Ring ring;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * (i + jitter(rng)) / n;
    const double r = radius(rng);
    ring.push_back({c.x + r * std::cos(a), c.y + r * std::sin(a)});
  }
  ring.push_back(ring.front());
  return ring;
}

// Reference for the area of polygon rings clipped to a box: Sutherland-Hodgman (exact for a
// simple ring against a convex window) and the shoelace formula, in long double.
long double ClippedRingArea(const Ring& ring, double x0, double y0, double x1, double y1) {
  using P = std::pair<long double, long double>;
  std::vector<P> poly;
  for (size_t i = 0; i + 1 < ring.size(); ++i) poly.emplace_back(ring[i].x, ring[i].y);
  auto clip = [&](auto inside, auto cross) {
    std::vector<P> out;
    for (size_t i = 0; i < poly.size(); ++i) {
      const P& a = poly[i];
      const P& b = poly[(i + 1) % poly.size()];
      if (inside(b)) {
        if (!inside(a)) out.push_back(cross(a, b));
        out.push_back(b);
      } else if (inside(a)) {
        out.push_back(cross(a, b));
      }
    }
    poly = out;
  };
  auto at_x = [](long double x) {
    return [x](const P& a, const P& b) {
      return P{x, a.second + (b.second - a.second) * (x - a.first) / (b.first - a.first)};
    };
  };
  auto at_y = [](long double y) {
    return [y](const P& a, const P& b) {
      return P{a.first + (b.first - a.first) * (y - a.second) / (b.second - a.second), y};
    };
  };
  clip([&](const P& p) { return p.first >= x0; }, at_x(x0));
  clip([&](const P& p) { return p.first <= x1; }, at_x(x1));
  clip([&](const P& p) { return p.second >= y0; }, at_y(y0));
  clip([&](const P& p) { return p.second <= y1; }, at_y(y1));
  long double twice = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const P& a = poly[i];
    const P& b = poly[(i + 1) % poly.size()];
    twice += a.first * b.second - b.first * a.second;
  }
  return std::abs(twice) / 2;
}

double ReferenceBoxArea(const Area& area, double x0, double y0, double x1, double y1) {
  long double sum = 0;
  for (const PolygonInput& p : area.ToPolygons()) {
    sum += ClippedRingArea(p.outer, x0, y0, x1, y1);
    for (const Ring& h : p.holes) sum -= ClippedRingArea(h, x0, y0, x1, y1);
  }
  return static_cast<double>(sum);
}

// Two or three overlapping stars, one of them with a hole.
Area RandomArea(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(-2.0, 6.0);
  std::uniform_int_distribution<int> count(8, 40);
  std::vector<PolygonInput> polys;
  const int n = 2 + static_cast<int>(seed % 2);
  for (int k = 0; k < n; ++k) {
    const Point2 c{pos(rng), pos(rng)};
    PolygonInput p{RandomStar(rng, c, 1.5, 4.0, count(rng)), {}};
    if (k == 0) p.holes.push_back(RandomStar(rng, c, 0.3, 0.7, count(rng)));
    polys.push_back(p);
  }
  return MustCreate(polys);
}

TEST(CellOverlapFractionsTest, MatchesPerCellClippingAndSampling) {
  for (uint32_t seed = 1; seed <= 12; ++seed) {
    SCOPED_TRACE(seed);
    const Area area = RandomArea(seed);
    // The grid cuts through the area on the left and bottom and extends past it elsewhere.
    const double cell = 0.37;
    const Point2 origin{-1.3, -0.9};
    const int rows = 40, cols = 36;
    const std::vector<float> f = CellOverlapFractions(area, rows, cols, cell, origin);
    ASSERT_EQ(f.size(), static_cast<size_t>(rows * cols));
    std::mt19937 rng(seed);
    double total = 0.0;
    int sampled = 0;
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        const double x0 = origin.x + c * cell, y0 = origin.y + r * cell;
        const double exact = area.BoxOverlapM2(x0, y0, x0 + cell, y0 + cell) / (cell * cell);
        const double ref = ReferenceBoxArea(area, x0, y0, x0 + cell, y0 + cell) / (cell * cell);
        const float got = f[r * cols + c];
        // Boost.Geometry 1.74 snaps overlay turn points to 1e-7 of the inputs' extent, so
        // clipped areas agree to a few 1e-6 of a cell here, not to float precision.
        ASSERT_NEAR(got, exact, 2e-5) << "cell " << r << "," << c;
        ASSERT_NEAR(got, ref, 2e-5) << "cell " << r << "," << c;
        total += got * cell * cell;
        if (got > 0 && got < 1 && rng() % 8 == 0) {  // point sampling on some boundary cells
          const int s = 40;
          int in = 0;
          for (int i = 0; i < s; ++i) {
            for (int j = 0; j < s; ++j) {
              in += area.Contains({x0 + (j + 0.5) * cell / s, y0 + (i + 0.5) * cell / s});
            }
          }
          EXPECT_NEAR(got, static_cast<double>(in) / (s * s), 0.05) << "cell " << r << "," << c;
          ++sampled;
        }
      }
    }
    EXPECT_GT(sampled, 0);
    const Point2 hi{origin.x + cols * cell, origin.y + rows * cell};
    EXPECT_NEAR(total, area.BoxOverlapM2(origin.x, origin.y, hi.x, hi.y), 1e-4);
    EXPECT_LT(total, area.AreaM2() - 0.1);  // the grid really cuts the area
  }
}

TEST(CellOverlapFractionsTest, GridAlignedEdgesAndOutsideGrid) {
  Area a = MustCreate({{Box(1, 1, 3, 2), {}}});
  const std::vector<float> f = CellOverlapFractions(a, 3, 4, 1.0, {0, 0});
  const std::vector<float> want = {0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 0};
  for (size_t i = 0; i < f.size(); ++i) EXPECT_NEAR(f[i], want[i], 1e-6) << i;
  EXPECT_EQ(CellOverlapFractions(a, 2, 2, 1.0, {10, 10}), std::vector<float>(4, 0.0f));
  EXPECT_TRUE(CellOverlapFractions(a, 0, 5, 1.0, {0, 0}).empty());
}

// Found by fuzz/geojson_fuzzer, all wrong in Boost 1.74's overlay: an edge through cell
// corners (whole cells returned), polygons touching at a cell corner (seen as crossing), and
// a hole touching its outer ring on a cell side.
TEST(CellOverlapFractionsTest, FuzzFoundDegenerateCells) {
  Area a = MustCreate({{{{0, 0}, {2, 0}, {3, 2}, {0, 2}, {0, 0}}, {}},
                       {{{1, 1}, {6, 0}, {3, 3}, {0, 3}, {1, 1}}, {}}});
  const double cell = 6.0 / 14;
  std::vector<float> f = CellOverlapFractions(a, 16, 16, cell, {-cell, -cell});
  double total = 0.0;
  for (float v : f) total += v * cell * cell;
  EXPECT_NEAR(total, a.AreaM2(), 1e-5);
  EXPECT_EQ(f[4 * 16 + 12], 0.0f);
  EXPECT_EQ(f[5 * 16 + 11], 0.0f);
  Area touching = MustCreate(
      {{{{0, 0}, {2, 0}, {0, 2}, {0, 0}}, {}}, {{{1, 1}, {7, 2}, {6, 3}, {1, 3}, {1, 1}}, {}}});
  ASSERT_EQ(touching.ToPolygons().size(), 2u);
  f = CellOverlapFractions(touching, 16, 16, 0.5, {-0.5, -0.5});
  EXPECT_NEAR(f[3 * 16 + 2], 0.5, 1e-5);
  EXPECT_NEAR(f[3 * 16 + 3], 11.0 / 12, 1e-5);
  EXPECT_NEAR(touching.BoxOverlapM2(0.5, 1, 1, 1.5), 0.125, 1e-6);
  Area hole = MustCreate(
      {{{{0, 0}, {5, 0}, {4, 4}, {0, 43}, {0, 0}}, {{{1, 1}, {0, 2}, {4, 2}, {2, 1}, {1, 1}}}}});
  const double c = 43.0 / 14;
  f = CellOverlapFractions(hole, 16, 16, c, {-c, -c});
  EXPECT_NEAR(f[1 * 16 + 1], ReferenceBoxArea(hole, 0, 0, c, c) / (c * c), 1e-5);
  total = 0.0;
  for (float v : f) total += v * c * c;
  EXPECT_NEAR(total, hole.AreaM2(), 1e-4);
  // A hole edge through a cell corner: Boost clipped the hole to the whole cell.
  Area corner = MustCreate(
      {{{{0, 0}, {8, 0}, {4, 4}, {0, 20}, {0, 0}}, {{{1, 1}, {5, 0}, {2, 4}, {3, 2}, {1, 1}}}}});
  const double k = 20.0 / 14;
  f = CellOverlapFractions(corner, 16, 16, k, {-k, -k});
  EXPECT_NEAR(f[3 * 16 + 3], ReferenceBoxArea(corner, 2 * k, 2 * k, 3 * k, 3 * k) / (k * k), 1e-5);
  EXPECT_NEAR(corner.BoxOverlapM2(2 * k, 2 * k, 3 * k, 3 * k) / (k * k), f[3 * 16 + 3], 1e-5);
}

// Areas with many edges are clipped in blocks of columns; compare a band of cells.
TEST(CellOverlapFractionsTest, ManyEdgesMatchReference) {
  std::mt19937 rng(11);
  const Area a = MustCreate({{RandomStar(rng, {0, 0}, 5, 10, 600), {}}});
  const double cell = 0.45;
  const Point2 origin{-10.1, -10.2};
  const int rows = 46, cols = 46;
  const std::vector<float> f = CellOverlapFractions(a, rows, cols, cell, origin);
  for (int r = 20; r < 26; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double x0 = origin.x + c * cell, y0 = origin.y + r * cell;
      const double ref = ReferenceBoxArea(a, x0, y0, x0 + cell, y0 + cell) / (cell * cell);
      ASSERT_NEAR(f[r * cols + c], ref, 2e-5) << r << "," << c;
    }
  }
}

TEST(CellOverlapFractionsTest, MillionCellsSumToArea) {
  std::mt19937 rng(7);
  Ring star = RandomStar(rng, {50, 50}, 20, 49, 100);
  Area a = MustCreate({{star, {RandomStar(rng, {50, 50}, 2, 8, 30)}}});
  const std::vector<float> f = CellOverlapFractions(a, 1000, 1000, 0.1, {0, 0});
  double total = 0.0;
  for (float v : f) total += v;
  EXPECT_NEAR(total * 0.01, a.AreaM2(), 1e-3 * a.AreaM2());
}

TEST(RasterizeAreaTest, CentreAndInsideRulesMatchPointTests) {
  for (uint32_t seed = 20; seed < 26; ++seed) {
    SCOPED_TRACE(seed);
    const Area area = RandomArea(seed);
    const double res = 0.21;
    absl::StatusOr<OccupancyMap> centre = RasterizeArea(area, res, RasterRule::kCentre);
    absl::StatusOr<OccupancyMap> inside = RasterizeArea(area, res, RasterRule::kInside);
    ASSERT_TRUE(centre.ok() && inside.ok());
    ASSERT_EQ(centre->width(), inside->width());
    const Point2 o = centre->origin();
    EXPECT_NEAR(o.x, std::floor(area.min_corner().x / res) * res, 1e-12);
    EXPECT_NEAR(o.y, std::floor(area.min_corner().y / res) * res, 1e-12);
    EXPECT_GE(o.x + centre->width() * res, area.max_corner().x);
    EXPECT_GE(o.y + centre->height() * res, area.max_corner().y);
    EXPECT_LT(o.x + (centre->width() - 1) * res, area.max_corner().x);
    for (int r = 0; r < centre->height(); ++r) {
      for (int c = 0; c < centre->width(); ++c) {
        const Point2 mid{o.x + (c + 0.5) * res, o.y + (r + 0.5) * res};
        ASSERT_EQ(centre->IsFree(r, c), area.Contains(mid)) << r << "," << c;
        EXPECT_NE(centre->at(r, c), CellState::kUnknown);
        const double x0 = o.x + c * res, y0 = o.y + r * res;
        const bool covered =
            area.BoxOverlapM2(x0, y0, x0 + res, y0 + res) >= res * res * (1 - 1e-9);
        ASSERT_EQ(inside->IsFree(r, c), covered) << r << "," << c;
        if (inside->IsFree(r, c)) {
          EXPECT_TRUE(area.Contains({x0, y0}) && area.Contains({x0 + res, y0 + res}));
        }
      }
    }
  }
}

TEST(RasterizeAreaTest, PixelAlignedSquareAndLimits) {
  Area a = MustCreate({{Box(0, 0, 2, 1.5), {Box(0.5, 0.5, 1, 1)}}});
  absl::StatusOr<OccupancyMap> m = RasterizeArea(a, 0.5, RasterRule::kInside);
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_EQ(m->width(), 4);
  EXPECT_EQ(m->height(), 3);
  EXPECT_EQ(m->CountFree(), 11);
  EXPECT_FALSE(m->IsFree(1, 1));
  EXPECT_EQ(RasterizeArea(a, 0.5, RasterRule::kCentre)->CountFree(), 11);
  EXPECT_EQ(RasterizeArea(a, 0.01, RasterRule::kCentre, 1000).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(RasterizeArea(a, 0.0, RasterRule::kCentre).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(RasterizeArea(a, std::nan(""), RasterRule::kInside).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace covplan
