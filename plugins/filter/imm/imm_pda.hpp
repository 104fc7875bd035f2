// Purpose: the IMM's arithmetic under probabilistic data association (IMM-PDA, IMM-JPDA): the joint (candidate, mode) weights from track-level association probabilities, and the per-mode moment-matched combination of the mode-matched updates.
#pragma once

#include "imm_mixing.hpp"

#include <Eigen/Core>

#include <cmath>

namespace trackflow::imm {

// The IMM-PDA filter (Houles & Bar-Shalom 1989, "Multisensor tracking of a maneuvering target in
// clutter", IEEE Trans. AES 25(2); the IMMPDAF of Bar-Shalom, Willett & Tian 2011, "Tracking and
// Data Fusion", and Mazor, Averbuch, Bar-Shalom & Dayan 1998, IEEE Trans. AES 34(1), sec. on
// IMM-PDAF) with the association probabilities given at track level (beta_k for candidate z_k,
// beta_0 for none; from assoc.pda, or a JPDA's marginals as in the IMM-JPDA of Blom & Bloem 2000,
// "Probabilistic data association avoiding track coalescence", IEEE Trans. AC 45(2), and their
// "Joint IMMPDA particle filter", Fusion 2003):
// with c_j the predicted mode probabilities and g_jk = N(z_k; z^_j, S_j) mode j's likelihood of z_k,
//   w_jk = beta_k c_j g_jk / sum_i c_i g_ik,   w_j0 = beta_0 c_j,   mu_j = w_j0 + sum_k w_jk,
// and mode j's posterior is the mixture of its prediction (weight w_j0 / mu_j) and of its update
// with each z_k (weight w_jk / mu_j) matched in its first two moments — its own PDA combined
// update with those weights. Summed over j, the (candidate, mode) mixture is exactly the mixture of
// the IMM's posterior for each candidate (weight beta_k) and of its prediction (weight beta_0):
// mu_j above is Houles & Bar-Shalom's mu_j = c_j Lambda_j / sum_i c_i Lambda_i with the mode
// likelihood Lambda_j proportional to (1 - P_D P_G) + (P_D / lambda) sum_k g_jk, written through the
// beta's (beta_k is proportional to (P_D / lambda) sum_i c_i g_ik, beta_0 to 1 - P_D P_G).

// q_j = c_j g_jk / sum_i c_i g_ik for one candidate, from the modes' log-likelihoods (a mode that
// could not use the candidate gets the worst likelihood of the others, as in the IMM's update:
// floor_likelihoods). false: no mode could use it (the candidate is dropped).
inline bool candidate_mode_weights(const double* c, double* ll, const bool* used, int count, double* q) {
  if (!floor_likelihoods(ll, used, count)) return false;
  return update_probabilities(c, ll, count, q);
}

// Probabilities summing to 1 again after the rounding of a sum of products.
inline void normalise(double* mu, int count) {
  double sum = 0.0;
  for (int j = 0; j < count; ++j) sum += mu[j];
  if (sum > 0.0)
    for (int j = 0; j < count; ++j) mu[j] /= sum;
}

// Per mode, the weighted sums of its candidate updates in its own state order (its first N entries
// of the common-size storage): W_j = sum_k w_jk, D_j = sum_k w_jk dx_jk,
// M_j = sum_k w_jk (P_jk + dx_jk dx_jk'), with dx_jk the update's deviation from the prediction
// (deviations, so that the sums do not cancel); `used` = sum of the beta_k of the candidates used.
struct WeightedSums {
  explicit WeightedSums(int count) {
    for (int j = 0; j < count; ++j) {
      D[j].setZero();
      M[j].setZero();
    }
  }
  template <int N>
  void add(int j, double w, const VecC& dx, const MatC& P) {
    if (!(w > 0.0)) return;
    W[j] += w;
    D[j].template head<N>() += w * dx.template head<N>();
    M[j].template topLeftCorner<N, N>() +=
        w * (P.template topLeftCorner<N, N>() + dx.template head<N>() * dx.template head<N>().transpose());
  }
  double W[kMaxModes] = {};
  VecC D[kMaxModes];
  MatC M[kMaxModes];
  double used = 0.0;
};

// Mode j's combined update in place (x, P: its prediction), with w0 = w_j0 (unnormalised, like the
// sums): a = w0 + W_j, d = D_j / a, x <- x + d, P <- (w0 P + M_j) / a - d d' (Bar-Shalom, Willett &
// Tian 2011, eq. 3.4.2-4's spread of the innovations, written on the states), symmetrised.
template <int N>
void moment_step(double w0, const WeightedSums& s, int j, Eigen::Matrix<double, N, 1>& x, Eigen::Matrix<double, N, N>& P) {
  const double a = w0 + s.W[j];
  if (!(a > 0.0)) return;
  const Eigen::Matrix<double, N, 1> d = s.D[j].template head<N>() / a;
  Eigen::Matrix<double, N, N> out = (w0 * P + s.M[j].template topLeftCorner<N, N>()) / a - d * d.transpose();
  P = 0.5 * (out + out.transpose());
  x += d;
}

}  // namespace trackflow::imm
