// ProcessMetrics reads this process's /proc at collect time: the resident
// size follows memory the process really touches.
#include "server/process_metrics.h"

#include <cstring>
#include <map>
#include <memory>
#include <string>

#include "gtest/gtest.h"

namespace covplan {
namespace {

std::map<std::string, double> Values() {
  std::map<std::string, double> out;
  for (const prometheus::MetricFamily& f : ProcessMetrics().Collect()) {
    EXPECT_EQ(f.metric.size(), 1u) << f.name;
    out[f.name] = f.type == prometheus::MetricType::Counter ? f.metric[0].counter.value
                                                            : f.metric[0].gauge.value;
  }
  return out;
}

TEST(ProcessMetricsTest, ResidentMemoryFollowsTouchedMemory) {
  const std::map<std::string, double> before = Values();
  ASSERT_EQ(before.count("covplan_process_resident_memory_bytes"), 1u);
  ASSERT_EQ(before.count("covplan_process_virtual_memory_bytes"), 1u);
  ASSERT_EQ(before.count("covplan_process_cpu_seconds_total"), 1u);
  EXPECT_GT(before.at("covplan_process_resident_memory_bytes"), 0);
  EXPECT_GE(before.at("covplan_process_virtual_memory_bytes"),
            before.at("covplan_process_resident_memory_bytes"));
  EXPECT_GE(before.at("covplan_process_cpu_seconds_total"), 0);

  constexpr size_t kBytes = 64 << 20;
  std::unique_ptr<char[]> block(new char[kBytes]);
  std::memset(block.get(), 1, kBytes);  // touch every page
  const std::map<std::string, double> after = Values();
  EXPECT_GE(after.at("covplan_process_resident_memory_bytes") -
                before.at("covplan_process_resident_memory_bytes"),
            0.75 * kBytes);
  EXPECT_EQ(block[kBytes - 1], 1);
}

}  // namespace
}  // namespace covplan
