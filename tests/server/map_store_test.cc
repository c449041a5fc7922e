// The on-disk map registry: persistence across reopen, idempotent puts,
// checksum verification of damaged files, deletion.
#include "server/map_store.h"

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "absl/strings/str_cat.h"
#include "api/convert.h"
#include "gtest/gtest.h"
#include "tests/testing/test_maps.h"

namespace covplan {
namespace {

using ::covplan::testing::AsciiToPgm;
using ::covplan::testing::RasterMap;
using ::covplan::testing::TwoRooms;

class MapStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "covplan_store_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    map_ = RasterMap(AsciiToPgm(TwoRooms(), 4), 0.1);
    info_.set_map_id(ComputeMapId(map_));
    info_.set_name("rooms");
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  std::string dir_;
  v1::Map map_;
  v1::MapInfo info_;
};

TEST_F(MapStoreTest, PutIsIdempotentAndSurvivesReopen) {
  {
    absl::StatusOr<std::unique_ptr<MapStore>> store = MapStore::Open(dir_);
    ASSERT_TRUE(store.ok()) << store.status();
    absl::StatusOr<bool> created = (*store)->Put(info_, map_);
    ASSERT_TRUE(created.ok()) << created.status();
    EXPECT_TRUE(*created);
    created = (*store)->Put(info_, map_);
    ASSERT_TRUE(created.ok());
    EXPECT_FALSE(*created);
  }
  // No temporary files left behind (only the map and the lock file).
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir_)) {
    if (entry.path().filename() == ".lock") continue;
    EXPECT_EQ(entry.path().extension(), ".map");
    ++files;
  }
  EXPECT_EQ(files, 1);

  absl::StatusOr<std::unique_ptr<MapStore>> reopened = MapStore::Open(dir_);
  ASSERT_TRUE(reopened.ok());
  EXPECT_EQ((*reopened)->size(), 1);
  absl::StatusOr<v1::GetMapResponse> got = (*reopened)->Get(info_.map_id());
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->map().raster().image(), map_.raster().image());
  EXPECT_EQ(got->info().name(), "rooms");
  EXPECT_GT(got->info().created_unix_ms(), 0);
}

TEST_F(MapStoreTest, DamagedFileIsDetectedAndNotServed) {
  absl::StatusOr<std::unique_ptr<MapStore>> store = MapStore::Open(dir_);
  ASSERT_TRUE(store.ok());
  ASSERT_TRUE((*store)->Put(info_, map_).ok());
  const std::string path = dir_ + "/" + info_.map_id() + ".map";
  {  // Flip one byte in the payload.
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(-10, std::ios::end);
    f.put('\x55');
  }
  absl::StatusOr<v1::GetMapResponse> got = (*store)->Get(info_.map_id());
  EXPECT_EQ(got.status().code(), absl::StatusCode::kDataLoss);
  EXPECT_NE(got.status().message().find("corrupted"), std::string::npos);
  EXPECT_EQ(got.status().message().find(dir_), std::string::npos);  // no server paths

  store->reset();  // a restart: the lock is released
  absl::StatusOr<std::unique_ptr<MapStore>> reopened = MapStore::Open(dir_);
  ASSERT_TRUE(reopened.ok());
  std::vector<std::string> corrupted;
  EXPECT_TRUE((*reopened)->List(&corrupted).empty());
  EXPECT_EQ(corrupted, std::vector<std::string>{info_.map_id()});
  EXPECT_EQ((*reopened)->Get(info_.map_id()).status().code(), absl::StatusCode::kDataLoss);

  // Putting it again repairs it.
  absl::StatusOr<bool> created = (*reopened)->Put(info_, map_);
  ASSERT_TRUE(created.ok());
  EXPECT_TRUE(*created);
  EXPECT_TRUE((*reopened)->Get(info_.map_id()).ok());
}

// Plans: TrimPlans keeps the newest, TouchPlan makes a plan the newest.
TEST_F(MapStoreTest, PlansRoundTripAndTrimKeepsTheNewest) {
  absl::StatusOr<std::unique_ptr<MapStore>> store = MapStore::Open(dir_);
  ASSERT_TRUE(store.ok());
  const std::string binary("\0\x01\xffplan", 7);
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE((*store)->PutPlan(absl::StrCat("p-", i), binary).ok());
    std::this_thread::sleep_for(std::chrono::milliseconds(5));  // distinct times
  }
  EXPECT_EQ(*(*store)->GetPlan("p-3"), binary);
  ASSERT_TRUE((*store)->TouchPlan("p-1").ok());  // the newest now
  EXPECT_EQ((*store)->TouchPlan("p-9").code(), absl::StatusCode::kNotFound);
  EXPECT_EQ((*store)->TouchPlan("../x").code(), absl::StatusCode::kNotFound);
  EXPECT_EQ((*store)->TrimPlans(2), 3);
  EXPECT_EQ((*store)->GetPlan("p-0").status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ((*store)->GetPlan("p-3").status().code(), absl::StatusCode::kNotFound);
  EXPECT_TRUE((*store)->GetPlan("p-4").ok());
  EXPECT_TRUE((*store)->GetPlan("p-1").ok());
}

