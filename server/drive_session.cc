#include "server/drive_session.h"

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "api/convert.h"
#include "planner/replan/replanner.h"
#include "server/grpc_status.h"
#include "server/log.h"
#include "server/request_limits.h"
#include "server/tenant_tokens.h"

namespace covplan {
namespace {

int ObstacleItems(const v1::Obstacles& o) {
  return o.cells_size() + o.points_size() + o.polygons_size();
}

}  // namespace

// What a reaction decided under the lock, done after releasing it (gRPC
// operations are started without holding mu_, and Finish is the last touch).
struct DriveSession::Actions {
  const v1::DriveEvent* write = nullptr;
  bool read = false;
  bool finish = false;
  grpc::Status status;
  bool share = false;  // `shared` was seen by this session's robot, for its mission
  v1::Obstacles shared;
  std::vector<std::pair<std::string, std::string>> adopted;  // previous plan, new plan
};

DriveSession::DriveSession(DriveHost* host, grpc::CallbackServerContext* context,
                           SessionRegistry* registry, std::string session_id,
                           DriveHost::Tenant tenant)
    : host_(host),
      context_(context),
      registry_(registry),
      session_id_(std::move(session_id)),
      tenant_(std::move(tenant)) {}

void DriveSession::Start() {
  {
    absl::MutexLock lock(&mu_);
    last_message_ = absl::Now();
  }
  StartRead(&in_);
}

void DriveSession::Perform(const Actions& a) {
  for (const auto& [previous, plan_id] : a.adopted) host_->PlanAdopted(previous, plan_id);
  if (a.share) {
    // The robot's plans as they are now, newest first: its replan may have
    // been adopted (and the mission moved onto it) since it was read.
    std::vector<std::string> plans;
    {
      absl::MutexLock lock(&mu_);
      plans.assign(plans_.rbegin(), plans_.rend());
      if (first_.plan_ref_case() == v1::DriveRequest::kPlanId) plans.push_back(first_.plan_id());
    }
    host_->ShareObstacles(plans, a.shared);
  }
  if (a.write != nullptr) StartWrite(a.write);
  if (a.read) StartRead(&in_);
  if (a.finish) Finish(a.status);  // may delete this (through OnDone): last
}

void DriveSession::OnReadDone(bool ok) {
  Actions a;
  {
    absl::MutexLock lock(&mu_);
    if (!ok) {
      reads_done_ = true;  // the client closed its side (or the call ended)
    } else {
      last_message_ = absl::Now();
      HandleMessage(&a);
      a.read = !ending_;
    }
    CheckFinish(&a);
  }
  Perform(a);
}

void DriveSession::OnWriteDone(bool ok) {
  Actions a;
  {
    absl::MutexLock lock(&mu_);
    writing_ = false;
    out_.pop_front();
    if (!ok) {
      EndLocked(grpc::Status(grpc::StatusCode::CANCELLED, "the client stopped reading"));
    } else if (!out_.empty() && !ending_) {
      writing_ = true;
      a.write = &out_.front();
    }
    CheckFinish(&a);
  }
  Perform(a);
}

void DriveSession::OnCancel() {
  Actions a;
  {
    absl::MutexLock lock(&mu_);
    EndLocked(grpc::Status(grpc::StatusCode::CANCELLED, "session cancelled"));
    CheckFinish(&a);
  }
  Perform(a);
}

void DriveSession::OnDone() {
  LogLine("info", "drive session ended", {{"session", session_id_}});
  {
    absl::MutexLock lock(&mu_);
    if (v1::LiveEvent e; LiveEventLocked(&e)) {
      const int code = ending_ ? static_cast<int>(end_status_.error_code()) : 0;
      e.mutable_ended()->set_status(
          CodeName(absl::Status(static_cast<absl::StatusCode>(code), "")));
      host_->Live(e);
    }
  }
  registry_->Remove(this);
  host_->UpdateSessionGauge();
  Unref();
}

bool DriveSession::ExpireIfIdle(absl::Time idle_before) {
  Actions a;
  {
    absl::MutexLock lock(&mu_);
    if (finished_ || ending_ || running_ || last_message_ >= idle_before) return false;
    EndLocked(grpc::Status(
        grpc::StatusCode::DEADLINE_EXCEEDED,
        absl::StrFormat(
            "drive session idle for more than %g s without a message (--session_idle_s)",
            absl::ToDoubleSeconds(registry_->idle_timeout()))));
    CheckFinish(&a);
  }
  Perform(a);
  return true;
}

void DriveSession::End(const grpc::Status& status) {
  Actions a;
  {
    absl::MutexLock lock(&mu_);
    EndLocked(status);
    CheckFinish(&a);
  }
  Perform(a);
}

void DriveSession::EndLocked(const grpc::Status& status) {
  if (ending_ || finished_) return;
  ending_ = true;
  end_status_ = status;
  running_stop_.Cancel();
  pending_.reset();
}

void DriveSession::CheckFinish(Actions* a) {
  if (finished_) return;
  if (!ending_ && !reads_done_) return;  // the client may still send
  if (running_ || writing_) return;      // a cancelled replan returns soon
  if (!ending_ && (pending_.has_value() || !out_.empty())) return;
  finished_ = true;
  a->finish = true;
  a->status = end_status_;
}

void DriveSession::Push(v1::DriveEvent event, Actions* a) {
  if (ending_ || finished_) return;  // finished: the call is over (OnDone comes)
  out_.push_back(std::move(event));
  if (!writing_) {
    writing_ = true;
    a->write = &out_.front();
  }
}

void DriveSession::PushError(uint64_t sequence, const absl::Status& status, Actions* a) {
  v1::DriveEvent event;
  event.set_sequence(sequence);
  event.mutable_error()->set_code(static_cast<int32_t>(status.code()));
  event.mutable_error()->set_message(std::string(status.message()));
  Push(std::move(event), a);
}

bool DriveSession::KnowsPlan(const std::string& plan_id) const {
  for (const std::string& p : plans_) {
    if (p == plan_id) return true;
  }
  return false;
}

void DriveSession::HandleMessage(Actions* a) {
  const uint64_t seq = in_.sequence();
  if (absl::Status s = CheckRequestStrings(in_); !s.ok()) {
    if (!started_) {
      started_ = true;
      EndLocked(ToGrpcUnbounded(s));
    } else {
      PushError(seq, s, a);
    }
    return;
  }
  if (!started_) {
    started_ = true;
    if (in_.plan_ref_case() == v1::DriveRequest::PLAN_REF_NOT_SET) {
      EndLocked(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                             "the first DriveRequest needs plan_id or an inline plan"));
      return;
    }
    if (absl::StatusOr<ReplanMethod> m = ReplanMethodFromProto(in_.method()); !m.ok()) {
      EndLocked(ToGrpcUnbounded(m.status()));
      return;
    }
    first_ = in_;
    first_.clear_obstacles();
    Job job;
    job.start = true;
    job.sequence = seq;
    pending_ = std::move(job);
    StartJob(a);
    if (ObstacleItems(in_.obstacles()) == 0) {
      // Where the robot is (a robot that reconnected says so first): kept for
      // Resume like any report, on a plan of the caller's tenant.
      if (in_.has_progress() && in_.plan_ref_case() == v1::DriveRequest::kPlanId &&
          OwnsPlan(tenant_.tag, in_.plan_id())) {
        host_->RecordProgress(in_.plan_id(), in_.progress());
      }
      return;
    }
    // Obstacles in the first message: replanned once the plan is adopted.
  } else if (in_.plan_ref_case() == v1::DriveRequest::kPlan) {
    PushError(
        seq, absl::InvalidArgumentError("only the first DriveRequest may carry an inline plan"), a);
    return;
  }
  std::string plan_id = in_.plan_id();
  if (!plan_id.empty() && !KnowsPlan(plan_id) &&
      !(adopted_ == false && plan_id == first_.plan_id())) {
    PushError(seq,
              absl::InvalidArgumentError(absl::StrCat("plan_id '", plan_id.substr(0, 80),
                                                      "' is not a plan of this session")),
              a);
    return;
  }
  const int items = ObstacleItems(in_.obstacles());
  if (items == 0) {
    // A progress report: kept for Resume.
    if (in_.has_progress()) {
      if (plan_id.empty() && !plans_.empty()) plan_id = plans_.back();
      if (plan_id.empty() && first_.plan_ref_case() == v1::DriveRequest::kPlanId)
        plan_id = first_.plan_id();
      if (!plan_id.empty()) host_->RecordProgress(plan_id, in_.progress());
      if (v1::LiveEvent e; LiveEventLocked(&e)) {
        if (!plan_id.empty()) e.set_plan_id(plan_id);  // as far as the robot knows
        *e.mutable_progress() = in_.progress();
        host_->Live(e);
      }
    }
    return;
  }
  if (seen_items_ + items > kMaxObstacleItems) {
    PushError(seq,
              absl::ResourceExhaustedError(absl::StrFormat(
                  "a drive session accepts at most %d obstacle items (cells, points, polygons); "
                  "this one has %d and the message adds %d",
                  kMaxObstacleItems, seen_items_, items)),
              a);
    return;
  }
  if (absl::Status s = CheckObservation(in_.obstacles()); !s.ok()) {
    PushError(seq, s, a);
    return;
  }
  if (absl::StatusOr<ReplanMethod> m = ReplanMethodFromProto(in_.method()); !m.ok()) {
    PushError(seq, m.status(), a);
    return;
  }
  seen_.MergeFrom(in_.obstacles());
  seen_items_ += items;
  if (v1::LiveEvent e; LiveEventLocked(&e)) {
    if (!plan_id.empty()) e.set_plan_id(plan_id);
    *e.mutable_obstacles() = in_.obstacles();
    host_->Live(e);
    if (in_.has_progress()) {
      e.clear_obstacles();
      *e.mutable_progress() = in_.progress();
      host_->Live(e);
    }
  }
  Job job;
  job.sequence = seq;
  job.plan_id = plan_id;
  job.progress = in_.progress();
  job.method = in_.method();
  Enqueue(std::move(job), /*keep_running=*/false, a);
  // The other robots of its fleet mission learn of them (after the lock).
  a->share = true;
  a->shared = in_.obstacles();
}

