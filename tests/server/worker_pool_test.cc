// The bounded worker pool: runs tasks, refuses beyond threads + queue,
// recovers, drains on shutdown.
#include "server/worker_pool.h"

#include <atomic>

#include "absl/synchronization/notification.h"
#include "gtest/gtest.h"

namespace covplan {
namespace {

TEST(WorkerPoolTest, RefusesBeyondCapacityAndRecovers) {
  WorkerPool pool(/*threads=*/2, /*max_queue=*/3);
  absl::Notification release;
  std::atomic<int> done{0};
  int accepted = 0;
  for (int i = 0; i < 10; ++i) {
    accepted += pool.TrySubmit([&] {
      release.WaitForNotificationWithTimeout(absl::Seconds(5));
      done.fetch_add(1);
    });
  }
  EXPECT_EQ(accepted, 5);  // 2 running + 3 waiting
  release.Notify();
  for (int i = 0; i < 500 && done.load() < 5; ++i) absl::SleepFor(absl::Milliseconds(10));
  EXPECT_EQ(done.load(), 5);
  EXPECT_TRUE(pool.TrySubmit([&] { done.fetch_add(1); }));
  pool.Shutdown();
  EXPECT_EQ(done.load(), 6);
  EXPECT_FALSE(pool.TrySubmit([] {}));
}

TEST(WorkerPoolTest, ShutdownRunsQueuedTasks) {
  std::atomic<int> done{0};
  {
    WorkerPool pool(1, 10);
    for (int i = 0; i < 10; ++i) {
      ASSERT_TRUE(pool.TrySubmit([&] {
        absl::SleepFor(absl::Milliseconds(1));
        done.fetch_add(1);
      }));
    }
  }
  EXPECT_EQ(done.load(), 10);
}

}  // namespace
}  // namespace covplan
