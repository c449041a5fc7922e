// The bounded worker pool: runs tasks, refuses beyond threads + queue,
// recovers, drains on shutdown; groups take turns and a group's bound on
// running tasks holds while other groups' tasks still run.
#include "server/worker_pool.h"

#include <atomic>
#include <string>
#include <vector>

#include "absl/synchronization/mutex.h"
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

TEST(WorkerPoolTest, GroupsTakeTurnsForAFreeWorker) {
  WorkerPool pool(/*threads=*/1, /*max_queue=*/16);
  absl::Notification release;
  absl::Mutex mu;
  std::vector<std::string> order;
  const auto task = [&](std::string name) {
    return [&, name] {
      absl::MutexLock lock(&mu);
      order.push_back(name);
    };
  };
  // The worker is held, then group a queues four tasks before b and c queue one each.
  absl::Notification started;
  ASSERT_TRUE(pool.TrySubmit(
      [&] {
        started.Notify();
        release.WaitForNotificationWithTimeout(absl::Seconds(5));
      },
      "a", 0));
  ASSERT_TRUE(started.WaitForNotificationWithTimeout(absl::Seconds(5)));
  for (int i = 1; i <= 4; ++i) ASSERT_TRUE(pool.TrySubmit(task("a" + std::to_string(i)), "a", 0));
  ASSERT_TRUE(pool.TrySubmit(task("b1"), "b", 0));
  ASSERT_TRUE(pool.TrySubmit(task("c1"), "c", 0));
  release.Notify();
  pool.Shutdown();
  // FIFO would run a1..a4 first; in turns b and c wait for one task of a.
  EXPECT_EQ(order, (std::vector<std::string>{"a1", "b1", "c1", "a2", "a3", "a4"}));
}

TEST(WorkerPoolTest, AGroupRunsNoMoreThanItsBoundWhileOthersRun) {
  WorkerPool pool(/*threads=*/3, /*max_queue=*/16);
  absl::Notification release;
  std::atomic<int> a_running{0};
  std::atomic<int> a_most{0};
  std::atomic<int> b_done{0};
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(pool.TrySubmit(
        [&] {
          const int now = a_running.fetch_add(1) + 1;
          int most = a_most.load();
          while (now > most && !a_most.compare_exchange_weak(most, now)) {
          }
          release.WaitForNotificationWithTimeout(absl::Seconds(5));
          a_running.fetch_sub(1);
        },
        "a", /*max_running=*/1));
  }
  // Two workers are free; a's bound keeps them for b.
  for (int i = 0; i < 2; ++i) ASSERT_TRUE(pool.TrySubmit([&] { b_done.fetch_add(1); }, "b", 0));
  for (int i = 0; i < 500 && b_done.load() < 2; ++i) absl::SleepFor(absl::Milliseconds(10));
  EXPECT_EQ(b_done.load(), 2);
  EXPECT_EQ(pool.active(), 1);
  EXPECT_EQ(pool.queued(), 3);
  release.Notify();
  pool.Shutdown();
  EXPECT_EQ(a_most.load(), 1);
  EXPECT_EQ(a_running.load(), 0);
}

}  // namespace
}  // namespace covplan
