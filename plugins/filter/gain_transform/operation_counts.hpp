// Purpose: instrumented operation counts of one filter step, per phase, for the gain-transform core, filter.ekf's arithmetic and a lean EKF (test and benchmark only).
#pragma once

#include "counting_scalar.hpp"
#include "ekf_operation_replica.hpp"
#include "gain_transform_core.hpp"

#include <trackflow/motion.hpp>

namespace trackflow::gain_transform {

// Phases of one predict + update step with a 3-element polar measurement.
//   covariance_prediction: P (or the LOS blocks) propagated over T
//   linearisation: LOS frame / Jacobian of h (and the angle-curvature terms both filters add)
//   gain_and_covariance_update: from the predicted covariance to K and the updated covariance
//     (for the gain transform: re-expression of the blocks in the new frame, R in LOS units,
//     three 3-state updates and eq 35)
//   state: x = F x, h(x), residual, x += K nu, NIS
//   publication: the ENU covariance for the Estimate (the gain transform forms it from its blocks;
//     the EKF only copies)
// "Gain computation" in paper 002's sense (the covariance recursion whose output is K) is the
// sum of the first three.
struct StepCounts {
  OperationCount covariance_prediction, linearisation, gain_and_covariance_update, state, publication;
  OperationCount gain_computation() const { return sum({covariance_prediction, linearisation, gain_and_covariance_update}); }
  OperationCount filter() const { return sum({covariance_prediction, linearisation, gain_and_covariance_update, state}); }
  OperationCount with_publication() const { return sum({filter(), publication}); }
  static OperationCount sum(std::initializer_list<OperationCount> parts) {
    OperationCount t;
    for (const auto& p : parts) {
      t.mul += p.mul;
      t.div += p.div;
      t.add += p.add;
      t.func += p.func;
    }
    return t;
  }
};

template <class F>
OperationCount count_operations(F&& f) {
  const OperationCount before = operation_count();
  f();
  return operation_count() - before;
}

namespace detail {
// Paper 002's radar at 40 Hz, a target on its circle, Singer alpha 1/s, sigma_m 20 m/s2.
inline constexpr double kT = 0.025, kAlpha = 1.0, kSigma = 20.0;
inline SingerAxis<Counted> singer_axis() {
  const Eigen::Matrix3d F = SingerModel::axis_transition(kAlpha, kT);
  const Eigen::Matrix3d Q = (2.0 * kAlpha) * SingerModel::noise_per_psd(kAlpha, kT);
  return {F(0, 1), F(0, 2), F(1, 2), F(2, 2), {Q(0, 0), Q(0, 1), Q(0, 2), Q(1, 1), Q(1, 2), Q(2, 2)}};
}
inline const double kPosition[3] = {1400.0, 540.0, 150.0};
inline const double kMeasured[3] = {1505.0, 1.2023, 0.0995};  // r, az (north_clockwise), el
inline const double kRdiag[3] = {225.0, 9e-6, 9e-6};
}  // namespace detail

// The gain-transform step exactly as filter.gain_transform runs it (the same template functions).
inline StepCounts count_gain_transform_step() {
  using S = Counted;
  const SingerAxis<S> model = detail::singer_axis();
  AxisCov<S> B[3] = {{200, 900, 900, 8000, 9000, 400}, {20, 100, 200, 900, 1000, 400}, {20, 100, 200, 900, 1000, 400}};
  S x[9];
  for (int a = 0; a < 3; ++a) {
    x[3 * a] = detail::kPosition[a];
    x[3 * a + 1] = a == 0 ? -70.0 : a == 1 ? 190.0 : 0.0;
    x[3 * a + 2] = 5.0;
  }
  LosFrame<S> previous;
  {
    const S d0[3] = {1410.0, 520.0, 150.0};
    line_of_sight_frame(d0, AzimuthConvention::NorthClockwise, previous);
  }
  StepCounts c;
  const S q = detail::kSigma;
  S sigma2;
  c.covariance_prediction = count_operations([&] {
    sigma2 = q * q;  // one sigma_m on all axes: the same in every frame
    for (auto& b : B) predict_axis(b, model, sigma2);
  });
  LosFrame<S> f;
  S rbar[3];
  const bool use[3] = {true, true, true};
  UpdateResult<S> out;
  S nu[3];
  c.state = count_operations([&] { predict_state(x, model); });
  c.linearisation = count_operations([&] {
    const S d[3] = {x[0], x[3], x[6]};
    line_of_sight_frame(d, AzimuthConvention::NorthClockwise, f);
    const S R[3] = {detail::kRdiag[0], detail::kRdiag[1], detail::kRdiag[2]};
    measurement_variances(B, f, d[2], R, 3.0, rbar);
  });
  // measurement_variances reads the blocks before they are re-expressed here; the plugin does it
  // after reframe. The operation count is the same.
  c.gain_and_covariance_update = count_operations([&] {
    reframe(B, previous.u, f.u);
    decoupled_gain(B, f, rbar, use, out);
  });
  c.state = StepCounts::sum({c.state, count_operations([&] {
                               for (int i = 0; i < 3; ++i) nu[i] = S(detail::kMeasured[i]) - f.h[i];
                               correct_state(x, f, nu, use, out);
                             })});
  Eigen::Matrix<S, 9, 9> P;
  c.publication = count_operations([&] { enu_covariance(B, f.u, P); });
  return c;
}

namespace detail {
inline Eigen::Matrix<Counted, 9, 9> ekf_covariance() {
  Eigen::Matrix<double, 9, 9> A;
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) A(i, j) = std::sin(1.0 + i * 9 + j);
  const Eigen::Matrix<double, 9, 9> P = A * A.transpose() + 10.0 * Eigen::Matrix<double, 9, 9>::Identity();
  return P.cast<Counted>();
}
}  // namespace detail

