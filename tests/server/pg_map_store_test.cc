// The PostgreSQL map store against a throwaway local cluster (initdb in a
// temp dir, unix socket only). Skipped, with the reason, when no PostgreSQL
// server binaries are installed.
#include "server/pg_map_store.h"

#include <grpcpp/grpcpp.h>
#include <libpq-fe.h>

#include <filesystem>
#include <memory>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "api/convert.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/covplan_server.h"
#include "tests/server/pg_test_cluster.h"
#include "tests/testing/test_maps.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

class PgMapStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    pg_ = testing::PgTestCluster::Start(&why);
    if (pg_ == nullptr) GTEST_SKIP() << why;
    map_ = testing::RasterMap(testing::AsciiToPgm(testing::TwoRooms(), 4), 0.1);
    info_.set_map_id(ComputeMapId(map_));
    info_.set_name("two rooms");
  }

  std::unique_ptr<PgMapStore> Open() {
    absl::StatusOr<std::unique_ptr<PgMapStore>> store = PgMapStore::Open(pg_->Conninfo("covplan"));
    EXPECT_TRUE(store.ok()) << store.status();
    return store.ok() ? std::move(*store) : nullptr;
  }

  // Runs SQL on a connection of the test's own.
  void Sql(const std::string& sql) {
    PGconn* conn = PQconnectdb(pg_->Conninfo("covplan").c_str());
    ASSERT_EQ(PQstatus(conn), CONNECTION_OK) << PQerrorMessage(conn);
    PGresult* r = PQexec(conn, sql.c_str());
    EXPECT_EQ(PQresultStatus(r), PGRES_COMMAND_OK) << PQresultErrorMessage(r);
    PQclear(r);
    PQfinish(conn);
  }

  std::unique_ptr<testing::PgTestCluster> pg_;
  v1::Map map_;
  v1::MapInfo info_;
};

TEST_F(PgMapStoreTest, PutGetListDeleteAcrossInstances) {
  std::unique_ptr<PgMapStore> a = Open(), b = Open();
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->size(), 0);
  EXPECT_EQ(*a->Put(info_, map_), true);
  EXPECT_EQ(*b->Put(info_, map_), false);  // idempotent, seen by another instance
  absl::StatusOr<v1::GetMapResponse> got = b->Get(info_.map_id());
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->info().name(), "two rooms");
  EXPECT_EQ(got->map().SerializeAsString(), map_.SerializeAsString());
  // A store opened later serves every registered map.
  std::unique_ptr<PgMapStore> late = Open();
  std::vector<std::string> corrupted;
  std::vector<v1::MapInfo> listed = late->List(&corrupted);
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_EQ(listed[0].map_id(), info_.map_id());
  EXPECT_TRUE(corrupted.empty());
  EXPECT_EQ(late->size(), 1);
  EXPECT_EQ(*late->Delete(info_.map_id()), true);
  EXPECT_EQ(*a->Delete(info_.map_id()), false);
  EXPECT_EQ(a->Get(info_.map_id()).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(a->size(), 0);
}

TEST_F(PgMapStoreTest, DamagedRowIsDataLossAndPutRepairsIt) {
  std::unique_ptr<PgMapStore> store = Open();
  ASSERT_TRUE(store->Put(info_, map_).ok());
  Sql("UPDATE covplan_maps SET payload = overlay(payload placing '\\xff'::bytea from 20 for 1)");
  EXPECT_EQ(store->Get(info_.map_id()).status().code(), absl::StatusCode::kDataLoss);
  std::vector<std::string> corrupted;
  EXPECT_TRUE(store->List(&corrupted).empty());
  EXPECT_EQ(corrupted, std::vector<std::string>{info_.map_id()});
  EXPECT_EQ(*store->Put(info_, map_), true);  // replaced
  EXPECT_TRUE(store->Get(info_.map_id()).ok());
}

