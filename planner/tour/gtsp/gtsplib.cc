#include "planner/tour/gtsp/gtsplib.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"

namespace covplan {
namespace {

// Dense matrices beyond this would need gigabytes; GTSPLIB stays far below.
constexpr long kMaxDimension = 10000;

struct Token {
  absl::string_view text;
  int line;
};

enum class Section { kNone, kCoords, kWeights, kSets, kSkip };

absl::Status Error(int line, absl::string_view what) {
  return absl::InvalidArgumentError(absl::StrCat("GTSPLIB line ", line, ": ", what));
}

absl::Status ParseDouble(const Token& t, double& out) {
  const char* end = t.text.data() + t.text.size();
  const char* begin = t.text.data();
  if (begin != end && *begin == '+') ++begin;
  auto [ptr, ec] = std::from_chars(begin, end, out);
  if (ec != std::errc() || ptr != end || !std::isfinite(out)) {
    return Error(t.line, absl::StrCat("expected a number, got '", t.text, "'"));
  }
  return absl::OkStatus();
}

absl::Status ParseLong(const Token& t, long& out) {
  const char* end = t.text.data() + t.text.size();
  const char* begin = t.text.data();
  if (begin != end && *begin == '+') ++begin;
  auto [ptr, ec] = std::from_chars(begin, end, out);
  if (ec != std::errc() || ptr != end) {
    return Error(t.line, absl::StrCat("expected an integer, got '", t.text, "'"));
  }
  return absl::OkStatus();
}

int Nint(double x) { return static_cast<int>(x + 0.5); }

double GeoRadians(double x) {
  constexpr double kPi = 3.141592;  // TSPLIB's value, part of the metric's definition
  const double deg = std::trunc(x);
  const double min = x - deg;
  return kPi * (deg + 5.0 * min / 3.0) / 180.0;
}

struct Header {
  std::string name;
  long dimension = -1;
  long num_sets = -1;
  std::string weight_type;
  std::string weight_format;
  int last_line = 0;
  std::vector<Token> coords, weights, sets;
  int coords_line = 0, weights_line = 0, sets_line = 0;
};

absl::Status ReadSections(absl::string_view text, Header& h) {
  Section section = Section::kNone;
  int line_no = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_no;
    line = absl::StripAsciiWhitespace(line);
    if (line.empty()) continue;
    const char c0 = line.front();
    const bool keyword = absl::ascii_isalpha(static_cast<unsigned char>(c0)) || c0 == '_';
    if (!keyword) {
      std::vector<Token>* dst = nullptr;
      switch (section) {
        case Section::kCoords:
          dst = &h.coords;
          break;
        case Section::kWeights:
          dst = &h.weights;
          break;
        case Section::kSets:
          dst = &h.sets;
          break;
        case Section::kSkip:
          continue;
        case Section::kNone:
          return Error(line_no, absl::StrCat("data outside of any section: '", line, "'"));
      }
      for (absl::string_view tok :
           absl::StrSplit(line, absl::ByAnyChar(" \t\r\v\f"), absl::SkipEmpty())) {
        dst->push_back({tok, line_no});
      }
      continue;
    }
    absl::string_view key = line, value;
    if (size_t colon = line.find(':'); colon != absl::string_view::npos) {
      key = absl::StripAsciiWhitespace(line.substr(0, colon));
      value = absl::StripAsciiWhitespace(line.substr(colon + 1));
    } else if (size_t sp = line.find_first_of(" \t"); sp != absl::string_view::npos) {
      key = line.substr(0, sp);
      value = absl::StripAsciiWhitespace(line.substr(sp));
    }
    const std::string k = absl::AsciiStrToUpper(key);
    section = Section::kNone;
    if (k == "EOF") break;
    if (k == "NAME") {
      h.name = std::string(value);
    } else if (k == "DIMENSION" || k == "GTSP_SETS") {
      long v = 0;
      if (absl::Status st = ParseLong({value, line_no}, v); !st.ok()) return st;
      if (v <= 0 || v > kMaxDimension) {
        return Error(line_no, absl::StrCat(k, " must be in [1, ", kMaxDimension, "], got ", v));
      }
      (k == "DIMENSION" ? h.dimension : h.num_sets) = v;
    } else if (k == "EDGE_WEIGHT_TYPE") {
      h.weight_type = absl::AsciiStrToUpper(value);
    } else if (k == "EDGE_WEIGHT_FORMAT") {
      h.weight_format = absl::AsciiStrToUpper(value);
    } else if (k == "NODE_COORD_SECTION") {
      section = Section::kCoords;
      h.coords_line = line_no;
    } else if (k == "EDGE_WEIGHT_SECTION") {
      section = Section::kWeights;
      h.weights_line = line_no;
    } else if (k == "GTSP_SET_SECTION") {
      section = Section::kSets;
      h.sets_line = line_no;
    } else if (absl::EndsWith(k, "_SECTION")) {
      section = Section::kSkip;  // DISPLAY_DATA_SECTION, FIXED_EDGES_SECTION, ...
    }
    // Other keywords (TYPE, COMMENT, NODE_COORD_TYPE, ...) carry nothing we need.
  }
  h.last_line = line_no;
  return absl::OkStatus();
}

absl::Status FillFromCoordinates(const Header& h, GtspInstance& inst) {
  const int n = inst.num_vertices;
  if (h.coords_line == 0) return Error(h.last_line, "missing NODE_COORD_SECTION");
  if (h.coords.size() != static_cast<size_t>(3) * n) {
    const int line = h.coords.empty() ? h.coords_line : h.coords.back().line;
    return Error(line, absl::StrCat("NODE_COORD_SECTION has ", h.coords.size(),
                                    " numbers, expected 3 per node (id x y) for ", n, " nodes"));
  }
  inst.costs.assign(static_cast<size_t>(n) * n, 0.0);
  std::vector<double> x(n), y(n);
  std::vector<char> seen(n, 0);
  for (int i = 0; i < n; ++i) {
    long id = 0;
    if (absl::Status st = ParseLong(h.coords[3 * i], id); !st.ok()) return st;
    if (id < 1 || id > n || seen[id - 1]) {
      return Error(h.coords[3 * i].line,
                   absl::StrCat("node id ", id, " is out of range [1, ", n, "] or repeated"));
    }
    seen[id - 1] = 1;
    if (absl::Status st = ParseDouble(h.coords[3 * i + 1], x[id - 1]); !st.ok()) return st;
    if (absl::Status st = ParseDouble(h.coords[3 * i + 2], y[id - 1]); !st.ok()) return st;
  }
  const std::string& type = h.weight_type;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      double d = 0.0;
      if (i != j) {
        const double dx = x[i] - x[j], dy = y[i] - y[j];
        if (type == "EUC_2D") {
          d = Nint(std::sqrt(dx * dx + dy * dy));
        } else if (type == "CEIL_2D") {
          d = std::ceil(std::sqrt(dx * dx + dy * dy));
        } else if (type == "ATT") {
          const double r = std::sqrt((dx * dx + dy * dy) / 10.0);
          const int t = Nint(r);
          d = t < r ? t + 1 : t;
        } else {  // GEO
          constexpr double kEarthRadius = 6378.388;
          const double lat_i = GeoRadians(x[i]), lon_i = GeoRadians(y[i]);
          const double lat_j = GeoRadians(x[j]), lon_j = GeoRadians(y[j]);
          const double q1 = std::cos(lon_i - lon_j), q2 = std::cos(lat_i - lat_j),
                       q3 = std::cos(lat_i + lat_j);
          const double arg = std::clamp(0.5 * ((1.0 + q1) * q2 - (1.0 - q1) * q3), -1.0, 1.0);
          d = static_cast<int>(kEarthRadius * std::acos(arg) + 1.0);
        }
      }
      inst.costs[static_cast<size_t>(i) * n + j] = d;
    }
  }
  return absl::OkStatus();
}

