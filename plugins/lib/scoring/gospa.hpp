// Purpose: GOSPA (and OSPA) between truth and track positions, by optimal assignment on cut-off distances.
#pragma once

#include "assignment/sparse_assignment.hpp"
#include "memory/grow.hpp"

#include <Eigen/Core>

#include <cmath>
#include <cstddef>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace trackflow::metrics {

// For alpha = 2 only: the p-th power of GOSPA split into what the paper calls
// localisation error of properly detected targets, and the costs of missed and false targets.
// localisation + missed + false == GospaResult::gospa_pow_p (up to rounding).
struct GospaDecomposition {
  double localisation = 0.0;  // sum of d(x, y)^p over truth-track pairs closer than c
  double missed = 0.0;        // c^p / 2 per truth without such a track
  double false_tracks = 0.0;  // c^p / 2 per track without such a truth
  int detected = 0;           // pairs closer than c
  int missed_count = 0;
  int false_count = 0;
};

struct GospaResult {
  double gospa = 0.0;        // d_p^(c, alpha)(X, Y)
  double gospa_pow_p = 0.0;  // the same before the 1/p root: what sums and averages over time
  double ospa = 0.0;         // d_p^(c)(X, Y) of Schuhmacher, Vo and Vo (0 for two empty sets)
  // OSPA's p-th power in its two terms, both divided by n = max(|X|, |Y|) (0 for two empty sets):
  // localisation (1/n) min_pi sum d^(c)^p and cardinality (1/n) c^p (n - m). Their sum is ospa^p
  // up to rounding; the paper's components e_loc and e_card are their p-th roots.
  double ospa_localisation = 0.0;
  double ospa_cardinality = 0.0;
  std::optional<GospaDecomposition> decomposition;  // alpha == 2 only
  // Per truth: its track (a pair closer than c), or -1. Views the Gospa object's storage, valid
  // until its next evaluate() or reserve().
  std::span<const int> track_for_truth;
};

// GOSPA of A. S. Rahmathullah, A. F. Garcia-Fernandez and L. Svensson, "Generalized optimal
// sub-pattern assignment metric", FUSION 2017 (arXiv:1601.05585; equation numbers of arXiv v7,
// not yet checked against the PDF: docs/assignment.md).
// X: truth positions, Y: track positions, d(x, y) the Euclidean distance, d^(c) = min(d, c).
//
//   Definition 1, Eq. (1), |X| <= |Y|:
//     d_p^(c,alpha)(X, Y) = ( min_pi sum_{i=1}^{|X|} d^(c)(x_i, y_pi(i))^p + c^p / alpha (|Y| - |X|) )^(1/p)
//   over injections pi of X into Y (for |X| > |Y| the roles swap: the metric is symmetric).
//   Proposition 1, Eq. (2), alpha = 2, over partial assignments gamma of X and Y:
//     d_p^(c,2)(X, Y) = ( min_gamma sum_{(i,j) in gamma} d(x_i, y_j)^p + c^p / 2 (|X| + |Y| - 2 |gamma|) )^(1/p)
//   whose optimal gamma holds the pairs of an optimal pi closer than c: each pair at or beyond c
//   costs c^p either way, as a clipped pair or as one missed plus one false target.
//
// OSPA of D. Schuhmacher, B.-T. Vo and B.-N. Vo, "A consistent metric for performance evaluation
// of multi-object filters", IEEE Trans. Signal Processing 56(8), 2008, m <= n:
//     d_p^(c)(X, Y) = ( (min_pi sum_{i=1}^m d^(c)(x_i, y_pi(i))^p + c^p (n - m)) / n )^(1/p)
// The minimising pi is the one GOSPA's Eq. (1) needs (the penalty term does not depend on pi),
// so one assignment gives both.
//
// The optimal pi comes from the clustered sparse assignment over the pairs closer than c
// (evaluate() says how; equal to the linear assignment of the |X| x |Y| matrix of d^(c)(x_i, y_j)^p,
// which the brute-force tests check). Cut-off, order and alpha are checked once (c > 0, 1 <= p, 0 < alpha <= 2,
// all finite); non-finite positions are refused with std::invalid_argument. After reserve() an
// evaluate() of sets no larger allocates nothing.
class Gospa {
 public:
  Gospa(double cutoff, double order, double alpha = 2.0) : cutoff_(cutoff), order_(order), alpha_(alpha) {
    if (!(std::isfinite(cutoff) && cutoff > 0.0))
      throw std::invalid_argument("gospa: cut-off c must be finite and > 0, not " + std::to_string(cutoff));
    if (!(std::isfinite(order) && order >= 1.0))
      throw std::invalid_argument("gospa: order p must be finite and >= 1, not " + std::to_string(order));
    if (!(alpha > 0.0 && alpha <= 2.0))
      throw std::invalid_argument("gospa: alpha must be in (0, 2], not " + std::to_string(alpha));
    cutoff_pow_p_ = clipped_pow(cutoff_);  // as the matrix entries are computed: c^p bit for bit
  }

  void reserve(int truths, int tracks) {
    problem_.clear(truths, tracks);
    track_for_truth_.reserve(static_cast<std::size_t>(truths));
  }