void DriveSession::Enqueue(Job job, bool keep_running, Actions* a) {
  job.generation = generation_;
  if (pending_.has_value() && !pending_->start) {
    job.superseded = std::move(pending_->superseded);
    if (pending_->sequence != 0) job.superseded.push_back(pending_->sequence);
    pending_.reset();
  }
  if (running_ && !running_start_) {
    // Superseded: its result will not be pushed (a kept one still records
    // the robot's progress, which `job` may start from).
    if (!keep_running) running_stop_.Cancel();
    if (running_sequence_ != 0) job.superseded.push_back(running_sequence_);
  }
  pending_ = std::move(job);
  if (!running_) StartJob(a);
}

bool DriveSession::LiveEventLocked(v1::LiveEvent* e) {
  if (map_id_.empty() || !host_->Watched(map_id_)) return false;
  e->set_map_id(map_id_);
  e->set_session_id(session_id_);
  if (!plans_.empty()) e->set_plan_id(plans_.back());
  return true;
}

void DriveSession::Adopt(const std::string& plan_id) {
  plans_.push_back(plan_id);
  while (plans_.size() > kMaxSessionPlans) {
    registry_->Untrack(this, plans_.front());
    plans_.pop_front();
  }
  registry_->Track(this, plan_id);
}

bool DriveSession::PushMissionPlan(const std::string& plan_id, const v1::DriveEvent& event) {
  Actions a;
  {
    absl::MutexLock lock(&mu_);
    if (ending_ || finished_ || !adopted_ || plans_.empty() || plans_.back() != plan_id)
      return false;
    ++generation_;  // results of jobs queued before are stale now
    if (running_ && !running_start_) running_stop_.Cancel();
    std::vector<uint64_t> superseded;
    if (pending_.has_value()) {
      superseded = std::move(pending_->superseded);
      if (pending_->sequence != 0) superseded.push_back(pending_->sequence);
      pending_.reset();
    }
    const std::string& fresh = event.replan().plan().plan_id();
    const std::string previous = plans_.back();
    Adopt(fresh);
    if (v1::LiveEvent e; LiveEventLocked(&e)) {
      v1::LiveReplan* r = e.mutable_replan();
      r->set_previous_plan_id(previous);
      *r->mutable_replan() = event.replan().replan();
      *r->mutable_mission() = event.mission();
      host_->Live(e);
    }
    v1::DriveEvent pushed = event;
    pushed.set_sequence(0);
    for (uint64_t s : superseded) pushed.add_superseded(s);
    Push(std::move(pushed), &a);
    if (seen_items_ > 0) {  // the new plan does not know what this robot saw
      Job job;
      job.plan_id = fresh;
      job.notice = event.mission();
      Enqueue(std::move(job), /*keep_running=*/true, &a);
    }
    CheckFinish(&a);
  }
  Perform(a);
  return true;
}

