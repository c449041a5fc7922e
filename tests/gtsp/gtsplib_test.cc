// GTSPLIB reader: every supported edge-weight type against hand-computed
// distances, and malformed or truncated files.
#include <random>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "planner/tour/gtsp/gtsplib.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

std::string Coords(const std::string& type, const std::string& nodes, int n,
                   const std::string& sets, int m) {
  return "NAME : tiny\nTYPE : GTSP\nCOMMENT : test\nDIMENSION : " + std::to_string(n) +
         "\nGTSP_SETS : " + std::to_string(m) + "\nEDGE_WEIGHT_TYPE : " + type +
         "\nNODE_COORD_SECTION\n" + nodes + "GTSP_SET_SECTION\n" + sets + "EOF\n";
}

GtspInstance MustParse(const std::string& text) {
  absl::StatusOr<GtspLibFile> f = ParseGtspLib(text);
  EXPECT_TRUE(f.ok()) << f.status();
  return f.ok() ? f->instance : GtspInstance();
}

constexpr char kFourNodes[] = "1 0 0\n2 3 4\n3 1 1\n4 10 0\n";
constexpr char kTwoSets[] = "1 1 3 -1\n2 2 4 -1\n";

TEST(GtspLibTest, Euc2dRoundsToNearest) {
  absl::StatusOr<GtspLibFile> f = ParseGtspLib(Coords("EUC_2D", kFourNodes, 4, kTwoSets, 2));
  ASSERT_TRUE(f.ok()) << f.status();
  EXPECT_EQ(f->name, "tiny");
  const GtspInstance& g = f->instance;
  EXPECT_EQ(g.num_vertices, 4);
  EXPECT_EQ(g.sets, (std::vector<std::vector<int>>{{0, 2}, {1, 3}}));
  EXPECT_EQ(g.cost(0, 1), 5);  // 3-4-5
  EXPECT_EQ(g.cost(0, 2), 1);  // sqrt 2 = 1.41
  EXPECT_EQ(g.cost(1, 2), 4);  // sqrt 13 = 3.61
  EXPECT_EQ(g.cost(1, 3), 8);  // sqrt 65 = 8.06
  EXPECT_EQ(g.cost(2, 3), 9);  // sqrt 82 = 9.06
  EXPECT_EQ(g.cost(3, 0), 10);
  EXPECT_EQ(g.cost(2, 2), 0);
}

TEST(GtspLibTest, Ceil2dRoundsUp) {
  const GtspInstance g = MustParse(Coords("CEIL_2D", kFourNodes, 4, kTwoSets, 2));
  EXPECT_EQ(g.cost(0, 1), 5);
  EXPECT_EQ(g.cost(0, 2), 2);
  EXPECT_EQ(g.cost(2, 1), 4);
  EXPECT_EQ(g.cost(1, 3), 9);
  EXPECT_EQ(g.cost(3, 2), 10);
}

TEST(GtspLibTest, AttPseudoEuclidean) {
  const GtspInstance g =
      MustParse(Coords("ATT", "1 0 0\n2 10 0\n3 0 30\n", 3, "1 1 -1\n2 2 3 -1\n", 2));
  EXPECT_EQ(g.cost(0, 1), 4);   // sqrt(10) = 3.16 -> nint 3 < 3.16 -> 4
  EXPECT_EQ(g.cost(0, 2), 10);  // sqrt(90) = 9.49 -> 9 < 9.49 -> 10
  EXPECT_EQ(g.cost(1, 2), 10);  // sqrt(100) = 10 exactly
}

TEST(GtspLibTest, GeoUsesDegreesMinutesAndEarthRadius) {
  const GtspInstance g =
      MustParse(Coords("GEO", "1 0.00 0.00\n2 0.00 1.00\n3 0.30 0.00\n4 45.30 -10.45\n", 4,
                       "1 1 2 -1\n2 3 4 -1\n", 2));
  EXPECT_EQ(g.cost(0, 1), 112);  // 1 degree of longitude on the equator: 111.3 km, +1 truncated
  EXPECT_EQ(g.cost(0, 2), 56);   // 0.30 = 30 minutes of latitude: 55.7 km
  EXPECT_EQ(g.cost(1, 2), 125);
  EXPECT_EQ(g.cost(0, 3), 5175);
  EXPECT_EQ(g.cost(3, 3), 0);
}