// filter.ekf's arithmetic before issue 12 (dense 9x9 Joseph form; the plugin now runs the structured
// update of kalman.hpp) for the Singer motion with [r, az, el] (ekf_operation_replica.hpp).
inline StepCounts count_filter_ekf_step() {
  using S = Counted;
  using namespace replica;
  const SingerAxis<S> m = detail::singer_axis();
  Mat<S, 3, 3> A, Q1;
  A << S(1.0), m.f01, m.f02, S(0.0), S(1.0), m.f12, S(0.0), S(0.0), m.f22;
  Q1 << m.q.pp, m.q.pv, m.q.pa, m.q.pv, m.q.vv, m.q.va, m.q.pa, m.q.va, m.q.aa;
  Mat<S, 9, 9> P = detail::ekf_covariance();
  Mat<S, 9, 1> x;
  for (int a = 0; a < 3; ++a) x.template segment<3>(3 * a) << detail::kPosition[a], 10.0, 1.0;
  const S q[3] = {detail::kSigma, detail::kSigma, detail::kSigma};
  StepCounts c;
  c.covariance_prediction = count_operations([&] { ekf_predict_covariance(P, A, Q1, q); });
  c.state = count_operations([&] { ekf_predict_state(x, A); });
  Mat<S, 3, 9> H;
  Mat<S, 3, 3> R = Mat<S, 3, 3>::Zero();
  S d[3];
  c.linearisation = count_operations([&] {
    for (int a = 0; a < 3; ++a) d[a] = x(3 * a) - S(0.0);  // position - sensor
    ekf_jacobian(d, H);
    const S Ph[2][2] = {{P(0, 0), P(0, 3)}, {P(3, 0), P(3, 3)}};
    S caz, cel;
    ekf_curvature(d, Ph, caz, cel);
    for (int i = 0; i < 3; ++i) R(i, i) = detail::kRdiag[i];
    R(2, 2) += cel;
    R(1, 1) += caz;
  });
  JosephGain<S> g;
  c.gain_and_covariance_update = count_operations([&] {
    ekf_gain(P, H, R, g);
    ekf_joseph_covariance(P, H, R, g.K);
  });
  c.state = StepCounts::sum({c.state, count_operations([&] {
                               using std::atan2;
                               using std::hypot;
                               const S rho = hypot(d[0], d[1]);  // h(x): enu_to_spherical
                               const S h[3] = {hypot(rho, d[2]), atan2(d[0], d[1]), atan2(d[2], rho)};
                               Mat<S, 3, 1> nu;
                               for (int i = 0; i < 3; ++i) nu(i) = S(detail::kMeasured[i]) - h[i];
                               S nis;
                               ekf_state(x, nu, g, nis);
                             })});
  return c;  // publication: copies only
}

// A lean EKF: structured prediction, H = [G 0 0] exploited, symmetric updates (replica::lean_*).
inline StepCounts count_lean_ekf_step() {
  using S = Counted;
  using namespace replica;
  const SingerAxis<S> m = detail::singer_axis();
  Mat<S, 9, 9> P = detail::ekf_covariance();
  S x[9];
  for (int a = 0; a < 3; ++a) {
    x[3 * a] = detail::kPosition[a];
    x[3 * a + 1] = 10.0;
    x[3 * a + 2] = 1.0;
  }
  StepCounts c;
  const S q = detail::kSigma;
  c.covariance_prediction = count_operations([&] { lean_predict_covariance(P, m, q * q); });
  c.state = count_operations([&] { predict_state(x, m); });
  LosFrame<S> f;
  c.linearisation = count_operations([&] {
    const S d[3] = {x[0], x[3], x[6]};
    line_of_sight_frame(d, AzimuthConvention::NorthClockwise, f);
  });
  Mat<S, 9, 3> K;
  Mat<S, 3, 3> Sinn;
  Mat<S, 3, 3> R = Mat<S, 3, 3>::Zero();
  for (int i = 0; i < 3; ++i) R(i, i) = detail::kRdiag[i];
  c.gain_and_covariance_update = count_operations([&] { lean_ekf_gain(P, f.u, f.scale, R, K, Sinn); });
  c.state = StepCounts::sum({c.state, count_operations([&] {
                               S nu[3];
                               for (int i = 0; i < 3; ++i) nu[i] = S(detail::kMeasured[i]) - f.h[i];
                               for (int r = 0; r < 9; ++r) x[r] = x[r] + K(r, 0) * nu[0] + K(r, 1) * nu[1] + K(r, 2) * nu[2];
                             })});
  return c;
}

}  // namespace trackflow::gain_transform
