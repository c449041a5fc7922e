#include "server/process_metrics.h"

#include <unistd.h>

#include <fstream>
#include <sstream>
#include <string>

namespace covplan {
namespace {

prometheus::MetricFamily Family(const std::string& name, const std::string& help,
                                prometheus::MetricType type, double value) {
  prometheus::MetricFamily family;
  family.name = name;
  family.help = help;
  family.type = type;
  prometheus::ClientMetric metric;
  if (type == prometheus::MetricType::Counter) {
    metric.counter.value = value;
  } else {
    metric.gauge.value = value;
  }
  family.metric.push_back(metric);
  return family;
}

}  // namespace

std::vector<prometheus::MetricFamily> ProcessMetrics::Collect() const {
  std::vector<prometheus::MetricFamily> families;
  const double page = static_cast<double>(sysconf(_SC_PAGESIZE));
  // statm: size resident shared text lib data dt (pages).
  std::ifstream statm("/proc/self/statm");
  double size_pages = 0, resident_pages = 0;
  if (statm >> size_pages >> resident_pages) {
    families.push_back(Family("covplan_process_resident_memory_bytes",
                              "Resident set size of the server process",
                              prometheus::MetricType::Gauge, resident_pages * page));
    families.push_back(Family("covplan_process_virtual_memory_bytes",
                              "Virtual memory size of the server process",
                              prometheus::MetricType::Gauge, size_pages * page));
  }
  // stat: fields 14 and 15 are utime and stime in clock ticks; field 2 (the
  // command name) is in parentheses and may hold spaces, so skip past ')'.
  std::ifstream stat("/proc/self/stat");
  std::string line;
  if (std::getline(stat, line)) {
    const size_t close = line.rfind(')');
    if (close != std::string::npos) {
      std::istringstream rest(line.substr(close + 1));
      std::string field;
      double utime = 0, stime = 0;
      // After ')': field 3 (state) is the first; utime is field 14.
      for (int i = 3; i < 14 && rest >> field; ++i) {
      }
      if (rest >> utime >> stime) {
        const double ticks = static_cast<double>(sysconf(_SC_CLK_TCK));
        families.push_back(Family("covplan_process_cpu_seconds_total",
                                  "User and system CPU time of the server process",
                                  prometheus::MetricType::Counter, (utime + stime) / ticks));
      }
    }
  }
  return families;
}

}  // namespace covplan
