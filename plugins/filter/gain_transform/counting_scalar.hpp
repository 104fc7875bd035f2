// Purpose: a double that counts its multiplications, divisions, additions and function calls, usable as an Eigen scalar (test and benchmark only).
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <cstdint>

namespace trackflow::gain_transform {

struct OperationCount {
  std::int64_t mul = 0, div = 0, add = 0, func = 0;  // func: sqrt, hypot, atan2, exp, ...
  OperationCount operator-(const OperationCount& o) const { return {mul - o.mul, div - o.div, add - o.add, func - o.func}; }
};

// One global tally: the code under count runs single-threaded in the test and the benchmark.
inline OperationCount& operation_count() {
  static OperationCount c;
  return c;
}

// Arithmetic on the wrapped double with the same results as double; every +, -, *, / and every
// math function call is counted (negation and comparisons are not: they cost no multiplier).
struct Counted {
  double v = 0.0;
  Counted() = default;
  Counted(double x) : v(x) {}  // NOLINT: implicit, as a scalar literal
  explicit operator double() const { return v; }

  friend Counted operator*(Counted a, Counted b) { ++operation_count().mul; return a.v * b.v; }
  friend Counted operator/(Counted a, Counted b) { ++operation_count().div; return a.v / b.v; }
  friend Counted operator+(Counted a, Counted b) { ++operation_count().add; return a.v + b.v; }
  friend Counted operator-(Counted a, Counted b) { ++operation_count().add; return a.v - b.v; }
  friend Counted operator-(Counted a) { return -a.v; }
  Counted& operator*=(Counted b) { return *this = *this * b; }
  Counted& operator/=(Counted b) { return *this = *this / b; }
  Counted& operator+=(Counted b) { return *this = *this + b; }
  Counted& operator-=(Counted b) { return *this = *this - b; }
  friend bool operator<(Counted a, Counted b) { return a.v < b.v; }
  friend bool operator>(Counted a, Counted b) { return a.v > b.v; }
  friend bool operator<=(Counted a, Counted b) { return a.v <= b.v; }
  friend bool operator>=(Counted a, Counted b) { return a.v >= b.v; }
  friend bool operator==(Counted a, Counted b) { return a.v == b.v; }
  friend bool operator!=(Counted a, Counted b) { return a.v != b.v; }
};

inline Counted sqrt(Counted a) { ++operation_count().func; return std::sqrt(a.v); }
inline Counted hypot(Counted a, Counted b) { ++operation_count().func; return std::hypot(a.v, b.v); }
inline Counted atan2(Counted a, Counted b) { ++operation_count().func; return std::atan2(a.v, b.v); }
inline Counted exp(Counted a) { ++operation_count().func; return std::exp(a.v); }
inline Counted abs(Counted a) { return std::abs(a.v); }
inline bool isfinite(Counted a) { return std::isfinite(a.v); }
inline bool isnan(Counted a) { return std::isnan(a.v); }
inline bool isinf(Counted a) { return std::isinf(a.v); }

}  // namespace trackflow::gain_transform

namespace Eigen {
template <>
struct NumTraits<trackflow::gain_transform::Counted> : NumTraits<double> {
  using Real = trackflow::gain_transform::Counted;
  using NonInteger = trackflow::gain_transform::Counted;
  using Nested = trackflow::gain_transform::Counted;
  using Literal = trackflow::gain_transform::Counted;
  enum { IsComplex = 0, IsInteger = 0, IsSigned = 1, RequireInitialization = 1, ReadCost = 1, AddCost = 1, MulCost = 1 };
};
}  // namespace Eigen
