#include "planner/lp/glpk_problem.h"

#include <glpk.h>

#include <cmath>

#include "absl/strings/str_format.h"
#include "absl/time/clock.h"

namespace covplan {
namespace {

thread_local int live_problems = 0;

glp_prob* P(void* p) { return static_cast<glp_prob*>(p); }

int BoundType(double lo, double up) {
  const bool has_lo = std::isfinite(lo), has_up = std::isfinite(up);
  if (has_lo && has_up) return lo == up ? GLP_FX : GLP_DB;
  if (has_lo) return GLP_LO;
  if (has_up) return GLP_UP;
  return GLP_FR;
}

absl::Status SimplexStatus(int rc) {
  switch (rc) {
    case 0:
      return absl::OkStatus();
    case GLP_ETMLIM:
      return absl::DeadlineExceededError("GLPK simplex hit its time limit");
    case GLP_EITLIM:
      return absl::DeadlineExceededError("GLPK simplex hit its iteration limit");
    case GLP_ENOPFS:
      return absl::FailedPreconditionError("LP has no primal feasible solution");
    case GLP_ENODFS:
      return absl::FailedPreconditionError("LP has no dual feasible solution (unbounded)");
    case GLP_EBADB:
      return absl::InternalError("GLPK: invalid initial basis");
    case GLP_ESING:
      return absl::InternalError("GLPK: singular basis matrix");
    case GLP_ECOND:
      return absl::InternalError("GLPK: ill-conditioned basis matrix");
    case GLP_EBOUND:
      return absl::InternalError("GLPK: incorrect double bounds");
    case GLP_EFAIL:
      return absl::InternalError("GLPK: solver failure");
    case GLP_EOBJLL:
      return absl::InternalError("GLPK: objective below lower limit");
    case GLP_EOBJUL:
      return absl::InternalError("GLPK: objective above upper limit");
    default:
      return absl::InternalError(absl::StrFormat("GLPK simplex returned code %d", rc));
  }
}

absl::Status IntoptStatus(int rc) {
  switch (rc) {
    case 0:
      return absl::OkStatus();
    case GLP_ETMLIM:
      return absl::DeadlineExceededError("GLPK branch-and-bound hit its time limit");
    case GLP_ENOPFS:
      return absl::FailedPreconditionError("MIP has no primal feasible solution");
    case GLP_ENODFS:
      return absl::FailedPreconditionError("MIP relaxation has no dual feasible solution");
    case GLP_EROOT:
      return absl::InternalError("GLPK: optimal basis for the relaxation not provided");
    case GLP_EBOUND:
      return absl::InternalError("GLPK: incorrect bounds on integer columns");
    case GLP_EFAIL:
      return absl::InternalError("GLPK: MIP solver failure");
    case GLP_EMIPGAP:
      return absl::OkStatus();  // relative gap reached: solution is usable
    case GLP_ESTOP:
      return absl::CancelledError("GLPK branch-and-bound stopped");
    default:
      return absl::InternalError(absl::StrFormat("GLPK intopt returned code %d", rc));
  }
}

int TimeLimitMs(double seconds) {
  if (!(seconds > 0)) return 1;
  return seconds > 2.0e6 ? 2'000'000'000 : static_cast<int>(seconds * 1000.0);
}

}  // namespace

LinearProgram::LinearProgram() {
  ++live_problems;
  glp_term_out(GLP_OFF);
  prob_ = glp_create_prob();
  glp_set_obj_dir(P(prob_), GLP_MIN);
  ia_.push_back(0), ja_.push_back(0), ar_.push_back(0.0);
}

LinearProgram::~LinearProgram() {
  glp_delete_prob(P(prob_));
  // GLPK's environment is per thread; free it with the thread's last problem
  // so pool threads do not accumulate it.
  if (--live_problems == 0) glp_free_env();
}

int LinearProgram::AddColumn(double lower, double upper, double objective, bool integer) {
  const int j = glp_add_cols(P(prob_), 1);
  glp_set_col_bnds(P(prob_), j, BoundType(lower, upper), std::isfinite(lower) ? lower : 0.0,
                   std::isfinite(upper) ? upper : 0.0);
  glp_set_obj_coef(P(prob_), j, objective);
  if (integer) glp_set_col_kind(P(prob_), j, GLP_IV);
  integer_.push_back(integer);
  return num_cols_++;
}

void LinearProgram::AddRow(double lower, double upper,
                           const std::vector<std::pair<int, double>>& terms) {
  row_lower_.push_back(lower);
  row_upper_.push_back(upper);
  const int row = static_cast<int>(row_lower_.size());
  for (const auto& [col, coeff] : terms) {
    ia_.push_back(row);
    ja_.push_back(col + 1);
    ar_.push_back(coeff);
  }
}

absl::StatusOr<LpSolution> LinearProgram::Solve(const LpSolveOptions& options) {
  glp_term_out(GLP_OFF);
  glp_prob* lp = P(prob_);
  const int existing = glp_get_num_rows(lp);
  const int new_rows = num_rows() - existing;
  if (new_rows > 0) {
    glp_add_rows(lp, new_rows);
    for (int i = existing; i < num_rows(); ++i) {
      glp_set_row_bnds(lp, i + 1, BoundType(row_lower_[i], row_upper_[i]),
                       std::isfinite(row_lower_[i]) ? row_lower_[i] : 0.0,
                       std::isfinite(row_upper_[i]) ? row_upper_[i] : 0.0);
    }
    glp_load_matrix(lp, static_cast<int>(ia_.size()) - 1, ia_.data(), ja_.data(), ar_.data());
  }
  glp_smcp smcp;
  glp_init_smcp(&smcp);
  smcp.msg_lev = GLP_MSG_OFF;
  smcp.presolve = options.presolve ? GLP_ON : GLP_OFF;
  smcp.tm_lim = TimeLimitMs(options.time_limit_s);
  const absl::Time start = absl::Now();
  absl::Status st = SimplexStatus(glp_simplex(lp, &smcp));
  if (!st.ok()) return st;
  const int status = glp_get_status(lp);
  if (status == GLP_NOFEAS || status == GLP_INFEAS)
    return absl::FailedPreconditionError("LP is infeasible");
  if (status == GLP_UNBND) return absl::FailedPreconditionError("LP is unbounded");
  if (status != GLP_OPT) return absl::InternalError(absl::StrFormat("GLPK LP status %d", status));

  LpSolution sol;
  sol.values.resize(num_cols_);
  sol.integral = true;
  for (int j = 0; j < num_cols_; ++j) {
    sol.values[j] = glp_get_col_prim(lp, j + 1);
    if (integer_[j] && std::abs(sol.values[j] - std::round(sol.values[j])) > 1e-6)
      sol.integral = false;
  }
  sol.objective = glp_get_obj_val(lp);
  if (!options.integer || sol.integral) return sol;

  // Fractional relaxation: branch and bound from the optimal basis.
  glp_iocp iocp;
  glp_init_iocp(&iocp);
  iocp.msg_lev = GLP_MSG_OFF;
  const double used = absl::ToDoubleSeconds(absl::Now() - start);
  iocp.tm_lim = TimeLimitMs(options.time_limit_s - used);
  st = IntoptStatus(glp_intopt(lp, &iocp));
  if (!st.ok()) return st;
  const int mip_status = glp_mip_status(lp);
  if (mip_status != GLP_OPT && mip_status != GLP_FEAS) {
    return absl::FailedPreconditionError("MIP has no integer feasible solution");
  }
  for (int j = 0; j < num_cols_; ++j) sol.values[j] = glp_mip_col_val(lp, j + 1);
  sol.objective = glp_mip_obj_val(lp);
  sol.integral = true;
  return sol;
}

}  // namespace covplan
