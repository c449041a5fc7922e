// The LRU + single-flight cache: byte budget, eviction order, one build for
// concurrent callers, failed builds not cached, waiters bounded by their own
// deadline.
#include "server/artifact_lru.h"

#include <atomic>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/synchronization/notification.h"
#include "gtest/gtest.h"

namespace covplan {
namespace {

struct Blob {
  size_t bytes = 0;
  int id = 0;
};

using BlobCache = SharedLruCache<Blob>;

BlobCache::Builder Make(size_t bytes, int id, std::atomic<int>* builds = nullptr) {
  return [=](const StopToken&) -> absl::StatusOr<std::shared_ptr<const Blob>> {
    if (builds != nullptr) builds->fetch_add(1);
    return std::make_shared<const Blob>(Blob{bytes, id});
  };
}

TEST(SharedLruCacheTest, HitsMissesAndLruEvictionWithinBudget) {
  BlobCache cache(100, [](const Blob& b) { return b.bytes; });
  bool hit = false;
  ASSERT_TRUE(cache.GetOrBuild("a", StopToken(), Make(40, 1), &hit).ok());
  EXPECT_FALSE(hit);
  ASSERT_TRUE(cache.GetOrBuild("b", StopToken(), Make(40, 2), &hit).ok());
  ASSERT_TRUE(cache.GetOrBuild("a", StopToken(), Make(40, 99), &hit).ok());  // a is now newest
  EXPECT_TRUE(hit);
  ASSERT_TRUE(cache.GetOrBuild("c", StopToken(), Make(40, 3), &hit).ok());  // evicts b
  BlobCache::Stats stats = cache.stats();
  EXPECT_EQ(stats.entries, 2u);
  EXPECT_EQ(stats.bytes, 80u);
  EXPECT_EQ(stats.evictions, 1);
  EXPECT_EQ(stats.hits, 1);
  EXPECT_EQ(stats.misses, 3);
  absl::StatusOr<std::shared_ptr<const Blob>> a =
      cache.GetOrBuild("a", StopToken(), Make(40, 99), &hit);
  EXPECT_TRUE(hit);
  EXPECT_EQ((*a)->id, 1);
  cache.GetOrBuild("b", StopToken(), Make(40, 4), &hit).IgnoreError();
  EXPECT_FALSE(hit);  // b had been evicted
  // Larger than the whole budget: returned, not kept.
  absl::StatusOr<std::shared_ptr<const Blob>> big =
      cache.GetOrBuild("big", StopToken(), Make(500, 5), &hit);
  ASSERT_TRUE(big.ok());
  EXPECT_EQ((*big)->id, 5);
  EXPECT_LE(cache.stats().bytes, 100u);
  cache.GetOrBuild("big", StopToken(), Make(500, 6), &hit).IgnoreError();
  EXPECT_FALSE(hit);
}

TEST(SharedLruCacheTest, ConcurrentCallersBuildOnce) {
  BlobCache cache(1000, [](const Blob& b) { return b.bytes; });
  std::atomic<int> builds{0};
  absl::Notification release;
  auto slow = [&](const StopToken&) -> absl::StatusOr<std::shared_ptr<const Blob>> {
    builds.fetch_add(1);
    release.WaitForNotificationWithTimeout(absl::Seconds(5));
    return std::make_shared<const Blob>(Blob{10, 7});
  };
  std::atomic<int> hits{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < 8; ++i) {
    threads.emplace_back([&] {
      bool hit = false;
      absl::StatusOr<std::shared_ptr<const Blob>> v =
          cache.GetOrBuild("k", StopToken(), slow, &hit);
      EXPECT_TRUE(v.ok());
      EXPECT_EQ((*v)->id, 7);
      hits += hit;
    });
  }
  absl::SleepFor(absl::Milliseconds(50));
  release.Notify();
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(builds.load(), 1);
  EXPECT_EQ(hits.load(), 7);
}

TEST(SharedLruCacheTest, FailuresAreNotCachedAndWaitersRespectTheirDeadline) {
  BlobCache cache(1000, [](const Blob& b) { return b.bytes; });
  bool hit = false;
  auto failing = [](const StopToken&) -> absl::StatusOr<std::shared_ptr<const Blob>> {
    return absl::InvalidArgumentError("bad map");
  };
  EXPECT_EQ(cache.GetOrBuild("k", StopToken(), failing, &hit).status().code(),
            absl::StatusCode::kInvalidArgument);
  std::atomic<int> builds{0};
  ASSERT_TRUE(cache.GetOrBuild("k", StopToken(), Make(10, 1, &builds), &hit).ok());
  EXPECT_EQ(builds.load(), 1);

  absl::Notification release;
  std::thread leader([&] {
    bool h = false;
    cache
        .GetOrBuild(
            "slow", StopToken(),
            [&](const StopToken&) -> absl::StatusOr<std::shared_ptr<const Blob>> {
              release.WaitForNotificationWithTimeout(absl::Seconds(5));
              return std::make_shared<const Blob>(Blob{10, 2});
            },
            &h)
        .IgnoreError();
  });
  absl::SleepFor(absl::Milliseconds(20));
  const absl::Time start = absl::Now();
  absl::StatusOr<std::shared_ptr<const Blob>> waited =
      cache.GetOrBuild("slow", StopToken::WithTimeout(absl::Milliseconds(50)), Make(10, 3), &hit);
  EXPECT_EQ(waited.status().code(), absl::StatusCode::kDeadlineExceeded);
  EXPECT_LT(absl::Now() - start, absl::Milliseconds(500));
  release.Notify();
  leader.join();
}

// DeleteMap's erase fences builds that were already running: their value
// reaches their own caller but is not stored, so a deleted map's artifacts
// cannot come back from a build that raced the delete.
TEST(SharedLruCacheTest, EraseFencesABuildAlreadyRunning) {
  BlobCache cache(1000, [](const Blob& b) { return b.bytes; });
  absl::Notification started, release;
  std::thread builder([&] {
    bool hit = false;
    absl::StatusOr<std::shared_ptr<const Blob>> v = cache.GetOrBuild(
        "map1/grid", StopToken(),
        [&](const StopToken&) -> absl::StatusOr<std::shared_ptr<const Blob>> {
          started.Notify();
          release.WaitForNotification();
          return std::make_shared<const Blob>(Blob{10, 1});
        },
        &hit);
    EXPECT_TRUE(v.ok());
  });
  started.WaitForNotification();
  cache.EraseWithPrefix("map1/");
  release.Notify();
  builder.join();
  bool hit = true;
  ASSERT_TRUE(cache.GetOrBuild("map1/grid", StopToken(), Make(10, 2), &hit).ok());
  EXPECT_FALSE(hit);  // the raced build was not kept
  // Other maps are not fenced, and builds after the erase are kept again.
  ASSERT_TRUE(cache.GetOrBuild("map2/grid", StopToken(), Make(10, 3), &hit).ok());
  ASSERT_TRUE(cache.GetOrBuild("map2/grid", StopToken(), Make(10, 4), &hit).ok());
  EXPECT_TRUE(hit);
  ASSERT_TRUE(cache.GetOrBuild("map1/grid", StopToken(), Make(10, 5), &hit).ok());
  EXPECT_TRUE(hit);
}

// A build that started before more erases than the fence window remembers
// is refused (conservatively), not kept.
TEST(SharedLruCacheTest, FenceWindowOverflowRefusesOldBuilds) {
  BlobCache cache(1000, [](const Blob& b) { return b.bytes; });
  absl::Notification started, release;
  std::thread builder([&] {
    bool hit = false;
    cache
        .GetOrBuild(
            "keep/grid", StopToken(),
            [&](const StopToken&) -> absl::StatusOr<std::shared_ptr<const Blob>> {
              started.Notify();
              release.WaitForNotification();
              return std::make_shared<const Blob>(Blob{10, 1});
            },
            &hit)
        .IgnoreError();
  });
  started.WaitForNotification();
  for (int i = 0; i < 300; ++i) cache.EraseWithPrefix(absl::StrCat("other", i, "/"));
  release.Notify();
  builder.join();
  bool hit = true;
  ASSERT_TRUE(cache.GetOrBuild("keep/grid", StopToken(), Make(10, 2), &hit).ok());
  EXPECT_FALSE(hit);
}

}  // namespace
}  // namespace covplan