absl::Status FillFromWeights(const Header& h, GtspInstance& inst) {
  const long n = inst.num_vertices;
  if (h.weights_line == 0) return Error(h.last_line, "missing EDGE_WEIGHT_SECTION");
  const std::string& f = h.weight_format;
  long expected = 0;
  if (f == "FULL_MATRIX") {
    expected = n * n;
  } else if (f == "UPPER_ROW" || f == "LOWER_ROW") {
    expected = n * (n - 1) / 2;
  } else if (f == "UPPER_DIAG_ROW" || f == "LOWER_DIAG_ROW") {
    expected = n * (n + 1) / 2;
  } else {
    return Error(h.weights_line,
                 absl::StrCat("unsupported EDGE_WEIGHT_FORMAT '", f,
                              "' (FULL_MATRIX, UPPER_ROW, LOWER_ROW, UPPER_DIAG_ROW, "
                              "LOWER_DIAG_ROW are supported)"));
  }
  if (h.weights.size() != static_cast<size_t>(expected)) {
    const int line = h.weights.empty() ? h.weights_line : h.weights.back().line;
    return Error(line,
                 absl::StrCat("EDGE_WEIGHT_SECTION has ", h.weights.size(), " numbers, expected ",
                              expected, " for ", f, " with DIMENSION ", n));
  }
  inst.costs.assign(static_cast<size_t>(n) * n, 0.0);
  size_t k = 0;
  auto next = [&](long i, long j, bool symmetric) -> absl::Status {
    double w = 0.0;
    if (absl::Status st = ParseDouble(h.weights[k], w); !st.ok()) return st;
    if (w < 0.0) return Error(h.weights[k].line, absl::StrCat("negative edge weight ", w));
    ++k;
    inst.costs[static_cast<size_t>(i) * n + j] = w;
    if (symmetric) inst.costs[static_cast<size_t>(j) * n + i] = w;
    return absl::OkStatus();
  };
  for (long i = 0; i < n; ++i) {
    long lo = 0, hi = n;  // FULL_MATRIX row i: j in [lo, hi)
    if (f == "UPPER_ROW") lo = i + 1;
    if (f == "UPPER_DIAG_ROW") lo = i;
    if (f == "LOWER_ROW") hi = i;
    if (f == "LOWER_DIAG_ROW") hi = i + 1;
    for (long j = lo; j < hi; ++j) {
      if (absl::Status st = next(i, j, f != "FULL_MATRIX"); !st.ok()) return st;
    }
  }
  return absl::OkStatus();
}