std::string Explicit(const std::string& format, const std::string& weights) {
  return "NAME: e\nTYPE: AGTSP\nDIMENSION: 4\nGTSP_SETS: 2\nEDGE_WEIGHT_TYPE: EXPLICIT\n"
         "EDGE_WEIGHT_FORMAT: " +
         format + "\nEDGE_WEIGHT_SECTION\n" + weights +
         "\nGTSP_SET_SECTION:\n1 1 2 -1\n2 3 4 -1\nEOF\n";
}

TEST(GtspLibTest, ExplicitFullMatrixIsAsymmetric) {
  const GtspInstance g =
      MustParse(Explicit("FULL_MATRIX", "0 1 2 3\n4 0 5 6\n7 8 0 9\n10 11 12 0"));
  EXPECT_EQ(g.cost(0, 3), 3);
  EXPECT_EQ(g.cost(3, 0), 10);
  EXPECT_EQ(g.cost(1, 2), 5);
  EXPECT_EQ(g.cost(2, 1), 8);
  EXPECT_EQ(g.cost(3, 2), 12);
}

void ExpectTriangle(const GtspInstance& g, bool upper) {
  // Weights "1 2 3 4 5 6" read row by row.
  const int expect_upper[4][4] = {{0, 1, 2, 3}, {1, 0, 4, 5}, {2, 4, 0, 6}, {3, 5, 6, 0}};
  const int expect_lower[4][4] = {{0, 1, 2, 4}, {1, 0, 3, 5}, {2, 3, 0, 6}, {4, 5, 6, 0}};
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      EXPECT_EQ(g.cost(i, j), upper ? expect_upper[i][j] : expect_lower[i][j]) << i << "," << j;
    }
  }
}

TEST(GtspLibTest, ExplicitTriangularFormats) {
  ExpectTriangle(MustParse(Explicit("UPPER_ROW", "1 2 3\n4 5\n6")), true);
  ExpectTriangle(MustParse(Explicit("LOWER_ROW", "1\n2 3\n4 5 6")), false);
  ExpectTriangle(MustParse(Explicit("UPPER_DIAG_ROW", "0 1 2 3 0 4 5 0 6 0")), true);
  ExpectTriangle(MustParse(Explicit("LOWER_DIAG_ROW", "0\n1 0\n2 3 0\n4 5 6 0")), false);
}

TEST(GtspLibTest, SetsMaySpanLinesAndSkipsDisplayData) {
  const std::string text =
      "NAME:x\nDIMENSION:3\nGTSP_SETS:2\nEDGE_WEIGHT_TYPE:EUC_2D\nNODE_COORD_SECTION\n"
      "1 0 0\n2 0 3\n3 4 0\nDISPLAY_DATA_SECTION\n1 5 5\nGTSP_SET_SECTION\n2 3\n-1 1 1 "
      "2\n-1\nEOF\n";
  const GtspInstance g = MustParse(text);
  EXPECT_EQ(g.sets, (std::vector<std::vector<int>>{{0, 1}, {2}}));
  EXPECT_EQ(g.cost(1, 2), 5);
}

void ExpectParseError(const std::string& text, const std::string& fragment) {
  absl::StatusOr<GtspLibFile> f = ParseGtspLib(text);
  ASSERT_FALSE(f.ok()) << "parsed: " << text;
  EXPECT_EQ(f.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(f.status().message()), HasSubstr(fragment));
}

