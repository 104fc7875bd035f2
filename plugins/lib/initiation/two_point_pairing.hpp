// Purpose: two-point track starts shared by the initiators — a detection no track took pairs with one of the previous scan's within the distance a target can cover (max_speed) plus the measurement errors, pairs chosen jointly by a 2-D assignment; an unpaired detection waits one scan.
#pragma once

#include "assignment/sparse_assignment.hpp"
#include "association/point_grid.hpp"
#include "memory/grow.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/params.hpp>
#include <trackflow/tracker.hpp>

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

namespace trackflow::initiation {

struct PairingSettings {
  double max_speed = 0.0;  // m/s
  double sigmas = 3.0;     // measurement-error margin of the pairing gate, in standard deviations
};

// The two parameters every two-point initiator declares the same way, and their values.
inline std::vector<ParamSpec> pairing_params() {
  return {
      ParamSpec::real("max_speed", dim::velocity, "the fastest a target moves: the pairing gate's reach").req().positive(),
      ParamSpec::real("gate_sigmas", Dimension{}, "measurement-error margin of the pairing gate, in standard deviations")
          .def("3")
          .positive(),
  };
}
inline PairingSettings pairing_settings(const Params& p) { return {p.real("max_speed"), p.real("gate_sigmas")}; }

// The doc sentence of the pairing, for the initiators' declarations.
inline const char* pairing_doc() {
  return "A detection no track took in one scan pairs with one of the previous scan's that no track took, when they "
         "lie within max_speed * (t2 - t1) + gate_sigmas * sqrt(s1^2 + s2^2) of each other (s: root of the trace of "
         "the detection's position covariance); pairs are chosen jointly by a 2-D assignment on their relative "
         "distance. The pair initiates the estimator (its own two-point start, e.g. filter.kalman's differencing) as "
         "a tentative track with two hits. An unpaired detection waits one scan.";
}

// A detection's position in the frame and the standard deviation of its position error (the root
// of the trace of its position covariance: Cartesian R, or J R J' of a spherical or polar one;
// geometry.hpp places a 2-D detection in its plane).
struct Located {
  Vec3 position = Vec3::Zero();
  double sigma = 0.0;
};

inline Located locate(const Measurement& m) {
  Located l;
  l.position = measured_position(m);
  l.sigma = std::sqrt(measured_position_covariance(m, m.covariance).trace());
  return l;
}

// Pairs are chosen jointly: a 2-D assignment of the previous scan's free detections (rows) to this
// scan's (columns) on the distance between them, each row with its own "no pair" column at the
// gate distance, so that a pair is made only inside the gate
//   |p2 - p1| <= max_speed (t2 - t1) + sigmas sqrt(sigma1^2 + sigma2^2).
class TwoPointPairing {
 public:
  explicit TwoPointPairing(PairingSettings s) : s_(s) {}

  void reset() { pending_.clear(); }

  // Appends the pairs of this scan's `unassigned` detections with the previous scan's free ones
  // to `starts`; keeps this scan's unpaired detections for the next.
  void pair(const Scan& scan, std::span<const int> unassigned, std::vector<TrackStart>& starts) {
    current_.clear();
    for (int j : unassigned) {
      Measurement m;
      to_measurement(scan, scan.detections[static_cast<size_t>(j)], m);
      current_.push_back({m, locate(m), j});
    }
    const int rows = static_cast<int>(pending_.size()), m = static_cast<int>(current_.size());
    memory::assign_grown(used_, current_.size(), char{0});
    if (rows > 0 && m > 0) {
      // Pre-gate: the previous detections in a grid over (x, y); each current one looks in the box
      // of its widest possible gate (the largest previous sigma, the earliest previous time), then
      // tests each candidate's own gate exactly. The cell side is the median box width.
      double sigma_max = 0.0, t_min = pending_.front().m.time;
      points_.resize(pending_.size());
      for (std::size_t i = 0; i < pending_.size(); ++i) {
        sigma_max = std::max(sigma_max, pending_[i].where.sigma);
        t_min = std::min(t_min, pending_[i].m.time);
        points_[i] = pending_[i].where.position.head<2>();
      }
      reach_.resize(current_.size());
      for (std::size_t j = 0; j < current_.size(); ++j)
        reach_[j] = s_.max_speed * (current_[j].m.time - t_min) + s_.sigmas * std::hypot(sigma_max, current_[j].where.sigma);
      memory::reserve_grown(widths_, reach_.size());
      widths_.assign(reach_.begin(), reach_.end());
      const auto mid = widths_.begin() + static_cast<std::ptrdiff_t>(widths_.size() / 2);
      std::nth_element(widths_.begin(), mid, widths_.end());
      grid_.build(points_, 2.0 * *mid);
      problem_.clear(rows, m);
      for (int i = 0; i < rows; ++i) problem_.set_none_cost(i, 1.0);
      for (int j = 0; j < m; ++j) {
        const Candidate& b = current_[static_cast<size_t>(j)];
        const Eigen::Vector2d half = Eigen::Vector2d::Constant(reach_[static_cast<size_t>(j)]);
        const Eigen::Vector2d centre = b.where.position.head<2>();
        grid_.for_each_candidate(centre - half, centre + half, [&](int i) {
          const Candidate& a = pending_[static_cast<size_t>(i)];
          const double T = b.m.time - a.m.time;
          const double gate = s_.max_speed * T + s_.sigmas * std::hypot(a.where.sigma, b.where.sigma);
          const double d = (b.where.position - a.where.position).norm();
          if (T > 0.0 && d <= gate) problem_.add(i, j, d / gate);  // relative: a pair at the gate's edge costs the "no pair" 1
        });
      }
      const std::span<const int> col = problem_.solve();
      for (int i = 0; i < rows; ++i) {
        const int c = col[static_cast<size_t>(i)];
        if (c < 0) continue;
        TrackStart st;
        st.first = pending_[static_cast<size_t>(i)].m;
        st.second = current_[static_cast<size_t>(c)].detection;
        starts.push_back(st);
        used_[static_cast<size_t>(c)] = 1;
      }
    }
    // What did not pair waits one scan for a partner.
    pending_.clear();
    for (size_t j = 0; j < current_.size(); ++j)
      if (!used_[j]) pending_.push_back(current_[j]);
  }

 private:
  struct Candidate {
    Measurement m;
    Located where;
    int detection = -1;
  };
  PairingSettings s_;
  std::vector<Candidate> pending_, current_;
  std::vector<char> used_;
  std::vector<Eigen::Vector2d> points_;
  std::vector<double> reach_, widths_;
  association::PointGrid grid_;
  assignment::SparseAssignment problem_;
};

}  // namespace trackflow::initiation
