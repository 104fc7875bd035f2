// Purpose: filter.ukf — scaled unscented Kalman filter with a Cartesian ENU state (CV, CA or Singer motion) on spherical [r, az, el(, rdot)] measurements.
#include "estimation/cartesian_radar_estimator.hpp"
#include "estimation/ekf_radar_update.hpp"
#include "estimation/zenith_guard.hpp"
#include "sigma_spherical.hpp"
#include "unscented_transform.hpp"

#include <trackflow/number_text.hpp>
#include <trackflow/kalman.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/single_track_filter.hpp>
#include <trackflow/spherical_measurement.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cstdio>
#include <string>

namespace trackflow {
namespace {

struct UnscentedSettings {
  double alpha = 1.0, beta = 2.0, kappa = 0.0;
};

// Settings, measurement checks, initialisation, prediction and publishing: cartesian_radar_estimator.hpp.
// The prediction there is the linear F x, F P F' + Q: for a linear map the unscented transform
// returns exactly these moments, so sigma points are used only for the nonlinear h.
template <int Order>
class UnscentedKalmanFilter final
    : public cartesian_filter::CartesianRadarEstimator<Order, UnscentedKalmanFilter<Order>> {
  using Base = cartesian_filter::CartesianRadarEstimator<Order, UnscentedKalmanFilter<Order>>;
  friend Base;
  using Base::N;
  using Base::x_;
  using Base::P_;
  using Base::R_;
  using Base::idx_;
  using Layout = typename Base::Layout;
  using StateN = typename Base::StateN;
  using MatN = typename Base::MatN;

 public:
  UnscentedKalmanFilter(cartesian_filter::Settings s, UnscentedSettings u)
      : Base(std::move(s)), weights_(ukf::ScaledWeights::make(N, u.alpha, u.beta, u.kappa)) {}

  static std::vector<std::string> counter_names() { return {"azimuth_dropped"}; }
  // Spherical only: a 2-D radar's track has a zero-variance z (cartesian_radar_state.hpp), for which
  // the sigma points' Cholesky factor does not exist.
  static constexpr FrameMask kFrames = mask(Frame::Spherical);

 private:
  enum Counter { kAzimuthDropped };

  void on_start_run() {
    jitter_count_ = spread_clamped_count_ = updates_ = relinearised_count_ = 0;
    max_jitter_ = 0.0;
    zenith_reported_ = false;
  }

  void on_end_run_report() {
    // Numerical repairs are counted rather than reported at every step.
    if (jitter_count_ > 0) {
      const std::string buf = number_text::general(max_jitter_, 3);
      this->warn("state covariance not numerically positive definite at " + std::to_string(jitter_count_) + " of " +
                 std::to_string(updates_) + " updates: symmetrised, up to " + buf +
                 " added to its diagonal before drawing sigma points");
    }
    if (spread_clamped_count_ > 0)
      this->warn("negative centre weight W0c = " + std::to_string(weights_.cov0) +
                 " made R plus the unscented spread indefinite (P - K S K' could lose definiteness) at " +
                 std::to_string(spread_clamped_count_) + " of " + std::to_string(updates_) +
                 " updates; its negative part was removed there (see alpha, beta, kappa)");
    if (relinearised_count_ > 0) this->warn(cartesian_filter::relinearised_text(relinearised_count_, updates_));
  }

  // The azimuth dropped near the zenith (zenith_guard.hpp, as filter.ekf drops it): counted, and
  // reported once per run.
  void dropped_azimuth(const Measurement& m) {
    this->count(kAzimuthDropped);
    if (zenith_reported_) return;
    this->warn("target near the zenith at t=" + std::to_string(m.time) +
               " s: azimuth not used (the zenith is within 3 sigma of the prediction, where the azimuth may flip by "
               "pi between sigma points); counted in the summary, reported once per run");
    zenith_reported_ = true;
  }

  // A prior much wider than the measurement (cartesian_filter::prior_much_wider; a huge q) whose
  // sigma points reach the zenith: they sample h where the target cannot be, around and across the
  // sensor (issue 27: q = 1e12 m2/s3 gave a RMSE of 28 000 km), so the update is filter.ekf's
  // iterated one there (the same code), counted and reported at the end of the run.
  template <int M>
  bool iterated_correct(const Measurement& m, const Eigen::Matrix<double, M, M>& R) {
    cartesian_filter::EkfInnovation<M> in;
    const cartesian_filter::EkfOutcome outcome =
        cartesian_filter::ekf_radar_iterated_update<N, M>(x_, P_, idx_, m, R, in);
    if (outcome == cartesian_filter::EkfOutcome::AtSensor) {
      this->warn("predicted position at the sensor at t=" + std::to_string(m.time) +
                 " s: no direction to linearise about; measurement not used");
      return false;
    }
    ++relinearised_count_;
    if (in.azimuth_dropped) dropped_azimuth(m);
    if (outcome == cartesian_filter::EkfOutcome::Used) {
      this->template accept_update<M>(in.nu, in.S, in.nis);
      return true;
    }
    this->warn("innovation covariance not positive definite at t=" + std::to_string(m.time) +
               " s; measurement not used");
    return false;
  }

  template <int M>
  bool correct(const Measurement& m) {
    using MatM = Eigen::Matrix<double, M, M>;
    ++updates_;
    // The zenith within 3 sigma of the prediction (zenith_guard.hpp): the azimuth is dropped below,
    // or, on a prediction much wider than the measurement, the measurement decides (iterated).
    const Vec3 d = frame_to_sensor(m, Layout::position(x_) - m.sensor_position);
    const bool zenith = cartesian_filter::azimuth_unusable(d, cartesian_filter::horizontal_covariance<N>(P_, idx_, m));
    if (zenith && cartesian_filter::prior_much_wider<N, M>(x_, P_, idx_, m, MatM(R_.template topLeftCorner<M, M>())))
      return iterated_correct<M>(m, MatM(R_.template topLeftCorner<M, M>()));
    MatN L;
    const double jitter = ukf::guarded_cholesky<N>(P_, L);
    if (jitter < 0.0) {
      this->warn("state covariance at t=" + std::to_string(m.time) +
                 " s cannot be factored for sigma points; measurement not used");
      return false;
    }
    if (jitter > 0.0) {
      ++jitter_count_;
      max_jitter_ = std::max(max_jitter_, jitter);
    }
    // The sigma points x ± c L_j measured as offsets from the centre (sigma_spherical.hpp). h
    // reads the position (and, with the range rate, the velocity): a column of L that moves
    // neither gives h(x) itself (the last one, which moves only the last acceleration).
    // A tilted sensor (Measurement::sensor_axes) sees the centre and the offsets in its own axes.
    const ukf::SphericalNearCentre<M> near(d, frame_to_sensor(m, Layout::velocity(x_)), m.azimuth);
    constexpr int kRead = M == 4 ? 6 : 3;
    const double c = weights_.spread;
    typename ukf::SphericalNearCentre<M>::template Batch<2 * N> points;
    int slot[N];  // points.z[slot[j]] = h(x + c L_j), points.z[slot[j] + 1] = h(x - c L_j); -1: h(x)
    for (int j = 0; j < N; ++j) {
      bool moves = false;  // L is lower triangular: only rows from j on can be non-zero
      for (int k = 0; k < kRead && !moves; ++k) moves = idx_[k] >= j && L(idx_[k], j) != 0.0;
      slot[j] = moves ? points.count : -1;
      if (!moves) continue;
      // x - c L_j: the negated offsets of x + c L_j ((-c) a = -(c a) exactly).
      const int k = points.count;
      points.count += 2;
      points.ex[k + 1] = -(points.ex[k] = c * L(idx_[0], j));
      points.ey[k + 1] = -(points.ey[k] = c * L(idx_[1], j));
      points.ez[k + 1] = -(points.ez[k] = c * L(idx_[2], j));
      points.fx[k + 1] = -(points.fx[k] = c * L(idx_[3], j));
      points.fy[k + 1] = -(points.fy[k] = c * L(idx_[4], j));
      points.fz[k + 1] = -(points.fz[k] = c * L(idx_[5], j));
    }
    if (!m.sensor_level) {
      const Mat3 At = m.sensor_axes.transpose();
      for (int k = 0; k < points.count; ++k) {
        const Vec3 e = At * Vec3(points.ex[k], points.ey[k], points.ez[k]);
        const Vec3 f = At * Vec3(points.fx[k], points.fy[k], points.fz[k]);
        points.ex[k] = e.x(), points.ey[k] = e.y(), points.ez[k] = e.z();
        points.fx[k] = f.x(), points.fy[k] = f.y(), points.fz[k] = f.z();
      }
    }
    near.evaluate(points);
    const SphericalVec<M>* zp[N];
    const SphericalVec<M>* zm[N];
    for (int j = 0; j < N; ++j) {
      zp[j] = slot[j] < 0 ? &near.centre() : &points.z[slot[j]];
      zm[j] = slot[j] < 0 ? &near.centre() : &points.z[slot[j] + 1];
    }
    ukf::MeasurementMoments<N, M> ut;
    ukf::moments_from_points<N, M>(near.centre(), zp, zm, L, weights_, ut, false);
    const SphericalVec<M> z = m.value.template head<M>();
    SphericalVec<M> nu = spherical_residual<M>(z, ut.mean);
    // The Joseph form with the statistically linearised H and R + extra gives the textbook
    // UKF's gain P_xz S^-1 and its P - K S K', but as a sum of two positive semi-definite
    // terms (unscented_transform.hpp; docs/filters.md).
    MatM R = R_.template topLeftCorner<M, M>();
    R += ut.extra;
    // A negative W0c can make R + extra indefinite, and with it P - K S K'. Then the negative
    // part of `extra` is removed (eigenvalues clamped at 0), so R + extra >= R.
    if (weights_.cov0 < 0.0 && Eigen::LLT<MatM>(R).info() != Eigen::Success) {
      const Eigen::SelfAdjointEigenSolver<MatM> eig(ut.extra);
      R = R_.template topLeftCorner<M, M>();
      R += eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() * eig.eigenvectors().transpose();
      ++spread_clamped_count_;
    }
    // Near the zenith the sigma points straddle it and their azimuths differ by up to pi: their
    // mean and spread describe nothing (issue 27: an exact zenith pass gave RMSE 246 m, ANEES
    // 5 119, where filter.ekf gives 4.6 m). The azimuth is dropped as filter.ekf drops it (the same
    // test, zenith_guard.hpp): zero column of G (H = G' L^-1), zero innovation, R decorrelated.
    if (zenith) {
      ut.G.col(1).setZero();
      cartesian_filter::drop_azimuth_noise<M>(nu, R);
      dropped_azimuth(m);
    }
    // H = G' L^-1 is never formed: P H' = L L' H' = L G (L lower triangular), H P H' = G' G.
    // Column by column (P H')(:, k) = sum_j G(j, k) L(:, j): whole columns of L (zero above the
    // diagonal), so the loops over the N rows vectorise.
    Eigen::Matrix<double, N, M> PHt = Eigen::Matrix<double, N, M>::Zero();
    for (int k = 0; k < M; ++k)
      for (int j = 0; j < N; ++j) {
        const double g = ut.G(j, k);
        for (int r = 0; r < N; ++r) PHt(r, k) += L(r, j) * g;
      }
    MatM S = R;
    S.noalias() += ut.G.transpose().lazyProduct(ut.G);
    double nis = 0.0;
    if (joseph_update_cross<N, M>(x_, P_, nu, PHt, S, nis)) {
      this->template accept_update<M>(nu, S, nis);
      return true;
    }
    this->warn("innovation covariance not positive definite at t=" + std::to_string(m.time) +
               " s; measurement not used");
    return false;
  }

  ukf::ScaledWeights weights_;
  int jitter_count_ = 0, spread_clamped_count_ = 0, updates_ = 0, relinearised_count_ = 0;
  bool zenith_reported_ = false;
  double max_jitter_ = 0.0;
};

// The node's parameters: the Cartesian filters' settings and the sigma-point scaling.
struct UkfParams {
  cartesian_filter::Settings s;
  UnscentedSettings u;
};

UkfParams parse(const Params& p) {
  UkfParams k{cartesian_filter::parse_settings(p, "filter.ukf"), {}};
  const int n = k.s.state_dim();
  k.u.alpha = p.real("alpha");
  k.u.beta = p.real("beta");
  k.u.kappa = p.real_or("kappa", 3.0 - n);
  if (!(n + k.u.kappa > 0.0))
    throw p.error("kappa", "kappa must exceed -n = " + std::to_string(-n) + " (the state has n = " +
                               std::to_string(n) + " elements): the sigma points lie at sqrt(alpha^2 (n + kappa)) "
                               "standard deviations");
  return k;
}

std::unique_ptr<Component> create(const Params& p) {
  const UkfParams k = parse(p);
  if (k.s.order() == 2) return make_single_track_filter(k.s.type, k.s.node, UnscentedKalmanFilter<2>(k.s, k.u));
  return make_single_track_filter(k.s.type, k.s.node, UnscentedKalmanFilter<3>(k.s, k.u));
}

std::unique_ptr<Estimator> create_estimator(const Params& p) {
  const UkfParams k = parse(p);
  if (k.s.order() == 2) return std::make_unique<UnscentedKalmanFilter<2>>(k.s, k.u);
  return std::make_unique<UnscentedKalmanFilter<3>>(k.s, k.u);
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.ukf";
  d.kind = ComponentKind::Filter;
  d.summary = "Scaled unscented Kalman filter: Cartesian ENU state (CV, CA or Singer) on spherical "
              "[r, az, el(, rdot)] measurements";
  d.doc =
      "Same state, motion models, initialisation, coasting and noise handles as filter.ekf; the prediction is linear "
      "(exact for these models). The measurement h(x) = [r, az, el(, rdot)] goes through the scaled unscented "
      "transform (Wan & van der Merwe 2000; Julier 2002): 2n+1 sigma points x, x +- sqrt(n+lambda) L_j from the "
      "Cholesky factor of P, lambda = alpha^2 (n + kappa) - n, weights W0m = lambda/(n+lambda), "
      "W0c = W0m + 1 - alpha^2 + beta, Wi = 1/(2(n+lambda)). Azimuths are averaged relative to the centre point's "
      "(no +-pi cut) and every residual's azimuth is wrapped to (-pi, pi]. Update in Joseph form with the "
      "statistically linearised H = P_zx P^-1 and R plus the unexplained spread (equal to P - K S K', kept "
      "positive semi-definite). Near the zenith the azimuth is dropped as filter.ekf drops it (the same test: the "
      "zenith within 3 sigma of the prediction; counted as azimuth_dropped); where that prediction's horizontal "
      "variance also exceeds 100 times the measurement's (a huge q) it is updated by filter.ekf's iterated update (reported at the "
      "end of the run). Defaults alpha 1, beta 2, kappa 3 - n: sigma points at sqrt(3) sigma (the Gaussian's "
      "fourth moment, Julier & Uhlmann 2004) and non-negative covariance weights for n <= 9."
      " Several inputs (up to 8 radars, each at its own site with its own noise, rate and biases): the measurements are used one after another in time order, equal time stamps in the engine's delivery order (the order of the radars' declaration when they share a truth source); a tilted sensor (a geodetic site away from the frame's origin) is measured in its own axes; the summary then gives updates.<input> and nis_mean.<input> (mean NIS per element with its 95 % chi-square band) per sensor. See docs/filters.md.";
  d.accepts = mask(ItemKind::Measurement);
  // Several radars into one track: one input per sensor (docs/filters.md, "Several sensors").
  d.min_inputs = 1;
  d.max_inputs = SingleTrackRunResult::kMaxPorts;
  d.produces = mask(ItemKind::Estimate);
  d.accepts_frames = mask(Frame::Spherical);
  d.params = cartesian_filter::param_specs();
  d.params.push_back(ParamSpec::real("alpha", dim::none,
                                     "spread of the sigma points (scaled UT); 1 keeps them at sqrt(n + kappa) sigma, "
                                     "small values (1e-3) make W0 large and negative")
                         .def("1")
                         .positive());
  d.params.push_back(ParamSpec::real("beta", dim::none,
                                     "knowledge of the distribution in the centre covariance weight (2: Gaussian)")
                         .def("2"));
  d.params.push_back(ParamSpec::real("kappa", dim::none,
                                     "secondary scaling; n + kappa > 0 (default 3 - n: -3 for CV, -6 for CA/Singer)"));
  d.create = create;
  d.create_estimator = create_estimator;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.ukf", trackflow::register_components)
