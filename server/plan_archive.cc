#include "server/plan_archive.h"

#include <sys/random.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/synchronization/notification.h"
#include "api/convert.h"
#include "server/log.h"
#include "server/map_sources.h"
#include "server/tenant_tokens.h"

namespace covplan {
namespace {

// Where a server alone keeps its estimator; replicas sharing a store keep
// theirs under their own names and start from this one.
constexpr char kEstimatorFile[] = "replan_estimator.txt";

std::string EstimatorFile(const std::string& replica) {
  return replica.empty() ? kEstimatorFile : absl::StrCat("replan_estimator_", replica, ".txt");
}

}  // namespace

std::string NewPlanId(const std::string& tenant_tag) {
  // The kernel's CSPRNG, read 256 bytes at a time per thread (an id every
  // call, a system call every 16 ids).
  thread_local unsigned char pool[256];
  thread_local size_t used = sizeof(pool);
  if (used + 16 > sizeof(pool)) {
    size_t got = 0;
    while (got < sizeof(pool)) {
      const ssize_t n = ::getrandom(pool + got, sizeof(pool) - got, 0);
      if (n < 0) {
        if (errno == EINTR) continue;
        // getrandom cannot fail on Linux >= 3.17 once the pool is seeded; if
        // it ever does, refuse to hand out a guessable id.
        LogLine("error", "getrandom failed", {{"errno", absl::StrCat(errno)}});
        std::abort();
      }
      got += static_cast<size_t>(n);
    }
    used = 0;
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string id = "p-";
  id.reserve(2 + 32 + 16);
  for (size_t i = 0; i < 16; ++i) {
    const unsigned char b = pool[used + i];
    id.push_back(kHex[b >> 4]);
    id.push_back(kHex[b & 15]);
  }
  // Each byte is handed out once.
  std::memset(pool + used, 0, 16);
  used += 16;
  return id + PlanIdSuffix(tenant_tag);
}

PlanArchive::PlanArchive(const ServiceOptions& options, MapRepository* store,
                         ServerMetrics* metrics, const PlanningEngine* engine, WorkerPool* io_pool)
    : options_(options),
      store_(store),
      metrics_(metrics),
      engine_(engine),
      io_pool_(io_pool),
      plans_(options.plan_ttl, options.max_retained_plans) {
  store_->TrimPlans(options_.max_stored_plans);
  // The replan estimator learned by earlier runs of this server.
  // A replica's own, else (its first run) what a server alone learned.
  std::string file = EstimatorFile(options_.replica);
  absl::StatusOr<std::string> saved = store_->GetState(file);
  if (absl::IsNotFound(saved.status()) && !options_.replica.empty()) {
    saved = store_->GetState(file = kEstimatorFile);
  }
  if (saved.ok()) {
    const absl::Status parsed = estimator_.Parse(*saved);
    LogLine(parsed.ok() ? "info" : "warn", "replan estimator loaded",
            {{"from", file},
             {"samples", absl::StrCat(estimator_.num_samples())},
             {"detail", parsed.ok() ? "" : std::string(parsed.message())}});
  }
  PublishEstimator();
}

void PlanArchive::PublishRetainedCount() {
  metrics_->plans_retained().Set(static_cast<double>(plans_.size()));
}

std::shared_ptr<std::string> PlanArchive::Record(const v1::PlanRequest& origin,
                                                 const v1::PlanResponse& plan) {
  v1::InlinePlan record;
  *record.mutable_request() = origin;
  *record.mutable_plan() = plan;
  auto bytes = std::make_shared<std::string>();
  if (!record.SerializeToString(bytes.get())) return nullptr;
  RememberOrigin(plan.plan_id(), std::make_shared<const v1::PlanRequest>(origin));
  return bytes;
}

void PlanArchive::Write(const std::string& plan_id, const std::string& bytes) {
  if (absl::Status s = store_->PutPlan(plan_id, bytes); !s.ok()) {
    LogLine("warn", "plan not persisted",
            {{"plan", plan_id}, {"detail", std::string(s.message())}});
    return;
  }
  if (persisted_.fetch_add(1) % 256 == 255) {
    io_pool_->TrySubmit([this] { store_->TrimPlans(options_.max_stored_plans); });
  }
}

void PlanArchive::Persist(const v1::PlanRequest& origin, const v1::PlanResponse& plan) {
  std::shared_ptr<std::string> bytes = Record(origin, plan);
  if (bytes == nullptr) return;
  const std::string plan_id = plan.plan_id();
  // Off the reply's path: the disk write (with its fsyncs) runs on the I/O
  // pool after the answer is on its way.
  const bool queued = io_pool_->TrySubmit([this, bytes, plan_id] { Write(plan_id, *bytes); });
  if (!queued) LogLine("warn", "plan not persisted: I/O queue full", {{"plan", plan_id}});
}

void PlanArchive::PersistNow(const v1::PlanRequest& origin, const v1::PlanResponse& plan) {
  std::shared_ptr<std::string> bytes = Record(origin, plan);
  if (bytes == nullptr) return;
  const std::string plan_id = plan.plan_id();
  auto written = std::make_shared<absl::Notification>();
  const bool queued = io_pool_->TrySubmit([this, bytes, plan_id, written] {
    Write(plan_id, *bytes);
    written->Notify();
  });
  if (!queued) {
    LogLine("warn", "plan not persisted: I/O queue full", {{"plan", plan_id}});
    return;
  }
  // A store that hangs (a database gone) delays the answer by this much at
  // most; the write goes on behind it.
  if (!written->WaitForNotificationWithTimeout(kPersistNowWait)) {
    LogLine("warn", "plan write still pending when its answer left",
            {{"plan", plan_id},
             {"waited_ms", absl::StrCat(absl::ToInt64Milliseconds(kPersistNowWait))}});
  }
}

void PlanArchive::RememberOrigin(const std::string& plan_id,
                                 std::shared_ptr<const v1::PlanRequest> origin) {
  const size_t bound = (4 + 16) * options_.max_retained_plans + 16;
  absl::MutexLock lock(&origins_mu_);
  if (auto [it, added] = origins_.try_emplace(plan_id, origin); !added) {
    it->second = std::move(origin);  // the newest origin of an id wins; its age stays
    return;
  }
  origin_order_.push_back(plan_id);
  while (origin_order_.size() > bound) {
    origins_.erase(origin_order_.front());
    origin_order_.pop_front();
  }
}

std::shared_ptr<const RetainedPlan> PlanArchive::Get(const std::string& plan_id) {
  std::string made_from;
  std::shared_ptr<const RetainedPlan> plan = plans_.Get(plan_id, absl::Now(), &made_from);
  if (!made_from.empty()) AliasUsed(plan_id, made_from);
  return plan;
}

void PlanArchive::PutAlias(const std::string& alias_id, const std::string& original_id) {
  plans_.PutAlias(alias_id, original_id);
}

bool PlanArchive::OriginOf(const std::string& plan_id, v1::PlanRequest* origin) {
  const std::optional<std::string> original = plans_.OriginalOf(plan_id);
  absl::MutexLock lock(&origins_mu_);
  auto it = origins_.find(plan_id);
  if (it == origins_.end() && original.has_value()) it = origins_.find(*original);
  if (it == origins_.end()) return false;
  *origin = *it->second;
  return true;
}

namespace {
// "The plan of <original>": the record of an alias.
std::string AliasRecord(const std::string& original_id) {
  v1::InlinePlan record;
  record.mutable_plan()->set_plan_id(original_id);
  return record.SerializeAsString();
}
}  // namespace

void PlanArchive::AliasUsed(const std::string& alias_id, const std::string& original_id) {
  {
    absl::MutexLock lock(&origins_mu_);
    if (origins_.count(original_id) == 0) return;  // not stored (an inline map's plan)
  }
  PendingAlias pending{alias_id, original_id, AliasRecord(original_id)};
  bool queued = false, schedule = false;
  {
    absl::MutexLock lock(&aliases_mu_);
    if (pending_aliases_.size() < kMaxPendingAliases) {
      pending_aliases_.push_back(std::move(pending));
      queued = true;
      schedule = !alias_flush_queued_;
      alias_flush_queued_ = true;
    }
  }
  if (!queued) {
    // Dropped: logged at the 1st, 2nd, 4th, 8th... drop.
    const uint64_t n = aliases_not_stored_.fetch_add(1) + 1;
    if ((n & (n - 1)) == 0) {
      LogLine("warn", "repeated plans not persisted: write queue full",
              {{"plan", alias_id}, {"not_stored_total", absl::StrCat(n)}});
    }
    return;
  }
  if (schedule && !io_pool_->TrySubmit([this] { FlushAliases(); })) {
    // The I/O pool is full: the next alias tries again.
    absl::MutexLock lock(&aliases_mu_);
    alias_flush_queued_ = false;
  }
}

void PlanArchive::StoreAliases(const std::vector<std::pair<std::string, std::string>>& records,
                               const std::set<std::string>& originals) {
  if (absl::Status s = store_->PutPlans(records); !s.ok()) {
    LogLine("warn", "repeated plans not persisted",
            {{"plans", absl::StrCat(records.size())}, {"detail", std::string(s.message())}});
  }
  const uint64_t before = persisted_.fetch_add(records.size());
  // Newer than their aliases: trimmed after them (an original not yet
  // written is written newest anyway).
  for (const std::string& id : originals) {
    if (absl::Status s = store_->TouchPlan(id); !s.ok() && !absl::IsNotFound(s)) {
      LogLine("warn", "stored plan not touched",
              {{"plan", id}, {"detail", std::string(s.message())}});
    }
  }
  if (before / 256 != (before + records.size()) / 256) store_->TrimPlans(options_.max_stored_plans);
}

void PlanArchive::FlushAliases() {
  for (;;) {
    std::deque<PendingAlias> batch;
    {
      absl::MutexLock lock(&aliases_mu_);
      if (pending_aliases_.empty()) {
        alias_flush_queued_ = false;
        return;
      }
      batch.swap(pending_aliases_);
    }
    std::vector<std::pair<std::string, std::string>> records;
    records.reserve(batch.size());
    std::set<std::string> originals;
    for (PendingAlias& a : batch) {
      records.emplace_back(std::move(a.alias_id), std::move(a.record));
      originals.insert(std::move(a.original_id));
    }
    StoreAliases(records, originals);
  }
}

void PlanArchive::StoreUnusedAliases() {
  const absl::Time start = absl::Now();
  std::vector<std::pair<std::string, std::string>> records;
  std::set<std::string> originals;
  const std::vector<std::pair<std::string, std::string>> unused = plans_.UnusedAliases();
  {
    absl::MutexLock lock(&origins_mu_);
    for (const auto& [alias_id, original_id] : unused) {
      if (origins_.count(original_id) == 0) continue;  // not stored (an inline map's plan)
      records.emplace_back(alias_id, AliasRecord(original_id));
      originals.insert(original_id);
    }
  }
  if (records.empty()) return;
  StoreAliases(records, originals);
  for (const auto& [alias_id, record] : records) plans_.MarkUsed(alias_id);  // stored once
  LogLine("info", "unused repeated plans stored",
          {{"plans", absl::StrCat(records.size())},
           {"ms", absl::StrFormat("%.1f", absl::ToDoubleMilliseconds(absl::Now() - start))}});
}

std::shared_ptr<const RetainedPlan> PlanArchive::Find(const std::string& plan_id,
                                                      const StopToken& stop,
                                                      v1::PlanRequest* origin) {
  if (std::shared_ptr<const RetainedPlan> in_memory = Get(plan_id)) {
    OriginOf(plan_id, origin);
    return in_memory;
  }
  if (std::optional<std::string> original = plans_.OriginalOf(plan_id)) {
    // An alias whose original is no longer retained: the original from the
    // store, copied under the alias's id.
    std::shared_ptr<const RetainedPlan> base = Load(*original, stop, origin, /*depth=*/1);
    if (base == nullptr) return nullptr;
    auto copy = std::make_shared<RetainedPlan>(*base);
    copy->plan_id = plan_id;
    plans_.Put(copy);
    plans_.MarkUsed(plan_id);
    AliasUsed(plan_id, *original);
    return copy;
  }
  return Load(plan_id, stop, origin, /*depth=*/0);
}

std::shared_ptr<const RetainedPlan> PlanArchive::Load(const std::string& plan_id,
                                                      const StopToken& stop,
                                                      v1::PlanRequest* origin, int depth) {
  // Missions are stored beside the plans (FleetMissions): not a plan.
  if (absl::StartsWith(plan_id, "mission-")) return nullptr;
  absl::StatusOr<std::string> bytes = store_->GetPlan(plan_id);
  v1::InlinePlan record;
  if (!bytes.ok() || !record.ParseFromString(*bytes)) return nullptr;
  std::shared_ptr<const RetainedPlan> plan;
  const std::string& named = record.plan().plan_id();
  if (!named.empty() && named != plan_id) {
    // An alias: its original's plan and origin, under the alias's id.
    if (depth > 0) return nullptr;
    std::shared_ptr<const RetainedPlan> original = plans_.Get(named);
    if (original == nullptr || !OriginOf(named, origin)) {
      original = Load(named, stop, origin, depth + 1);
    }
    if (original == nullptr) return nullptr;
    *record.mutable_request() = *origin;
    auto copy = std::make_shared<RetainedPlan>(*original);
    copy->plan_id = plan_id;
    plan = std::move(copy);
  } else {
    *origin = record.request();
    if (record.request().map_ref_case() != v1::PlanRequest::kMapId) return nullptr;
    // After a restart: rebuild the plan on its stored map.
    absl::StatusOr<RetainedPlan> rebuilt = RetainedPlanFromInline(
        record, *engine_, MapSourceFor(store_, options_.limits, record.request().map_id(), nullptr),
        stop);
    if (!rebuilt.ok()) {
      LogLine("warn", "stored plan could not be rebuilt",
              {{"plan", plan_id}, {"detail", std::string(rebuilt.status().message())}});
      return nullptr;
    }
    rebuilt->plan_id = plan_id;
    plan = std::make_shared<const RetainedPlan>(std::move(*rebuilt));
  }
  plans_.Put(plan);
  // Found in memory from now on: its origin with it (its replans are persisted).
  RememberOrigin(plan_id, std::make_shared<const v1::PlanRequest>(record.request()));
  return plan;
}

void PlanArchive::PublishEstimator() {
  metrics_->SetReplanEstimator(estimator_.coefficients().a, estimator_.coefficients().b,
                               estimator_.coefficients().c, estimator_.num_samples());
}

void PlanArchive::SaveEstimator() {
  // Off the reply's path.
  auto text = std::make_shared<std::string>(estimator_.Serialize());
  io_pool_->TrySubmit([this, text] {
    if (absl::Status s = store_->PutState(EstimatorFile(options_.replica), *text); !s.ok()) {
      LogLine("warn", "replan estimator not saved", {{"detail", std::string(s.message())}});
    }
  });
}

}  // namespace covplan
