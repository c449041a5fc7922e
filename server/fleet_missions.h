// The fleet missions the server planned (PlanFleet): a mission_id names the
// robots of one fleet plan and the plan_id of each robot's plan (retained
// and persisted by the PlanArchive like any plan). Kept in memory only,
// bounded in count, oldest dropped first; UpdateMission replaces a
// mission's plan ids, marks robots stopped and adds joining ones
// (server/mission_handlers.h), GetMission reads it.
//
//   FleetMissions missions(/*max_missions=*/1000);
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
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"

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
  explicit FleetMissions(size_t max_missions) : max_missions_(max_missions) {}

  void Put(FleetMission mission);
  std::optional<FleetMission> Get(const std::string& mission_id) const;
  // Replaces the mission of mission.mission_id if its plan ids are still
  // `expected_plan_ids`: NOT_FOUND once it was dropped, ABORTED when another
  // update came first.
  absl::Status Update(FleetMission mission, const std::vector<std::string>& expected_plan_ids);
  size_t size() const;

 private:
  const size_t max_missions_;
  mutable absl::Mutex mu_;
  std::deque<std::string> order_ ABSL_GUARDED_BY(mu_);  // oldest first
  std::unordered_map<std::string, FleetMission> missions_ ABSL_GUARDED_BY(mu_);
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_FLEET_MISSIONS_H_
