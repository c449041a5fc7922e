// The Drive streaming session (covplan.v1.CoveragePlanner/Drive): a robot
// streams progress and obstacle observations while it drives; the server
// pushes a new plan whenever one is ready.
//
// One DriveSession per call, on gRPC's callback API: reads, writes and the
// end of the call are driven by gRPC's reactions and by solves that run on
// the host's worker pool (never on a gRPC thread); the session reaches the
// service only through DriveHost (server/drive_host.h). At most one replan of
// a session runs at a time. An observation that arrives while one runs cancels
// it (its StopToken) and waits: when the worker returns, the newest
// observation is replanned with every obstacle the session has seen, so a
// superseded observation loses nothing; its replan is simply not pushed.
//
// Sessions are bounded: SessionRegistry refuses sessions beyond its limit,
// and its reaper ends sessions idle longer than the idle timeout with
// DEADLINE_EXCEEDED. A client that goes away cancels the call, which cancels
// the running replan and frees the session.
//
// Lifetime: gRPC holds one reference until OnDone; the reaper takes a
// reference while it inspects a session, so a session is deleted by
// whichever drops the last one.
//
// Thread-safety: all state is guarded by the session's mutex; gRPC
// operations are started with it held and Finish() only without it.
#ifndef COVPLAN_SERVER_DRIVE_SESSION_H_
#define COVPLAN_SERVER_DRIVE_SESSION_H_

#include <atomic>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "planner/common/stop_token.h"
#include "planner/grid/grid.h"
#include "server/drive_host.h"

namespace covplan {

class SessionRegistry;

class DriveSession final : public grpc::ServerBidiReactor<v1::DriveRequest, v1::DriveEvent> {
 public:
  // Most obstacle items (cells + points + polygons) one session may report.
  static constexpr int kMaxObstacleItems = 20000;
  // Most plans of a session that later messages may name.
  static constexpr size_t kMaxSessionPlans = 64;

  DriveSession(DriveHost* host, grpc::CallbackServerContext* context, SessionRegistry* registry,
               std::string session_id, DriveHost::Tenant tenant);

  // Starts reading (after the registry admitted the session).
  void Start();

  void OnReadDone(bool ok) override;
  void OnWriteDone(bool ok) override;
  void OnCancel() override;
  void OnDone() override;

  // Called by the reaper: ends the session if it has been idle since before
  // `idle_before`. Returns true when it did.
  bool ExpireIfIdle(absl::Time idle_before);
  // Ends the session with `status` (server draining).
  void End(const grpc::Status& status);

  // Fleet missions (server/drive_handler.h). Both act only while the
  // session's newest plan is `plan_id` (the robot drives it).
  // A new plan UpdateMission made for this robot: pushed as is (sequence
  // 0, `mission` set); a replan of this session still running is dropped,
  // and when the session has seen obstacles the new plan is replanned
  // around them at once. False when the session does not drive `plan_id`.
  bool PushMissionPlan(const std::string& plan_id, const v1::DriveEvent& event);
  // Obstacles another robot of the mission saw: merged into this session's
  // and replanned from the robot's recorded progress; the new plan is pushed
  // (with `notice`) only when the obstacles touch its remaining path.
  void ShareObservation(const std::string& plan_id, const v1::Obstacles& obstacles,
                        const v1::MissionNotice& notice);

  void Ref() { refs_.fetch_add(1); }
  void Unref() {
    if (refs_.fetch_sub(1) == 1) delete this;
  }

 private:
  struct Job {
    bool start = false;  // adopt the first message's plan
    uint64_t sequence = 0;
    std::string plan_id;  // the plan the progress refers to ("" = newest)
    v1::RobotProgress progress;
    v1::ReplanMethod method = v1::REPLAN_METHOD_UNSPECIFIED;  // unset: the session's
    std::vector<uint64_t> superseded;
    // A mission's job: from the progress recorded for plan_id (not
    // `progress`), pushed with this notice, and only if the plan changed.
    std::optional<v1::MissionNotice> notice;
    uint64_t generation = 0;  // the session's generation when it was queued
  };
  struct Actions;