TEST_F(MapStoreTest, TruncatedFileIsDetected) {
  absl::StatusOr<std::unique_ptr<MapStore>> store = MapStore::Open(dir_);
  ASSERT_TRUE(store.ok());
  ASSERT_TRUE((*store)->Put(info_, map_).ok());
  const std::string path = dir_ + "/" + info_.map_id() + ".map";
  std::filesystem::resize_file(path, std::filesystem::file_size(path) / 2);
  store->reset();
  absl::StatusOr<std::unique_ptr<MapStore>> reopened = MapStore::Open(dir_);
  ASSERT_TRUE(reopened.ok());
  EXPECT_EQ((*reopened)->Get(info_.map_id()).status().code(), absl::StatusCode::kDataLoss);
}

TEST_F(MapStoreTest, ASecondOpenOfALockedStoreFails) {
  absl::StatusOr<std::unique_ptr<MapStore>> store = MapStore::Open(dir_);
  ASSERT_TRUE(store.ok());
  absl::StatusOr<std::unique_ptr<MapStore>> second = MapStore::Open(dir_);
  EXPECT_EQ(second.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(second.status().message().find("in use by another covplan-server"), std::string::npos);
  store->reset();
  EXPECT_TRUE(MapStore::Open(dir_).ok());
}

TEST_F(MapStoreTest, MapCallsAreUnavailableUntilTheIndexIsLoaded) {
  {
    absl::StatusOr<std::unique_ptr<MapStore>> store = MapStore::Open(dir_);
    ASSERT_TRUE(store.ok());
    ASSERT_TRUE((*store)->Put(info_, map_).ok());
  }
  absl::StatusOr<std::unique_ptr<MapStore>> store = MapStore::OpenLocked(dir_, /*index=*/false);
  ASSERT_TRUE(store.ok());
  EXPECT_TRUE((*store)->loading());
  EXPECT_EQ((*store)->Get(info_.map_id()).status().code(), absl::StatusCode::kUnavailable);
  EXPECT_EQ((*store)->Put(info_, map_).status().code(), absl::StatusCode::kUnavailable);
  EXPECT_EQ((*store)->Delete(info_.map_id()).status().code(), absl::StatusCode::kUnavailable);
  ASSERT_TRUE((*store)->LoadIndex(nullptr).ok());
  EXPECT_FALSE((*store)->loading());
  EXPECT_TRUE((*store)->Get(info_.map_id()).ok());
}

TEST_F(MapStoreTest, ListPageContinuesAfterTheGivenId) {
  absl::StatusOr<std::unique_ptr<MapStore>> store = MapStore::Open(dir_);
  ASSERT_TRUE(store.ok());
  std::vector<std::string> ids;
  for (char c : {'1', '2', '3'}) {
    v1::MapInfo info = info_;
    info.set_map_id(std::string(64, c));
    ASSERT_TRUE((*store)->Put(info, map_).ok());
    ids.push_back(info.map_id());
  }
  bool more = false;
  std::vector<v1::MapInfo> page = *(*store)->ListPage("", 2, &more, nullptr);
  ASSERT_EQ(page.size(), 2u);
  EXPECT_EQ(page[1].map_id(), ids[1]);
  EXPECT_TRUE(more);
  page = *(*store)->ListPage(ids[1], 2, &more, nullptr);
  ASSERT_EQ(page.size(), 1u);
  EXPECT_EQ(page[0].map_id(), ids[2]);
  EXPECT_FALSE(more);
}

TEST_F(MapStoreTest, DeleteAndUnknownIds) {
  absl::StatusOr<std::unique_ptr<MapStore>> store = MapStore::Open(dir_);
  ASSERT_TRUE(store.ok());
  ASSERT_TRUE((*store)->Put(info_, map_).ok());
  EXPECT_EQ((*store)->Get(std::string(64, 'b')).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ((*store)->Get("../x").status().code(), absl::StatusCode::kInvalidArgument);
  absl::StatusOr<bool> deleted = (*store)->Delete(info_.map_id());
  ASSERT_TRUE(deleted.ok());
  EXPECT_TRUE(*deleted);
  deleted = (*store)->Delete(info_.map_id());
  ASSERT_TRUE(deleted.ok());
  EXPECT_FALSE(*deleted);
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/" + info_.map_id() + ".map"));
}

}  // namespace
}  // namespace covplan
