#include "server/fleet_missions.h"

#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "server/plan_archive.h"

namespace covplan {

std::string NewMissionId(const std::string& tenant_tag) {
  std::string id = NewPlanId(tenant_tag);
  if (absl::StartsWith(id, "p-")) id.erase(0, 2);
  return absl::StrCat("mission-", id);
}

void FleetMissions::Put(FleetMission mission) {
  absl::MutexLock lock(&mu_);
  if (max_missions_ == 0) return;
  const std::string id = mission.mission_id;
  if (missions_.insert_or_assign(id, std::move(mission)).second) order_.push_back(id);
  while (order_.size() > max_missions_) {
    missions_.erase(order_.front());
    order_.pop_front();
  }
}

std::optional<FleetMission> FleetMissions::Get(const std::string& mission_id) const {
  absl::MutexLock lock(&mu_);
  auto it = missions_.find(mission_id);
  if (it == missions_.end()) return std::nullopt;
  return it->second;
}

absl::Status FleetMissions::Update(FleetMission mission,
                                   const std::vector<std::string>& expected_plan_ids) {
  absl::MutexLock lock(&mu_);
  auto it = missions_.find(mission.mission_id);
  if (it == missions_.end()) {
    return absl::NotFoundError(
        absl::StrCat("mission ", mission.mission_id, " was dropped while it was updated"));
  }
  if (it->second.plan_ids != expected_plan_ids) {
    return absl::AbortedError(absl::StrCat("mission ", mission.mission_id,
                                           " was updated by another call meanwhile; send the "
                                           "update again"));
  }
  it->second = std::move(mission);
  return absl::OkStatus();
}

size_t FleetMissions::size() const {
  absl::MutexLock lock(&mu_);
  return missions_.size();
}

}  // namespace covplan