  ~DriveSession() override = default;
  void Perform(const Actions& a);
  // Handles in_ (the message just read).
  void HandleMessage(Actions* a) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  absl::Status CheckObservation(const v1::Obstacles& obstacles) const
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  bool KnowsPlan(const std::string& plan_id) const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  void StartJob(Actions* a) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // Queues `job`, superseding a queued one (and cancelling a running one of
  // the robot's own observations unless `keep_running`).
  void Enqueue(Job job, bool keep_running, Actions* a) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // The session drives `plan_id` now (newest last; the registry's index).
  void Adopt(const std::string& plan_id) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // Starts a LiveEvent of this robot in `e` (map, session, current plan);
  // false when nobody watches its map (or no plan is adopted yet). Events
  // are published under mu_ (host_->Live), so watchers see them in the
  // order the session changed; the host never calls back into a session.
  bool LiveEventLocked(v1::LiveEvent* e) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  void RunJob(const Job& job, const v1::DriveRequest& first, const v1::Obstacles& seen,
              const StopToken& stop);
  void Push(v1::DriveEvent event, Actions* a) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  void PushError(uint64_t sequence, const absl::Status& status, Actions* a)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // Stops taking input and pushing events; the call ends with `status`.
  void EndLocked(const grpc::Status& status) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  // Finishes the call once no replan runs and nothing is being written.
  void CheckFinish(Actions* a) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  DriveHost* const host_;
  grpc::CallbackServerContext* const context_;
  SessionRegistry* const registry_;
  const std::string session_id_;
  const DriveHost::Tenant tenant_;  // the caller's tenant (server/tenant_tokens.h)
  std::atomic<int> refs_{1};

  mutable absl::Mutex mu_;
  v1::DriveRequest in_ ABSL_GUARDED_BY(mu_);
  std::deque<v1::DriveEvent> out_ ABSL_GUARDED_BY(mu_);  // front: being written
  bool writing_ ABSL_GUARDED_BY(mu_) = false;
  bool started_ ABSL_GUARDED_BY(mu_) = false;  // the first message was read
  bool adopted_ ABSL_GUARDED_BY(mu_) = false;  // its plan was found
  bool reads_done_ ABSL_GUARDED_BY(mu_) = false;
  bool ending_ ABSL_GUARDED_BY(mu_) = false;  // cancelled, expired or failed: push nothing more
  bool finished_ ABSL_GUARDED_BY(mu_) = false;
  grpc::Status end_status_ ABSL_GUARDED_BY(mu_);
  std::string map_id_ ABSL_GUARDED_BY(mu_);                // the adopted plan's map
  v1::DriveRequest first_ ABSL_GUARDED_BY(mu_);            // method, seed, plan_ref
  std::shared_ptr<const Grid> grid_ ABSL_GUARDED_BY(mu_);  // the plans' grid (for checks)
  std::deque<std::string> plans_ ABSL_GUARDED_BY(mu_);     // newest last
  v1::Obstacles seen_ ABSL_GUARDED_BY(mu_);
  int seen_items_ ABSL_GUARDED_BY(mu_) = 0;
  std::optional<Job> pending_ ABSL_GUARDED_BY(mu_);
  // Raised when a mission pushes a plan: results of jobs queued before are stale.
  uint64_t generation_ ABSL_GUARDED_BY(mu_) = 0;
  bool running_ ABSL_GUARDED_BY(mu_) = false;
  bool running_start_ ABSL_GUARDED_BY(mu_) = false;
  uint64_t running_sequence_ ABSL_GUARDED_BY(mu_) = 0;
  StopToken running_stop_ ABSL_GUARDED_BY(mu_);
  // From construction: the reaper can see a session between its Add and Start.
  absl::Time last_message_ ABSL_GUARDED_BY(mu_) = absl::Now();
};

// The live sessions of a service: a bound on their number and a reaper
// thread that ends idle ones.
//
// Thread-safety: all methods are thread-safe.
class SessionRegistry {
 public:
  SessionRegistry(int max_sessions, absl::Duration idle_timeout);
  ~SessionRegistry();  // stops the reaper; sessions must have ended

  // False when `max_sessions` are open.
  bool Add(DriveSession* session);
  void Remove(DriveSession* session);
  int size() const;
  // The session that drives or drove `plan_id` (one of its recent plans),
  // with a reference the caller drops (Unref); null when none.
  DriveSession* Find(const std::string& plan_id);
  // `session` drives `plan_id` now (its earlier plans stay found until
  // Untrack: a fleet mission may still name one).
  void Track(DriveSession* session, const std::string& plan_id);
  void Untrack(DriveSession* session, const std::string& plan_id);
  absl::Duration idle_timeout() const { return idle_timeout_; }
  // Ends every open session with UNAVAILABLE (the server is draining).
  void EndAll();

 private:
  void Reap();
  // The open sessions, each with a reference the caller drops.
  std::vector<DriveSession*> Snapshot();

  const int max_sessions_;
  const absl::Duration idle_timeout_;
  mutable absl::Mutex mu_;
  std::set<DriveSession*> sessions_ ABSL_GUARDED_BY(mu_);
  std::map<std::string, DriveSession*> by_plan_ ABSL_GUARDED_BY(mu_);  // newest plan -> session
  bool stop_ ABSL_GUARDED_BY(mu_) = false;
  std::thread reaper_;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_DRIVE_SESSION_H_
