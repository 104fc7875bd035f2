// Purpose: per-interval, per-source sums of azimuth and elevation errors (count, sum, sum of squares) and the ensemble RMS and mean they give.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace trackflow::angles {

struct Interval {
  double start = 0.0, end = 0.0;  // s; holds start <= t < end
  bool contains(double t) const { return t >= start && t < end; }
};

struct ErrorSums {
  std::uint64_t n = 0;
  double az = 0.0, az2 = 0.0, el = 0.0, el2 = 0.0;  // rad, rad^2

  void add(double e_az, double e_el) {
    ++n;
    az += e_az;
    az2 += e_az * e_az;
    el += e_el;
    el2 += e_el * e_el;
  }
  void add(const ErrorSums& o) {
    n += o.n;
    az += o.az;
    az2 += o.az2;
    el += o.el;
    el2 += o.el2;
  }
  // Ensemble statistics over all samples of all runs in the interval (NaN without samples).
  double az_rms() const { return n ? std::sqrt(az2 / static_cast<double>(n)) : nan(); }
  double az_mean() const { return n ? az / static_cast<double>(n) : nan(); }
  double el_rms() const { return n ? std::sqrt(el2 / static_cast<double>(n)) : nan(); }
  double el_mean() const { return n ? el / static_cast<double>(n) : nan(); }

 private:
  static double nan() { return std::numeric_limits<double>::quiet_NaN(); }
};

// sums[interval * sources + source]: a flat table, added in run order.
class IntervalTable {
 public:
  IntervalTable() = default;
  IntervalTable(std::size_t intervals, std::size_t sources) : sources_(sources), sums_(intervals * sources) {}
  ErrorSums& at(std::size_t interval, std::size_t source) { return sums_[interval * sources_ + source]; }
  const ErrorSums& at(std::size_t interval, std::size_t source) const { return sums_[interval * sources_ + source]; }
  void add(const IntervalTable& o) {
    for (std::size_t i = 0; i < sums_.size() && i < o.sums_.size(); ++i) sums_[i].add(o.sums_[i]);
  }
  void clear() {
    for (auto& s : sums_) s = ErrorSums{};
  }
  // The flat table itself, for sending a run's table between processes (mpirun).
  std::vector<ErrorSums>& sums() { return sums_; }
  const std::vector<ErrorSums>& sums() const { return sums_; }

 private:
  std::size_t sources_ = 0;
  std::vector<ErrorSums> sums_;
};

}  // namespace trackflow::angles