absl::Status FillSets(const Header& h, GtspInstance& inst) {
  const long m = h.num_sets;
  if (h.sets_line == 0) return Error(h.last_line, "missing GTSP_SET_SECTION");
  inst.sets.assign(m, {});
  std::vector<char> seen(m, 0);
  std::vector<long> owner(inst.num_vertices, 0);  // 1-based set id, 0 = none
  size_t k = 0;
  for (long s = 0; s < m; ++s) {
    if (k >= h.sets.size()) {
      return Error(h.sets.empty() ? h.sets_line : h.sets.back().line,
                   absl::StrCat("GTSP_SET_SECTION ends after ", s, " of ", m, " sets"));
    }
    long id = 0;
    if (absl::Status st = ParseLong(h.sets[k], id); !st.ok()) return st;
    if (id < 1 || id > m || seen[id - 1]) {
      return Error(h.sets[k].line,
                   absl::StrCat("set id ", id, " is out of range [1, ", m, "] or repeated"));
    }
    seen[id - 1] = 1;
    const int set_line = h.sets[k].line;
    ++k;
    for (;;) {
      if (k >= h.sets.size())
        return Error(set_line, absl::StrCat("set ", id, " is not terminated by -1"));
      long v = 0;
      if (absl::Status st = ParseLong(h.sets[k], v); !st.ok()) return st;
      ++k;
      if (v == -1) break;
      if (v < 1 || v > inst.num_vertices) {
        return Error(h.sets[k - 1].line, absl::StrCat("set ", id, " lists vertex ", v,
                                                      ", outside [1, ", inst.num_vertices, "]"));
      }
      if (owner[v - 1] != 0) {
        return Error(h.sets[k - 1].line,
                     absl::StrCat("vertex ", v, " is in set ", owner[v - 1], " and in set ", id,
                                  "; sets must be disjoint"));
      }
      owner[v - 1] = id;
      inst.sets[id - 1].push_back(static_cast<int>(v - 1));
    }
    if (inst.sets[id - 1].empty()) return Error(set_line, absl::StrCat("set ", id, " is empty"));
  }
  if (k != h.sets.size()) {
    return Error(h.sets[k].line,
                 absl::StrCat("unexpected data after the ", m, " sets of GTSP_SET_SECTION"));
  }
  for (long v = 0; v < inst.num_vertices; ++v) {
    if (owner[v] == 0) {
      return Error(h.sets_line, absl::StrCat("vertex ", v + 1,
                                             " belongs to no set; the sets must "
                                             "partition the vertices 1..",
                                             inst.num_vertices));
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<GtspLibFile> ParseGtspLib(std::string_view text) {
  // Debian's abseil has its own string_view type.
  Header h;
  if (absl::Status st = ReadSections(absl::string_view(text.data(), text.size()), h); !st.ok())
    return st;
  if (h.dimension < 0) return Error(h.last_line, "missing DIMENSION");
  if (h.num_sets < 0) return Error(h.last_line, "missing GTSP_SETS");
  if (h.num_sets > h.dimension) {
    return Error(h.last_line, absl::StrCat("GTSP_SETS (", h.num_sets, ") exceeds DIMENSION (",
                                           h.dimension, ")"));
  }
  GtspLibFile file;
  file.name = h.name;
  GtspInstance& inst = file.instance;
  inst.num_vertices = static_cast<int>(h.dimension);
  const std::string& t = h.weight_type;
  absl::Status st;
  if (t == "EUC_2D" || t == "CEIL_2D" || t == "ATT" || t == "GEO") {
    st = FillFromCoordinates(h, inst);
  } else if (t == "EXPLICIT") {
    st = FillFromWeights(h, inst);
  } else if (t.empty()) {
    st = Error(h.last_line, "missing EDGE_WEIGHT_TYPE");
  } else {
    st = Error(h.last_line, absl::StrCat("unsupported EDGE_WEIGHT_TYPE '", t,
                                         "' (EUC_2D, CEIL_2D, ATT, GEO, EXPLICIT are supported)"));
  }
  if (!st.ok()) return st;
  if (st = FillSets(h, inst); !st.ok()) return st;
  if (st = inst.Validate(); !st.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("GTSPLIB: ", st.message()));
  }
  return file;
}

absl::StatusOr<GtspLibFile> LoadGtspLibFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat("cannot open GTSPLIB file '", path, "'"));
  std::stringstream buffer;
  buffer << in.rdbuf();
  absl::StatusOr<GtspLibFile> file = ParseGtspLib(buffer.str());
  if (!file.ok()) {
    return absl::Status(file.status().code(), absl::StrCat(path, ": ", file.status().message()));
  }
  if (file->name.empty()) {
    std::string base = path.substr(path.find_last_of('/') + 1);
    file->name = base.substr(0, base.rfind('.'));
  }
  return file;
}

}  // namespace covplan
