// The runtime estimator of Algorithm 1: f(m), the seconds a replan with m new
// ranks takes (rank ILP + transitions + the tour search it needs to reach a
// good tour), learned online from the replans actually run. The thesis kept f
// fixed and stalled at 20 % clutter; this one refits after every solve.
//
//   ReplanEstimator est;                       // a prior until samples arrive
//   int64_t m_bar = est.Budget(time_to_obstacle_s);
//   ... replan ...
//   est.Record(new_ranks, seconds);
//   std::string saved = est.Serialize();       // kept across restarts
//
// Model: f(m) = a + b·m + c·m³ (non-negative coefficients), least squares
// over the most recent samples (Eigen), falling back to the prior while
// fewer than kMinSamples exist.
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_PLANNER_REPLAN_ESTIMATOR_H_
#define COVPLAN_PLANNER_REPLAN_ESTIMATOR_H_

#include <cstdint>
#include <deque>
#include <string>

#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"

namespace covplan {

class ReplanEstimator {
 public:
  struct Coefficients {
    double a = 0.01;   // s
    double b = 0.002;  // s per new rank
    double c = 1e-7;   // s per new rank^3
  };
  static constexpr int kMinSamples = 5;
  static constexpr int kMaxSamples = 512;

  ReplanEstimator() = default;

  // Predicted seconds for m new ranks.
  double Predict(int64_t m) const;
  // The largest m with Predict(m) <= seconds (0 when even m = 0 does not fit
  // is reported as -1: no replan possible).
  int64_t Budget(double seconds) const;
  void Record(int64_t new_ranks, double seconds);
  Coefficients coefficients() const;
  int64_t num_samples() const;

  // Text form (samples) for persistence; Parse replaces the samples.
  std::string Serialize() const;
  absl::Status Parse(const std::string& text);

 private:
  void Refit() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);
  mutable absl::Mutex mu_;
  std::deque<std::pair<int64_t, double>> samples_ ABSL_GUARDED_BY(mu_);
  Coefficients coef_ ABSL_GUARDED_BY(mu_);
};

}  // namespace covplan

#endif  // COVPLAN_PLANNER_REPLAN_ESTIMATOR_H_