void DriveSession::ShareObservation(const std::string& plan_id, const v1::Obstacles& obstacles,
                                    const v1::MissionNotice& notice) {
  Actions a;
  {
    absl::MutexLock lock(&mu_);
    // `plan_id` is the plan the mission holds for this robot: this one, or
    // one it replaced whose successor the mission does not know yet.
    if (ending_ || finished_ || !adopted_ ||
        std::find(plans_.begin(), plans_.end(), plan_id) == plans_.end())
      return;
    const int items = ObstacleItems(obstacles);
    if (items == 0 || seen_items_ + items > kMaxObstacleItems) return;
    if (!CheckObservation(obstacles).ok()) return;
    seen_.MergeFrom(obstacles);
    seen_items_ += items;
    // A replan of the robot's own observation waits: it takes these along.
    if (pending_.has_value() && !pending_->start) return;
    Job job;
    job.plan_id = plans_.back();
    job.notice = notice;
    Enqueue(std::move(job), /*keep_running=*/true, &a);
    CheckFinish(&a);
  }
  Perform(a);
}

absl::Status DriveSession::CheckObservation(const v1::Obstacles& obstacles) const {
  Observations seen = ObstaclesFromProto(obstacles);
  if (grid_ != nullptr) return ValidateObservations(*grid_, seen);
  // Before the plan is adopted only the grid-free checks apply (finite
  // points, valid polygons); the replan checks the cells.
  seen.cells.clear();
  return ValidateObservations(Grid(1, 1, 1.0, {0.0, 0.0}, {1}), seen);
}