  double cutoff() const { return cutoff_; }
  double order() const { return order_; }
  double alpha() const { return alpha_; }

  // 2-D or 3-D positions (Eigen::Vector2d, Eigen::Vector3d).
  template <int Dim>
    requires(Dim == 2 || Dim == 3)
  GospaResult evaluate(std::span<const Eigen::Matrix<double, Dim, 1>> truth,
                       std::span<const Eigen::Matrix<double, Dim, 1>> tracks) {
    check_finite(truth, "truth");
    check_finite(tracks, "track");
    const int nx = static_cast<int>(truth.size());
    const int ny = static_cast<int>(tracks.size());

    // The optimal injection pi of Eq. (1) pairs some elements closer than c and leaves the rest at
    // the clipped cost c^p, so it is found as a partial assignment gamma over the pairs closer than
    // c, each priced d^p - c^p (what it saves against c^p), every truth with "no track" at 0:
    //   min_pi sum min(d, c)^p = c^p min(|X|, |Y|) + min_gamma sum_gamma (d^p - c^p).
    // Only pairs closer than c enter, and the problem splits into clusters (sparse_assignment.hpp).
    // The totals are then summed from the chosen pairs themselves (no cancellation against c^p).
    problem_.clear(nx, ny);
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < ny; ++j) {
        const double d = (truth[static_cast<std::size_t>(i)] - tracks[static_cast<std::size_t>(j)]).norm();
        if (d < cutoff_) {
          const double dp = clipped_pow(d);
          if (dp < cutoff_pow_p_) problem_.add(i, j, dp - cutoff_pow_p_);
        }
      }
    const std::span<const int> chosen = problem_.solve();

    memory::assign_grown(track_for_truth_, static_cast<std::size_t>(nx), -1);
    GospaDecomposition parts;
    for (int i = 0; i < nx; ++i) {
      const int j = chosen[static_cast<std::size_t>(i)];
      if (j < 0) continue;
      track_for_truth_[static_cast<std::size_t>(i)] = j;
      parts.localisation +=
          clipped_pow((truth[static_cast<std::size_t>(i)] - tracks[static_cast<std::size_t>(j)]).norm());
      ++parts.detected;
    }
    const int smaller = nx < ny ? nx : ny;
    const double assignment_cost = parts.localisation + cutoff_pow_p_ * (smaller - parts.detected);

    // Eq. (1): the assignment's cost plus c^p / alpha per element of the larger set left over.
    const int unmatched = nx > ny ? nx - ny : ny - nx;
    const int larger = nx > ny ? nx : ny;
    GospaResult r;
    r.gospa_pow_p = assignment_cost + cutoff_pow_p_ / alpha_ * unmatched;
    r.gospa = root_p(r.gospa_pow_p);
    r.ospa = larger == 0 ? 0.0 : root_p((assignment_cost + cutoff_pow_p_ * unmatched) / larger);
    if (larger) {
      r.ospa_localisation = assignment_cost / larger;
      r.ospa_cardinality = cutoff_pow_p_ * unmatched / larger;
    }

    // Proposition 1: the pairs of gamma are those closer than c; every other truth is missed and
    // every other track false (c^p / 2 each: a clipped pair's c^p split in two).
    if (alpha_ == 2.0) {
      parts.missed_count = nx - parts.detected;
      parts.false_count = ny - parts.detected;
      parts.missed = cutoff_pow_p_ / 2.0 * parts.missed_count;
      parts.false_tracks = cutoff_pow_p_ / 2.0 * parts.false_count;
      r.decomposition = parts;
    }
    r.track_for_truth = track_for_truth_;
    return r;
  }

  // Convenience for containers of positions (std::vector<Eigen::Vector3d>, ...).
  template <typename Positions>
  GospaResult evaluate(const Positions& truth, const Positions& tracks) {
    using Point = typename Positions::value_type;
    return evaluate<Point::RowsAtCompileTime>(std::span<const Point>(truth.data(), truth.size()),
                                              std::span<const Point>(tracks.data(), tracks.size()));
  }

 private:
  // d^(c)^p, with p = 1 and p = 2 done without pow so that the common orders are exact to the
  // last bit of the distance.
  double clipped_pow(double d) const {
    const double clipped = d < cutoff_ ? d : cutoff_;
    if (order_ == 1.0) return clipped;
    if (order_ == 2.0) return clipped * clipped;
    return std::pow(clipped, order_);
  }
  double root_p(double x) const {
    if (order_ == 1.0) return x;
    if (order_ == 2.0) return std::sqrt(x);
    return std::pow(x, 1.0 / order_);
  }

  template <int Dim>
  static void check_finite(std::span<const Eigen::Matrix<double, Dim, 1>> points, const char* what) {
    for (std::size_t k = 0; k < points.size(); ++k)
      if (!points[k].allFinite())
        throw std::invalid_argument(std::string("gospa: ") + what + " position " + std::to_string(k) +
                                    " is not finite");
  }

  double cutoff_;
  double order_;
  double alpha_;
  double cutoff_pow_p_ = 0.0;
  assignment::SparseAssignment problem_;
  std::vector<int> track_for_truth_;
};

}  // namespace trackflow::metrics