TEST_F(PgMapStoreTest, StateAndPlansRoundTripAndTrimKeepsTheNewest) {
  std::unique_ptr<PgMapStore> store = Open();
  EXPECT_EQ(store->GetState("estimator.txt").status().code(), absl::StatusCode::kNotFound);
  ASSERT_TRUE(store->PutState("estimator.txt", "a 1\n").ok());
  ASSERT_TRUE(store->PutState("estimator.txt", "a 2\n").ok());
  EXPECT_EQ(*store->GetState("estimator.txt"), "a 2\n");
  EXPECT_EQ(store->PutState("../x", "").code(), absl::StatusCode::kInvalidArgument);
  const std::string binary("\0\x01\xffplan", 7);
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(store->PutPlan(absl::StrCat("p-", i), binary).ok());
  EXPECT_EQ(*store->GetPlan("p-3"), binary);
  ASSERT_TRUE(store->TouchPlan("p-1").ok());  // the newest now
  EXPECT_EQ(store->TouchPlan("p-9").code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store->TrimPlans(2), 3);
  EXPECT_EQ(store->GetPlan("p-0").status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store->GetPlan("p-3").status().code(), absl::StatusCode::kNotFound);
  EXPECT_TRUE(store->GetPlan("p-4").ok());
  EXPECT_TRUE(store->GetPlan("p-1").ok());
  EXPECT_EQ(store->GetPlan("P/../1").status().code(), absl::StatusCode::kNotFound);
}

TEST_F(PgMapStoreTest, DatabaseDownIsUnavailableWithAReasonAndRecovers) {
  std::unique_ptr<PgMapStore> store = Open();
  ASSERT_TRUE(store->Put(info_, map_).ok());
  ASSERT_TRUE(pg_->Stop());
  const absl::Status get = store->Get(info_.map_id()).status();
  EXPECT_EQ(get.code(), absl::StatusCode::kUnavailable) << get;
  EXPECT_THAT(get.message(), HasSubstr("map store (PostgreSQL) unavailable"));
  EXPECT_EQ(store->Put(info_, map_).status().code(), absl::StatusCode::kUnavailable);
  EXPECT_EQ(store->PutPlan("p-1", "x").code(), absl::StatusCode::kUnavailable);
  EXPECT_EQ(store->Available().code(), absl::StatusCode::kUnavailable);
  EXPECT_TRUE(store->List(nullptr).empty());
  EXPECT_EQ(store->size(), 1);  // the last known count
  // A store opened while the database is down starts and reports it.
  absl::StatusOr<std::unique_ptr<PgMapStore>> later = PgMapStore::Open(pg_->Conninfo("covplan"));
  ASSERT_TRUE(later.ok()) << later.status();
  EXPECT_EQ((*later)->Available().code(), absl::StatusCode::kUnavailable);
  ASSERT_TRUE(pg_->Restart());
  EXPECT_TRUE(store->Get(info_.map_id()).ok());  // reconnected by itself
  EXPECT_TRUE((*later)->Get(info_.map_id()).ok());
  EXPECT_TRUE(store->Available().ok());
}

TEST_F(PgMapStoreTest, MalformedConninfoIsInvalidArgument) {
  EXPECT_EQ(PgMapStore::Open("host=/nonexistent port=1").status().code(), absl::StatusCode::kOk);
  EXPECT_EQ(PgMapStore::Open("nonsense").status().code(), absl::StatusCode::kInvalidArgument);
}

// Two servers on one database: a PutMap acknowledged by one is planned by
// the other; with the database down a cache miss is UNAVAILABLE, and the
// replica serves again once it returns.
// A replica on the test cluster's database (its own local directory).
std::unique_ptr<CovplanServer> StartReplica(const testing::PgTestCluster& pg,
                                            const std::string& name) {
  ServerConfig config;
  config.port = 0;
  config.metrics_port = -1;
  config.store_dir = std::filesystem::temp_directory_path().string() + "/covplan_pg_" + name + "_" +
                     std::to_string(getpid());
  config.map_store = "postgres";
  config.pg_conninfo = pg.Conninfo("covplan");
  absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
  EXPECT_TRUE(server.ok()) << server.status();
  return server.ok() ? std::move(*server) : nullptr;
}

std::unique_ptr<v1::CoveragePlanner::Stub> StubOf(const CovplanServer& s) {
  return v1::CoveragePlanner::NewStub(grpc::CreateChannel(absl::StrCat("127.0.0.1:", s.port()),
                                                          grpc::InsecureChannelCredentials()));
}

// Two replicas on the test cluster's database, a map put through the first.
struct TwoReplicas {
  std::unique_ptr<CovplanServer> one, two;
  std::unique_ptr<v1::CoveragePlanner::Stub> s1, s2;
  v1::PutMapResponse stored;
};

void StartTwoReplicas(const testing::PgTestCluster& pg, const v1::Map& map, const std::string& name,
                      TwoReplicas* r) {
  r->one = StartReplica(pg, name + "1");
  r->two = StartReplica(pg, name + "2");
  ASSERT_NE(r->one, nullptr);
  ASSERT_NE(r->two, nullptr);
  r->s1 = StubOf(*r->one);
  r->s2 = StubOf(*r->two);
  v1::PutMapRequest put;
  *put.mutable_map() = map;
  grpc::ClientContext context;
  ASSERT_TRUE(r->s1->PutMap(&context, put, &r->stored).ok());
}

