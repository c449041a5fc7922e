#include "server/plan_archive.h"

#include <sys/random.h>

#include <cerrno>
#include <cstdlib>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "api/convert.h"
#include "server/log.h"
#include "server/map_sources.h"
#include "server/tenant_tokens.h"

namespace covplan {
namespace {

constexpr char kEstimatorFile[] = "replan_estimator.txt";

}  // namespace

std::string NewPlanId(const std::string& tenant_tag) {
  unsigned char bytes[16];
  size_t got = 0;
  while (got < sizeof(bytes)) {
    const ssize_t n = ::getrandom(bytes + got, sizeof(bytes) - got, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      // getrandom cannot fail on Linux >= 3.17 once the pool is seeded; if it
      // ever does, refuse to hand out a guessable id.
      LogLine("error", "getrandom failed", {{"errno", absl::StrCat(errno)}});
      std::abort();
    }
    got += static_cast<size_t>(n);
  }
  std::string id = "p-";
  for (unsigned char b : bytes) absl::StrAppendFormat(&id, "%02x", b);
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
  if (absl::StatusOr<std::string> saved = store_->GetState(kEstimatorFile); saved.ok()) {
    const absl::Status parsed = estimator_.Parse(*saved);
    LogLine(parsed.ok() ? "info" : "warn", "replan estimator loaded",
            {{"samples", absl::StrCat(estimator_.num_samples())},
             {"detail", parsed.ok() ? "" : std::string(parsed.message())}});
  }
  PublishEstimator();
}

void PlanArchive::PublishRetainedCount() {
  metrics_->plans_retained().Set(static_cast<double>(plans_.size()));
}

void PlanArchive::Persist(const v1::PlanRequest& origin, const v1::PlanResponse& plan) {
  v1::InlinePlan record;
  *record.mutable_request() = origin;
  *record.mutable_plan() = plan;
  auto bytes = std::make_shared<std::string>();
  if (!record.SerializeToString(bytes.get())) return;
  const std::string plan_id = plan.plan_id();
  {
    absl::MutexLock lock(&origins_mu_);
    origins_.emplace_back(plan_id, std::make_shared<const v1::PlanRequest>(origin));
    while (origins_.size() > 4 * options_.max_retained_plans + 16) origins_.pop_front();
  }
  // Off the reply's path: the disk write (with its fsyncs) runs on the I/O
  // pool after the answer is on its way.
  const bool queued = io_pool_->TrySubmit([this, bytes, plan_id] {
    if (absl::Status s = store_->PutPlan(plan_id, *bytes); !s.ok()) {
      LogLine("warn", "plan not persisted",
              {{"plan", plan_id}, {"detail", std::string(s.message())}});
      return;
    }
    if (persisted_.fetch_add(1) % 256 == 255) store_->TrimPlans(options_.max_stored_plans);
  });
  if (!queued) LogLine("warn", "plan not persisted: I/O queue full", {{"plan", plan_id}});
}

std::shared_ptr<const RetainedPlan> PlanArchive::Find(const std::string& plan_id,
                                                      const StopToken& stop,
                                                      v1::PlanRequest* origin) {
  if (std::shared_ptr<const RetainedPlan> in_memory = plans_.Get(plan_id)) {
    absl::MutexLock lock(&origins_mu_);
    for (auto it = origins_.rbegin(); it != origins_.rend(); ++it) {
      if (it->first == plan_id) {
        *origin = *it->second;
        break;
      }
    }
    return in_memory;
  }
  // Missions are stored beside the plans (FleetMissions): not a plan.
  if (absl::StartsWith(plan_id, "mission-")) return nullptr;
  absl::StatusOr<std::string> bytes = store_->GetPlan(plan_id);
  v1::InlinePlan record;
  const bool stored = bytes.ok() && record.ParseFromString(*bytes);
  if (stored) *origin = record.request();
  if (!stored || record.request().map_ref_case() != v1::PlanRequest::kMapId) return nullptr;
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
  auto plan = std::make_shared<const RetainedPlan>(std::move(*rebuilt));
  plans_.Put(plan);
  {  // found in memory from now on: its origin with it (its replans are persisted)
    absl::MutexLock lock(&origins_mu_);
    origins_.emplace_back(plan_id, std::make_shared<const v1::PlanRequest>(record.request()));
    while (origins_.size() > 4 * options_.max_retained_plans + 16) origins_.pop_front();
  }
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
    if (absl::Status s = store_->PutState(kEstimatorFile, *text); !s.ok()) {
      LogLine("warn", "replan estimator not saved", {{"detail", std::string(s.message())}});
    }
  });
}

}  // namespace covplan
