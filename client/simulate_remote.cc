#include "client/simulate_remote.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "api/convert.h"
#include "client/remote.h"
#include "planner/common/status_macros.h"

namespace covplan {
namespace {

class ServerPlanSource final : public PlanSource {
 public:
  ServerPlanSource(std::unique_ptr<RemotePlanner> remote, v1::Map map,
                   const SimulationOptions& options, double watch_speed)
      : remote_(std::move(remote)),
        map_(std::move(map)),
        method_(ReplanMethodToProto(options.method)),
        seed_(static_cast<uint32_t>(options.seed)),
        watch_speed_(watch_speed) {}
  ~ServerPlanSource() override {
    if (session_ != nullptr) session_->Close().IgnoreError();
  }

  absl::StatusOr<RetainedPlan> InitialPlan(const OccupancyMap& /*known*/,
                                           const PlanOptions& options) override {
    v1::PutMapRequest put;
    *put.mutable_map() = map_;
    ASSIGN_OR_RETURN(v1::PutMapResponse stored, remote_->PutMap(put, absl::Seconds(120)));
    v1::PlanRequest request;
    request.set_map_id(stored.info().map_id());
    v1::RobotModel* robot = request.mutable_robot();
    robot->set_tool_width_m(options.robot.tool_width_m);
    robot->set_max_speed_mps(options.robot.max_speed_mps);
    robot->set_acceleration_mps2(options.robot.acceleration_mps2);
    robot->set_turn_rate_deg_s(options.robot.turn_rate_deg_s);
    request.set_time_limit_s(options.time_limit_s);
    request.set_seed(static_cast<uint32_t>(options.seed));
    request.set_min_free_fraction(options.min_free_fraction);
    ASSIGN_OR_RETURN(v1::PlanResponse planned,
                     remote_->Plan(request, absl::Seconds(options.time_limit_s + 300.0)));
    ASSIGN_OR_RETURN(CoveragePlan plan, PlanFromProto(planned));
    v1::DriveRequest first;
    first.set_plan_id(planned.plan_id());
    first.set_method(method_);
    first.set_seed(seed_);
    first.set_sequence(next_sequence_++);
    ASSIGN_OR_RETURN(session_, remote_->Drive(first, planned.map_id()));
    current_plan_id_ = planned.plan_id();
    started_ = absl::Now();
    RetainedPlan retained;
    retained.plan_id = planned.plan_id();
    retained.map_id = planned.map_id();
    retained.plan = std::move(plan);
    retained.request = options.ToRequest();
    return retained;
  }

  absl::StatusOr<ReplanResult> Replan(const RetainedPlan& /*plan*/, const RobotProgress& at,
                                      const Observations& seen,
                                      const ReplanOptions& options) override {
    if (session_ == nullptr) return absl::FailedPreconditionError("no drive session");
    v1::DriveRequest request;
    request.set_sequence(next_sequence_++);
    request.set_plan_id(current_plan_id_);
    ProgressToProto(at, request.mutable_progress());
    for (const CellIndex& c : seen.cells) {
      v1::CellRef* cell = request.mutable_obstacles()->add_cells();
      cell->set_row(c.row);
      cell->set_col(c.col);
    }
    const v1::ReplanMethod method = ReplanMethodToProto(options.method);
    if (method != method_) request.set_method(method);
    ASSIGN_OR_RETURN(v1::DriveEvent event, session_->Observe(request));
    if (event.has_error()) {
      return absl::Status(static_cast<absl::StatusCode>(event.error().code()),
                          absl::StrCat("server: ", event.error().message()));
    }
    if (!event.has_replan()) return absl::InternalError("the session answered without a plan");
    ReplanResult out;
    ASSIGN_OR_RETURN(out.plan, PlanFromProto(event.replan().plan()));
    out.stats = ReplanStatsFromProto(event.replan().replan());
    for (const v1::CellRef& c : event.replan().unreachable())
      out.unreachable.push_back({c.row(), c.col()});
    current_plan_id_ = event.replan().plan().plan_id();
    return out;
  }

  bool WatchesMoves() const override { return watch_speed_ > 0.0; }

  std::vector<double> ReconnectSeconds() const override {
    return session_ != nullptr ? session_->reconnect_seconds() : std::vector<double>();
  }

  // Paced: the run's clock at watch_speed_ times real time. Like a real
  // robot it reports at a steady 20 Hz, turning in place or driving (a
  // failed report ends nothing: the next replan says).
  void Moved(const RobotProgress& at, double clock_s) override {
    if (session_ == nullptr) return;
    const absl::Time due = started_ + absl::Seconds(clock_s / watch_speed_);
    for (absl::Time now = absl::Now();; now = absl::Now()) {
      if (now >= next_report_) {
        v1::DriveRequest report;
        report.set_sequence(next_sequence_++);
        report.set_plan_id(current_plan_id_);
        ProgressToProto(at, report.mutable_progress());
        session_->Report(report).IgnoreError();
        next_report_ = now + absl::Milliseconds(50);
      }
      if (now >= due) return;
      absl::SleepFor(std::min(due, next_report_) - now);
    }
  }

 private:
  std::unique_ptr<RemotePlanner> remote_;
  const v1::Map map_;
  const v1::ReplanMethod method_;
  const uint32_t seed_;
  const double watch_speed_;  // 0: not watched
  absl::Time started_, next_report_ = absl::InfinitePast();
  std::unique_ptr<RemotePlanner::DriveSession> session_;
  std::string current_plan_id_;
  uint64_t next_sequence_ = 1;
};

}  // namespace

absl::StatusOr<std::unique_ptr<PlanSource>> ConnectServerPlanSource(
    const Connection& server, const std::string& known_map_path, const SimulateRemoteFlags& flags,
    const SimulationOptions& options) {
  MapFileOverrides overrides;
  overrides.resolution = flags.resolution;
  overrides.free_thresh = flags.free_thresh;
  overrides.occupied_thresh = flags.occupied_thresh;
  if (flags.negate) overrides.negate = true;
  ASSIGN_OR_RETURN(v1::Map map, MapProtoFromFile(known_map_path, overrides, EngineLimits()));
  return std::unique_ptr<PlanSource>(new ServerPlanSource(
      RemotePlanner::Connect(server), std::move(map), options, flags.watch_speed));
}

}  // namespace covplan