TEST_F(PgMapStoreTest, ReplicasShareMapsAndSurviveTheDatabaseGoingAway) {
  TwoReplicas replicas;
  ASSERT_NO_FATAL_FAILURE(StartTwoReplicas(*pg_, map_, "r", &replicas));
  v1::CoveragePlanner::Stub* s1 = replicas.s1.get();
  v1::CoveragePlanner::Stub* s2 = replicas.s2.get();
  const v1::PutMapResponse& stored = replicas.stored;
  v1::PlanResponse plan;
  {
    grpc::ClientContext context;
    const grpc::Status status =
        s2->Plan(&context, testing::PlanRequestFor(stored.map_id(), 0.4), &plan);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_GT(plan.stats().num_ranks(), 0);
  }
  ASSERT_TRUE(pg_->Stop());
  {
    grpc::ClientContext context;
    v1::PutMapResponse again;
    v1::PutMapRequest put;
    *put.mutable_map() = map_;
    const grpc::Status status = s2->PutMap(&context, put, &again);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAVAILABLE);
    EXPECT_THAT(status.error_message(), HasSubstr("PostgreSQL"));
  }
  {
    // Replica two has the map's artifacts and keeps planning it (from
    // another start: a search, not a remembered answer).
    grpc::ClientContext context;
    v1::PlanRequest request = testing::PlanRequestFor(stored.map_id(), 0.4);
    request.mutable_robot()->mutable_start()->set_theta(1.0);
    const grpc::Status status = s2->Plan(&context, request, &plan);
    EXPECT_TRUE(status.ok()) << status.error_message();
  }
  {
    // Replica one never built this map's artifacts: it needs the store.
    grpc::ClientContext context;
    const grpc::Status status =
        s1->Plan(&context, testing::PlanRequestFor(stored.map_id(), 0.4), &plan);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAVAILABLE) << status.error_message();
  }
  ASSERT_TRUE(pg_->Restart());
  {
    grpc::ClientContext context;
    const grpc::Status status =
        s1->Plan(&context, testing::PlanRequestFor(stored.map_id(), 0.4), &plan);
    EXPECT_TRUE(status.ok()) << status.error_message();
  }
}

// Issue 30, item 1: a map deleted through one replica is refused by every
// replica within the store's check bound (PgMapStoreOptions::check_ttl, 1 s),
// also for a repeated request another replica answers from memory.
TEST_F(PgMapStoreTest, AMapDeletedThroughOneReplicaIsRefusedByEveryReplica) {
  TwoReplicas replicas;
  ASSERT_NO_FATAL_FAILURE(StartTwoReplicas(*pg_, map_, "d", &replicas));
  v1::CoveragePlanner::Stub* s1 = replicas.s1.get();
  v1::CoveragePlanner::Stub* s2 = replicas.s2.get();
  const v1::PutMapResponse& stored = replicas.stored;
  const v1::PlanRequest request = testing::PlanRequestFor(stored.map_id(), 0.4);
  // Both replicas plan it, twice: the second answer is remembered.
  for (auto* stub : {s1, s2, s1, s2}) {
    grpc::ClientContext context;
    v1::PlanResponse plan;
    ASSERT_TRUE(stub->Plan(&context, request, &plan).ok());
  }
  {
    grpc::ClientContext context;
    v1::DeleteMapRequest del;
    del.set_map_id(stored.map_id());
    v1::DeleteMapResponse deleted;
    ASSERT_TRUE(s1->DeleteMap(&context, del, &deleted).ok());
    ASSERT_TRUE(deleted.deleted());
  }
  const absl::Time deleted_at = absl::Now();
  for (auto* stub : {s1, s2}) {
    grpc::Status status;
    do {
      grpc::ClientContext context;
      v1::PlanResponse plan;
      status = stub->Plan(&context, request, &plan);
      if (status.ok()) absl::SleepFor(absl::Milliseconds(50));
    } while (status.ok() && absl::Now() - deleted_at < absl::Seconds(10));
    EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND) << status.error_message();
  }
  // The bound is 1 s; the slack is for a loaded machine.
  EXPECT_LT(absl::Now() - deleted_at, absl::Seconds(5));
}

}  // namespace
}  // namespace covplan