TEST(GtspLibTest, MalformedFilesAreRejectedWithLineInfo) {
  const std::string ok = Coords("EUC_2D", kFourNodes, 4, kTwoSets, 2);
  ASSERT_TRUE(ParseGtspLib(ok).ok());
  ExpectParseError("", "missing DIMENSION");
  ExpectParseError(Coords("EUC_2D", "1 0 0\n2 3 4\n3 1 1\n", 4, kTwoSets, 2),
                   "expected 3 per node");
  ExpectParseError(Coords("EUC_2D", "1 0 0\n2 3 x\n3 1 1\n4 10 0\n", 4, kTwoSets, 2),
                   "line 9: expected a number, got 'x'");
  ExpectParseError(Coords("EUC_2D", "1 0 0\n2 3 4\n2 1 1\n4 10 0\n", 4, kTwoSets, 2), "repeated");
  ExpectParseError(Coords("EUC_3D", kFourNodes, 4, kTwoSets, 2), "unsupported EDGE_WEIGHT_TYPE");
  ExpectParseError(Coords("EUC_2D", kFourNodes, 4, "1 1 3 -1\n2 2 4\n", 2), "not terminated by -1");
  ExpectParseError(Coords("EUC_2D", kFourNodes, 4, "1 1 3 -1\n1 2 4 -1\n", 2), "set id 1");
  ExpectParseError(Coords("EUC_2D", kFourNodes, 4, "1 1 3 -1\n2 2 5 -1\n", 2), "outside [1, 4]");
  // Messages name vertices and sets by the file's 1-based ids.
  ExpectParseError(Coords("EUC_2D", kFourNodes, 4, "1 1 3 -1\n2 2 -1\n", 2),
                   "vertex 4 belongs to no set");
  ExpectParseError(Coords("EUC_2D", kFourNodes, 4, "1 1 3 -1\n2 2 3 4 -1\n", 2),
                   "line 14: vertex 3 is in set 1 and in set 2; sets must be disjoint");
  ExpectParseError(Coords("EUC_2D", kFourNodes, 4, "1 1 2 3 4 -1\n2 -1\n", 2), "set 2 is empty");
  ExpectParseError(Coords("EUC_2D", kFourNodes, 4, "1 1 3 -1\n", 2), "ends after 1 of 2 sets");
  ExpectParseError(Coords("EUC_2D", kFourNodes, 4, "1 1 3 -1\n2 2 4 -1\n3 -1\n", 2),
                   "unexpected data");
  ExpectParseError(Coords("EUC_2D", kFourNodes, 4, kTwoSets, 3),
                   "GTSP_SET_SECTION ends after 2 of 3");
  ExpectParseError(Coords("EUC_2D", kFourNodes, 4, kTwoSets, 7), "exceeds DIMENSION");
  ExpectParseError("DIMENSION : -3\n", "line 1: DIMENSION must be in [1, 10000]");
  ExpectParseError("DIMENSION : many\n", "line 1: expected an integer");
  ExpectParseError("1 2 3\n", "line 1: data outside of any section");
  ExpectParseError(
      "DIMENSION: 4\nGTSP_SETS: 2\nEDGE_WEIGHT_TYPE: EUC_2D\nGTSP_SET_SECTION\n1 1 3 -1\n2 2 4 "
      "-1\n",
      "missing NODE_COORD_SECTION");
  ExpectParseError(Explicit("FULL_MATRIX", "0 1 2 3\n4 0 5 6\n7 8 0 9\n10 11 12"),
                   "has 15 numbers, expected 16");
  ExpectParseError(Explicit("UPPER_ROW", "1 2 3\n4 -5\n6"), "line 9: negative edge weight");
  ExpectParseError(Explicit("FUNCTION", "1"), "unsupported EDGE_WEIGHT_FORMAT");
}

// Truncating a valid file anywhere, or corrupting bytes, must give an error
// or a valid instance, never a crash.
TEST(GtspLibTest, TruncatedAndCorruptedFilesNeverCrash) {
  const std::string texts[] = {Coords("EUC_2D", kFourNodes, 4, kTwoSets, 2),
                               Explicit("LOWER_DIAG_ROW", "0\n1 0\n2 3 0\n4 5 6 0")};
  std::mt19937 rng(5);
  for (const std::string& text : texts) {
    for (size_t len = 0; len < text.size(); ++len) {
      absl::StatusOr<GtspLibFile> f = ParseGtspLib(text.substr(0, len));
      if (!f.ok()) {
        EXPECT_EQ(f.status().code(), absl::StatusCode::kInvalidArgument);
      } else {
        EXPECT_TRUE(f->instance.Validate().ok());
      }
    }
    const std::string alphabet = "0123456789 -:\n.eE_ABCXYZ+";
    for (int trial = 0; trial < 2000; ++trial) {
      std::string mutated = text;
      for (int k = 0; k < 3; ++k) {
        mutated[rng() % mutated.size()] = alphabet[rng() % alphabet.size()];
      }
      absl::StatusOr<GtspLibFile> f = ParseGtspLib(mutated);
      if (!f.ok()) {
        EXPECT_EQ(f.status().code(), absl::StatusCode::kInvalidArgument);
      } else {
        EXPECT_TRUE(f->instance.Validate().ok());
      }
    }
  }
}

TEST(GtspLibTest, LoadReportsMissingFile) {
  absl::StatusOr<GtspLibFile> f = LoadGtspLibFile("/nonexistent/dir/x.gtsp");
  EXPECT_EQ(f.status().code(), absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace covplan
