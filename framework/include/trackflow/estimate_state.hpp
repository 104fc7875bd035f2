// Purpose: publish a filter's fixed-size state and covariance into an Estimate, with its ENU [x y z vx vy vz] view picked out through an index map.
#pragma once

#include <trackflow/items.hpp>

#include <Eigen/Core>

namespace trackflow {

// For filters whose state holds the ENU position and velocity as plain entries (Cartesian
// Kalman-type filters): Estimate::state / covariance get x and P as they are, and enu /
// enu_covariance the entries at enu_index = the state indices of [x y z vx vy vz]. Fixed-size,
// no allocation (StateVec / StateCov have fixed capacity): called once per estimate.
template <int N>
inline void set_estimate_state(Estimate& e, const Eigen::Matrix<double, N, 1>& x, const Eigen::Matrix<double, N, N>& P,
                               const int (&enu_index)[6]) {
  e.state.resize(N);
  e.state.template head<N>() = x;
  e.covariance.resize(N, N);
  e.covariance.template topLeftCorner<N, N>() = P;
  for (int i = 0; i < 6; ++i) {
    e.enu(i) = x(enu_index[i]);
    for (int j = 0; j < 6; ++j) e.enu_covariance(i, j) = P(enu_index[i], enu_index[j]);
  }
}

}  // namespace trackflow
