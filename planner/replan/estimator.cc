#include "planner/replan/estimator.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "Eigen/Dense"
#include "absl/strings/str_format.h"

namespace covplan {

double ReplanEstimator::Predict(int64_t m) const {
  absl::MutexLock lock(&mu_);
  const double x = static_cast<double>(std::max<int64_t>(0, m));
  return coef_.a + coef_.b * x + coef_.c * x * x * x;
}

int64_t ReplanEstimator::Budget(double seconds) const {
  Coefficients k = coefficients();
  if (!(seconds >= k.a)) return -1;
  // f is increasing in m: bisect on [0, hi].
  int64_t lo = 0, hi = 1;
  auto f = [&](int64_t m) {
    const double x = static_cast<double>(m);
    return k.a + k.b * x + k.c * x * x * x;
  };
  while (hi < (int64_t{1} << 40) && f(hi) <= seconds) hi *= 2;
  while (lo + 1 < hi) {
    const int64_t mid = lo + (hi - lo) / 2;
    (f(mid) <= seconds ? lo : hi) = mid;
  }
  return lo;
}

void ReplanEstimator::Record(int64_t new_ranks, double seconds) {
  if (new_ranks < 0 || !std::isfinite(seconds) || seconds < 0) return;
  absl::MutexLock lock(&mu_);
  samples_.emplace_back(new_ranks, seconds);
  while (samples_.size() > static_cast<size_t>(kMaxSamples)) samples_.pop_front();
  Refit();
}

void ReplanEstimator::Refit() {
  if (samples_.size() < static_cast<size_t>(kMinSamples)) return;
  // The slope terms need at least two distinct rank counts; otherwise keep
  // the prior's slope and fit only the constant (as a bound, like below).
  bool distinct = false;
  for (const auto& sample : samples_) distinct = distinct || sample.first != samples_.front().first;
  if (!distinct) {
    const Coefficients prior;
    std::vector<double> residuals;
    for (const auto& [m, sec] : samples_) {
      const double x = static_cast<double>(m);
      residuals.push_back(sec - prior.b * x - prior.c * x * x * x);
    }
    const size_t q = residuals.size() * 9 / 10;
    std::nth_element(residuals.begin(), residuals.begin() + q, residuals.end());
    coef_ = Coefficients{std::max(0.0, residuals[q]), prior.b, prior.c};
    return;
  }
  // Least squares on (1, m, m^3); a negative coefficient is dropped and the
  // rest refitted, so f stays non-negative and increasing.
  bool use[3] = {true, true, true};
  for (int round = 0; round < 3; ++round) {
    const int k = use[0] + use[1] + use[2];
    Eigen::MatrixXd A(samples_.size(), k);
    Eigen::VectorXd y(samples_.size());
    for (size_t i = 0; i < samples_.size(); ++i) {
      const double x = static_cast<double>(samples_[i].first);
      const double col[3] = {1.0, x, x * x * x};
      int j = 0;
      for (int t = 0; t < 3; ++t) {
        if (use[t]) A(i, j++) = col[t];
      }
      y(i) = samples_[i].second;
    }
    const Eigen::VectorXd sol = A.colPivHouseholderQr().solve(y);
    double out[3] = {0, 0, 0};
    int j = 0;
    bool negative = false;
    for (int t = 0; t < 3; ++t) {
      if (!use[t]) continue;
      out[t] = sol(j++);
      if (!(out[t] >= 0.0)) use[t] = false, negative = true;
    }
    if (!negative && (out[1] > 0.0 || out[2] > 0.0)) {
      // Headroom: the fit is of the mean, a budget needs a bound; lift the
      // curve by the 90th percentile of the residuals.
      std::vector<double> residuals;
      for (const auto& [m, s] : samples_) {
        const double x = static_cast<double>(m);
        residuals.push_back(s - (out[0] + out[1] * x + out[2] * x * x * x));
      }
      const size_t q = residuals.size() * 9 / 10;
      std::nth_element(residuals.begin(), residuals.begin() + q, residuals.end());
      coef_.a = out[0] + std::max(0.0, residuals[q]);
      coef_.b = out[1];
      coef_.c = out[2];
      return;
    }
    if (!negative) use[1] = use[2] = false;  // flat fit: retry below with the prior's slope
    if (!use[1] && !use[2]) break;
  }
  // No increasing fit: keep the prior's slope, lift the constant to bound the samples.
  const Coefficients prior;
  double worst = 0.0;
  for (const auto& [m, sec] : samples_) {
    const double x = static_cast<double>(m);
    worst = std::max(worst, sec - prior.b * x - prior.c * x * x * x);
  }
  coef_ = Coefficients{worst, prior.b, prior.c};
}

ReplanEstimator::Coefficients ReplanEstimator::coefficients() const {
  absl::MutexLock lock(&mu_);
  return coef_;
}

int64_t ReplanEstimator::num_samples() const {
  absl::MutexLock lock(&mu_);
  return static_cast<int64_t>(samples_.size());
}

std::string ReplanEstimator::Serialize() const {
  absl::MutexLock lock(&mu_);
  std::string out = "covplan.replan_estimator.v1\n";
  for (const auto& [m, s] : samples_) absl::StrAppendFormat(&out, "%d %.9g\n", m, s);
  return out;
}

absl::Status ReplanEstimator::Parse(const std::string& text) {
  std::istringstream in(text);
  std::string header;
  std::getline(in, header);
  if (header != "covplan.replan_estimator.v1") {
    return absl::InvalidArgumentError("replan estimator file: unknown header");
  }
  std::deque<std::pair<int64_t, double>> samples;
  int64_t m = 0;
  double s = 0;
  while (in >> m >> s) {
    if (m < 0 || !std::isfinite(s) || s < 0) {
      return absl::InvalidArgumentError("replan estimator file: bad sample");
    }
    samples.emplace_back(m, s);
  }
  if (!in.eof()) return absl::InvalidArgumentError("replan estimator file: trailing garbage");
  absl::MutexLock lock(&mu_);
  samples_ = std::move(samples);
  while (samples_.size() > static_cast<size_t>(kMaxSamples)) samples_.pop_front();
  coef_ = Coefficients();
  Refit();
  return absl::OkStatus();
}

}  // namespace covplan
