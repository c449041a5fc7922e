// The fleet missions the server planned (PlanFleet): a mission_id names the
// robots of one fleet plan and the plan_id of each robot's plan (retained
// and persisted by the PlanArchive like any plan). Kept in memory, bounded
// in count (oldest dropped first), and written through to the store beside
// the plans (MapRepository::PutPlan under the mission id), so a mission
// survives a restart: Get reads a mission it does not hold from the store.
// UpdateMission replaces a mission's plan ids, marks robots stopped and adds
// joining ones (server/mission_handlers.h), GetMission reads it.
//
//   FleetMissions missions(/*max_missions=*/1000, store);
//   missions.Put({NewMissionId(tenant), map_id, {"r1", "r2"}, {plan_a, plan_b}});
//   std::optional<FleetMission> m = missions.Get(mission_id);
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_FLEET_MISSIONS_H_
#define COVPLAN_SERVER_FLEET_MISSIONS_H_

#include <cstddef>
#include <deque>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"
#include "server/map_repository.h"

namespace covplan {

// A mission id: a plan id's 128 random bits and tenant scope (NewPlanId),
// prefixed "mission-" instead of "p-".
std::string NewMissionId(const std::string& tenant_tag);

struct FleetMission {
  std::string mission_id;
  std::string map_id;
  std::vector<std::string> robot_ids;  // in request order
  std::vector<std::string> plan_ids;   // robot i's plan
  std::vector<bool> stopped;           // robot i stopped for good (missing: no)

  bool Stopped(size_t i) const { return i < stopped.size() && stopped[i]; }
};

class FleetMissions {
 public:
  // `store` (optional, not owned) keeps the missions across restarts.
  explicit FleetMissions(size_t max_missions, MapRepository* store = nullptr)
      : max_missions_(max_missions), store_(store) {}

  // Keeps the mission and writes it to the store (a failed write is logged:
  // the mission then lives until the restart).
  void Put(FleetMission mission);
  // From memory, else from the store (then kept in memory again).
  std::optional<FleetMission> Get(const std::string& mission_id) const;
  // Replaces the mission of mission.mission_id if its plan ids are still
  // `expected_plan_ids`: NOT_FOUND once it was dropped, ABORTED when another
  // update came first. Written through to the store.
  absl::Status Update(FleetMission mission, const std::vector<std::string>& expected_plan_ids);
  size_t size() const;

  // The mission (held in memory) whose robot currently drives `plan_id`, and
  // that robot's index in it.
  std::optional<std::pair<FleetMission, size_t>> MissionOfPlan(const std::string& plan_id) const;
  // A robot of a mission drives a replanned plan now (a Drive session or
  // Replan replaced `old_plan_id`): the mission follows it, so a later
  // UpdateMission redivides from the plan the robot really drives. False when
  // no mission (in memory) holds `old_plan_id`.
  bool ReplacePlan(const std::string& old_plan_id, const std::string& new_plan_id);

 private:
  void Index(const FleetMission& m) const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  void Unindex(const FleetMission& m) const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  void Keep(FleetMission mission) const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // Writes the mission as memory holds it now (writes in order: the last
  // one written is the newest state).
  void Store(const std::string& mission_id) const;

  const size_t max_missions_;
  MapRepository* const store_;
  mutable absl::Mutex store_mu_ ABSL_ACQUIRED_BEFORE(mu_);
  mutable absl::Mutex mu_;
  mutable std::deque<std::string> order_ ABSL_GUARDED_BY(mu_);  // oldest first
  mutable std::unordered_map<std::string, FleetMission> missions_ ABSL_GUARDED_BY(mu_);
  // plan_id -> mission_id, for the plans the missions in memory hold.
  mutable std::unordered_map<std::string, std::string> mission_of_plan_ ABSL_GUARDED_BY(mu_);
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_FLEET_MISSIONS_H_
