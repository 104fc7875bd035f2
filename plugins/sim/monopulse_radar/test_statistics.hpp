// Purpose: test helpers: sample moments, lag-k autocorrelation, and a batch-means standard error for correlated or heavy-tailed samples.
#pragma once

#include <cmath>
#include <cstddef>
#include <functional>
#include <vector>

namespace trackflow::test_stats {

inline double mean(const std::vector<double>& x) {
  double s = 0;
  for (double v : x) s += v;
  return s / static_cast<double>(x.size());
}

inline double variance(const std::vector<double>& x) {
  const double m = mean(x);
  double s = 0;
  for (double v : x) s += (v - m) * (v - m);
  return s / static_cast<double>(x.size() - 1);
}

// Sample autocorrelation at lag k (the usual biased estimator, bias O(1/n)).
inline double autocorrelation(const std::vector<double>& x, std::size_t k) {
  const double m = mean(x);
  double c0 = 0, ck = 0;
  for (std::size_t i = 0; i < x.size(); ++i) c0 += (x[i] - m) * (x[i] - m);
  for (std::size_t i = k; i < x.size(); ++i) ck += (x[i] - m) * (x[i - k] - m);
  return ck / c0;
}

// A statistic evaluated on `batches` consecutive batches of x: its mean and the standard error of that
// mean from the batches' spread. Valid for correlated samples when a batch is much longer than the
// correlation time, and makes no assumption about the distribution's tails.
struct BatchEstimate {
  double value = 0, standard_error = 0;
};
inline BatchEstimate batch_means(const std::vector<double>& x, int batches,
                                 const std::function<double(const std::vector<double>&)>& statistic) {
  const std::size_t n = x.size() / static_cast<std::size_t>(batches);
  std::vector<double> values;
  for (int b = 0; b < batches; ++b)
    values.push_back(statistic(std::vector<double>(x.begin() + static_cast<long>(b * n), x.begin() + static_cast<long>((b + 1) * n))));
  return {mean(values), std::sqrt(variance(values) / batches)};
}

}  // namespace trackflow::test_stats