void DriveSession::StartJob(Actions* a) {
  if (!pending_.has_value() || running_ || ending_ || finished_) return;
  Job job = std::move(*pending_);
  pending_.reset();
  if (!job.start && job.plan_id.empty() && !plans_.empty()) job.plan_id = plans_.back();
  running_ = true;
  running_start_ = job.start;
  running_sequence_ = job.sequence;
  running_stop_ = StopToken();
  const StopToken stop = running_stop_;
  v1::DriveRequest first = first_;
  v1::Obstacles seen = seen_;
  Ref();  // held by the worker
  const absl::Status queued = host_->SubmitSolve(
      tenant_, [this, job, first = std::move(first), seen = std::move(seen), stop] {
        RunJob(job, first, seen, stop);
        Unref();
      });
  if (!queued.ok()) {
    running_ = false;
    Unref();  // not the last: gRPC holds one until OnDone
    const absl::Status busy(queued.code(),
                            absl::StrCat(queued.message(),
                                         "; no worker for this session's replan, the obstacles are "
                                         "kept for the next one"));
    if (job.start) {
      EndLocked(ToGrpcUnbounded(busy));
    } else {
      PushError(job.sequence, busy, a);
    }
  }
}

void DriveSession::RunJob(const Job& job, const v1::DriveRequest& first, const v1::Obstacles& seen,
                          const StopToken& stop) {
  v1::DriveEvent event;
  event.set_sequence(job.sequence);
  absl::Status status;
  std::shared_ptr<const Grid> grid;
  std::string adopted, map_id;
  double compute_ms = 0.0;
  if (job.start) {
    absl::StatusOr<DriveHost::AdoptedPlan> plan = host_->AdoptPlan(first, stop, tenant_);
    status = plan.status();
    if (plan.ok()) {
      adopted = plan->plan_id;
      map_id = plan->map_id;
      grid = plan->grid;
      v1::DriveReady* ready = event.mutable_ready();
      ready->set_session_id(session_id_);
      ready->set_plan_id(adopted);
      ready->set_idle_timeout_s(absl::ToDoubleSeconds(registry_->idle_timeout()));
    }
  } else {
    v1::ReplanRequest request;
    request.set_plan_id(job.plan_id);
    *request.mutable_progress() = job.progress;
    if (job.notice.has_value()) {  // a mission's job: where the robot last reported it was
      std::optional<v1::RobotProgress> recorded = host_->RecordedProgress(job.plan_id);
      if (recorded.has_value()) {
        *request.mutable_progress() = *recorded;
      } else {
        request.mutable_progress()->set_distance_m(0.0);  // not started
      }
    }
    *request.mutable_obstacles() = seen;
    request.set_method(job.method != v1::REPLAN_METHOD_UNSPECIFIED ? job.method : first.method());
    request.set_seed(first.seed());
    const absl::Time t0 = absl::Now();
    status = host_->Replan(absl::StrCat(session_id_, "/", job.sequence), tenant_, request, stop,
                           event.mutable_replan());
    compute_ms = absl::ToDoubleMilliseconds(absl::Now() - t0);
  }
  Actions a;
  {
    absl::MutexLock lock(&mu_);
    running_ = false;
    if (job.start) {
      if (!status.ok()) {
        EndLocked(ToGrpcUnbounded(status));
      } else {
        adopted_ = true;
        grid_ = grid;
        map_id_ = map_id;
        Adopt(adopted);
        if (v1::LiveEvent e; LiveEventLocked(&e)) {
          e.mutable_started();
          host_->Live(e);
        }
        Push(std::move(event), &a);
      }
    } else if (pending_.has_value() || job.generation != generation_) {
      host_->CountSuperseded();  // a newer observation waits, or a mission pushed a plan
    } else if (!status.ok()) {
      if (job.notice.has_value() && job.superseded.empty()) {
        LogLine("warn", "mission replan failed",
                {{"session", session_id_}, {"detail", std::string(status.message())}});
      } else {
        PushError(job.sequence, status, &a);
      }
    } else if (job.notice.has_value() && job.superseded.empty() &&
               job.notice->cause() == v1::MissionNotice::SHARED_OBSTACLE &&
               event.replan().replan().num_encounters() == 0) {
      // Another robot's obstacles do not touch this robot's remaining path.
    } else {
      a.adopted.emplace_back(plans_.back(), event.replan().plan().plan_id());
      Adopt(event.replan().plan().plan_id());
      if (v1::LiveEvent e; LiveEventLocked(&e)) {
        v1::LiveReplan* r = e.mutable_replan();
        r->set_previous_plan_id(a.adopted.back().first);
        *r->mutable_replan() = event.replan().replan();
        r->set_compute_ms(compute_ms);
        if (job.notice.has_value()) *r->mutable_mission() = *job.notice;
        host_->Live(e);
      }
      for (uint64_t s : job.superseded) event.add_superseded(s);
      if (job.notice.has_value()) *event.mutable_mission() = *job.notice;
      Push(std::move(event), &a);
    }
    StartJob(&a);
    CheckFinish(&a);
  }
  Perform(a);
}

}  // namespace covplan
