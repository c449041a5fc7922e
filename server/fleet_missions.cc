#include "server/fleet_missions.h"

#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "covplan/v1/covplan.pb.h"
#include "server/log.h"
#include "server/plan_archive.h"

namespace covplan {

std::string NewMissionId(const std::string& tenant_tag) {
  std::string id = NewPlanId(tenant_tag);
  if (absl::StartsWith(id, "p-")) id.erase(0, 2);
  return absl::StrCat("mission-", id);
}

namespace {

std::string Serialized(const FleetMission& m) {
  v1::GetMissionResponse record;
  record.set_mission_id(m.mission_id);
  record.set_map_id(m.map_id);
  for (size_t i = 0; i < m.robot_ids.size(); ++i) {
    v1::MissionRobotState* r = record.add_robots();
    r->set_robot_id(m.robot_ids[i]);
    r->set_plan_id(i < m.plan_ids.size() ? m.plan_ids[i] : "");
    r->set_stopped(m.Stopped(i));
  }
  return record.SerializeAsString();
}

std::optional<FleetMission> Parsed(const std::string& mission_id, const std::string& bytes) {
  v1::GetMissionResponse record;
  if (!record.ParseFromString(bytes) || record.mission_id() != mission_id) return std::nullopt;
  FleetMission m;
  m.mission_id = record.mission_id();
  m.map_id = record.map_id();
  for (const v1::MissionRobotState& r : record.robots()) {
    m.robot_ids.push_back(r.robot_id());
    m.plan_ids.push_back(r.plan_id());
    m.stopped.push_back(r.stopped());
  }
  return m;
}

}  // namespace

void FleetMissions::Index(const FleetMission& m) const {
  for (const std::string& plan_id : m.plan_ids) {
    if (!plan_id.empty()) mission_of_plan_[plan_id] = m.mission_id;
  }
}

void FleetMissions::Unindex(const FleetMission& m) const {
  for (const std::string& plan_id : m.plan_ids) {
    auto it = mission_of_plan_.find(plan_id);
    if (it != mission_of_plan_.end() && it->second == m.mission_id) mission_of_plan_.erase(it);
  }
}

void FleetMissions::Keep(FleetMission mission) const {
  const std::string id = mission.mission_id;
  auto it = missions_.find(id);
  if (it != missions_.end()) {
    Unindex(it->second);
    it->second = std::move(mission);
  } else {
    it = missions_.emplace(id, std::move(mission)).first;
    order_.push_back(id);
  }
  Index(it->second);
  while (order_.size() > max_missions_) {
    auto oldest = missions_.find(order_.front());
    if (oldest != missions_.end()) {
      Unindex(oldest->second);
      missions_.erase(oldest);
    }
    order_.pop_front();
  }
}

std::optional<std::pair<FleetMission, size_t>> FleetMissions::MissionOfPlan(
    const std::string& plan_id) const {
  absl::MutexLock lock(&mu_);
  auto id = mission_of_plan_.find(plan_id);
  if (id == mission_of_plan_.end()) return std::nullopt;
  const FleetMission& m = missions_.at(id->second);
  for (size_t i = 0; i < m.plan_ids.size(); ++i) {
    if (m.plan_ids[i] == plan_id) return std::make_pair(m, i);
  }
  return std::nullopt;
}

bool FleetMissions::ReplacePlan(const std::string& old_plan_id, const std::string& new_plan_id) {
  std::string mission_id;
  {
    absl::MutexLock lock(&mu_);
    auto id = mission_of_plan_.find(old_plan_id);
    if (id == mission_of_plan_.end()) return false;
    mission_id = id->second;
    FleetMission& m = missions_.at(mission_id);
    for (std::string& plan_id : m.plan_ids) {
      if (plan_id == old_plan_id) plan_id = new_plan_id;
    }
    mission_of_plan_.erase(id);
    mission_of_plan_[new_plan_id] = mission_id;
  }
  Store(mission_id);
  return true;
}

void FleetMissions::Store(const std::string& mission_id) const {
  if (store_ == nullptr) return;
  absl::MutexLock write(&store_mu_);
  std::string bytes;
  {
    absl::MutexLock lock(&mu_);
    auto it = missions_.find(mission_id);
    if (it == missions_.end()) return;  // dropped meanwhile: the stored copy stays
    bytes = Serialized(it->second);
  }
  if (absl::Status s = store_->PutPlan(mission_id, bytes); !s.ok()) {
    LogLine("warn", "mission not persisted",
            {{"mission", mission_id}, {"detail", std::string(s.message())}});
  }
}

void FleetMissions::Put(FleetMission mission) {
  if (max_missions_ == 0) return;
  const std::string id = mission.mission_id;
  {
    absl::MutexLock lock(&mu_);
    Keep(std::move(mission));
  }
  Store(id);
}

std::optional<FleetMission> FleetMissions::Get(const std::string& mission_id) const {
  {
    absl::MutexLock lock(&mu_);
    auto it = missions_.find(mission_id);
    if (it != missions_.end()) return it->second;
  }
  if (store_ == nullptr || max_missions_ == 0 || !absl::StartsWith(mission_id, "mission-")) {
    return std::nullopt;
  }
  absl::StatusOr<std::string> bytes = store_->GetPlan(mission_id);
  if (!bytes.ok()) return std::nullopt;
  std::optional<FleetMission> stored = Parsed(mission_id, *bytes);
  if (!stored.has_value()) {
    LogLine("warn", "stored mission could not be read", {{"mission", mission_id}});
    return std::nullopt;
  }
  absl::MutexLock lock(&mu_);
  auto it = missions_.find(mission_id);  // another call may have loaded it first
  if (it != missions_.end()) return it->second;
  Keep(*stored);
  return stored;
}

absl::Status FleetMissions::Update(FleetMission mission,
                                   const std::vector<std::string>& expected_plan_ids) {
  const std::string id = mission.mission_id;
  {
    absl::MutexLock lock(&mu_);
    auto it = missions_.find(id);
    if (it == missions_.end()) {
      return absl::NotFoundError(absl::StrCat("mission ", id, " was dropped while it was updated"));
    }
    if (it->second.plan_ids != expected_plan_ids) {
      return absl::AbortedError(absl::StrCat(
          "mission ", id, " was updated by another call meanwhile; send the update again"));
    }
    Keep(std::move(mission));
  }
  Store(id);
  return absl::OkStatus();
}

size_t FleetMissions::size() const {
  absl::MutexLock lock(&mu_);
  return missions_.size();
}

}  // namespace covplan
