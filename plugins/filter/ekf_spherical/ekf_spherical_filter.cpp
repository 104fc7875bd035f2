// Purpose: filter.ekf_spherical — paper 000's spherical-coordinate EKF: 9-state CA model in (R, θ, φ), linear [r, az, el(, rdot)] measurement.
#include "spherical_ca_model.hpp"
#include "spherical_two_point.hpp"

#include <trackflow/single_track_filter.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/kalman.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/plugin.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace trackflow {
namespace {

using namespace ekf_spherical;

enum class Init { TwoPoint, Explicit };

struct SphericalEkfSettings {
  double q[3] = {1.0, 1.0, 1.0};  // jerk PSD of the radial, horizontal and vertical channels, m2/s5
  RangeRateUse range_rate = RangeRateUse::Auto;
  bool two_point = true;
  State x0 = State::Zero();  // init explicit
  Matrix P0 = Matrix::Zero();
  double sigma_accel = 50.0;  // two_point: std of the v̇ states
  Guard guard;
  std::string node;
};

// Elevation beyond which a measurement may be nearer the state in its folded form.
constexpr double kNearZenith = 80.0 * std::numbers::pi / 180.0;

// The state is relative to one stationary sensor, in that sensor's azimuth convention: both are
// fixed by the first measurement of a run.
class SphericalEkf final : public Estimator {

 public:
  explicit SphericalEkf(SphericalEkfSettings s)
      : Estimator(MeasurementSpec{mask(Frame::Spherical), s.range_rate, {"azimuth_dropped"}}),
        s_(std::move(s)) {
    for (int i = 0; i < 3; ++i) q_[i] = s_.q[i];
  }

  NoiseHandles noise() override {
    NoiseHandles h;
    h.measurement = {&R_, MeasurementSpace::Spherical};
    h.process = {q_, 3, NoiseKind::SpectralDensity, dim::jerk_psd, NoiseAxes::LineOfSight};  // q_r, q_h, q_v
    return h;
  }

  StateLayout layout() const override {
    static constexpr StateComponent kLayout[] = {{"R", "m"},     {"v_r", "m/s"}, {"vdot_r", "m/s2"},
                                                 {"theta", "rad"}, {"v_h", "m/s"}, {"vdot_h", "m/s2"},
                                                 {"phi", "rad"},   {"v_v", "m/s"}, {"vdot_v", "m/s2"}};
    return {kLayout, kDim};
  }

 private:
  enum Counter { kAzimuthDropped };

  bool reset() override {
    points_ = 0;
    has_sensor_ = false;
    last_T_ = -1.0;
    guard_steps_ = 0;
    predictions_ = 0;
    folds_ = 0;
    zenith_reported_ = false;
    if (!s_.two_point) {
      x_ = s_.x0;
      P_ = s_.P0;
    }
    return !s_.two_point;
  }

  void end_run(bool initialised) override {
    if (guard_steps_ > 0)
      warn("propagation guard (R < min_range or |elevation| > max_elevation) held the model's coefficients on " +
           std::to_string(guard_steps_) + " of " + std::to_string(predictions_) + " predictions, first at t=" +
           std::to_string(first_guard_time_) + " s; state folded over the zenith " + std::to_string(folds_) +
           " times; the spherical model is singular there (filter.ekf suits overhead passes)");
  }

  void scale_covariance(double k) override { P_ *= k; }

  void check(const Measurement& m) override { check_sensor(m); }

  // A spherical state means nothing once the origin or the azimuth reference changes.
  void check_sensor(const Measurement& m) {
    if (!has_sensor_) {
      sensor_ = m.sensor_position;
      convention_ = m.azimuth;
      has_sensor_ = true;
      return;
    }
    if (m.azimuth != convention_)
      throw DataError(who() + ": measurement at t=" + std::to_string(m.time) +
                      " s uses another azimuth convention than the track; the filter follows one sensor");
    if ((m.sensor_position - sensor_).norm() > 1e-6 * (1.0 + sensor_.norm()))
      throw DataError(who() + ": measurement at t=" + std::to_string(m.time) +
                      " s comes from another sensor position than the track's; the spherical state is relative to "
                      "one stationary sensor (use filter.ekf to fuse sensors)");
  }

  void predict(double T) override {
    if (!same_interval(T, last_T_)) {  // fixed-rate data: the unit-intensity Q1 is computed once
      unit_Q1_ = ConstantAcceleration::axis_noise_continuous(T, 1.0);
      last_T_ = T;
    }
    const Coefficients c = coefficients(x_, s_.guard);
    ++predictions_;
    if (c.range_guarded || c.elevation_guarded) {
      if (guard_steps_ == 0) first_guard_time_ = time();
      ++guard_steps_;
    }
    jacobian(x_, T, s_.guard, F_);
    process_noise(x_, unit_Q1_, q_, s_.guard, Q_);  // at the prior state, like F
    propagate(x_, T, s_.guard);
    x_(kTheta) = wrap_angle(x_(kTheta));
    propagate_covariance();
    P_ += Q_;
    P_ = (0.5 * (P_ + P_.transpose())).eval();
    if (fold_over_zenith(x_, P_)) ++folds_;
  }

  // P <- F P F' with F = I + E, E the model's few off-diagonal terms (spherical_ca_model.hpp:
  // the kinematic T, T^2/2 and the angle rows): P + E P, then the same on the columns. The zero
  // entries of F are skipped, so the products cost a multiple of E's non-zeros (14) instead of
  // two dense 9x9x9 products; the result is F P F' to rounding.
  void propagate_covariance() {
    FP_ = P_;
    for (int i = 0; i < kDim; ++i)
      for (int k = 0; k < kDim; ++k)
        if (k != i && F_(i, k) != 0.0) FP_.row(i) += F_(i, k) * P_.row(k);
    P_ = FP_;
    for (int j = 0; j < kDim; ++j)
      for (int k = 0; k < kDim; ++k)
        if (k != j && F_(j, k) != 0.0) P_.col(j) += F_(j, k) * FP_.col(k);
  }

  // H selects [R, θ, φ(, v_r)] with ones (a zero row where the azimuth is not used): P H' is those columns
  // of P and H P H' their rows, for the Joseph-form update from them (kalman.hpp).
  template <int M>
  static void selected_moments(const Matrix& P, const Eigen::Matrix<double, M, kDim>& H,
                               Eigen::Matrix<double, kDim, M>& PHt, Eigen::Matrix<double, M, M>& HPH) {
    int col[M];
    for (int m = 0; m < M; ++m) {
      col[m] = -1;
      for (int k = 0; k < kDim; ++k)
        if (H(m, k) != 0.0) col[m] = k;
      if (col[m] < 0)
        PHt.col(m).setZero();
      else
        PHt.col(m) = P.col(col[m]);
    }
    for (int m = 0; m < M; ++m)
      for (int n = 0; n < M; ++n) HPH(m, n) = col[m] < 0 ? 0.0 : PHt(col[m], n);
  }

  // Linear measurement (eq 3.61-3.63) in SDK order [r, az, el(, rdot)].
  bool update(const Measurement& m, int dim) override {
    return dim == 4 ? update_values<4>(m) : update_values<3>(m);
  }
  bool predict_measurement(const SensorFrame& s, const MeasCov& R, PredictedMeasurement& p) const override {
    return predicted_by_update<SphericalEkf>(s, R, p);
  }
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<SphericalEkf>(*this); }

  template <int M>
  bool update_values(const Measurement& m) {
    using MatM = Eigen::Matrix<double, M, M>;
    Eigen::Matrix<double, M, kDim> H = Eigen::Matrix<double, M, kDim>::Zero();
    H(0, kR) = 1.0;
    H(1, kTheta) = 1.0;
    H(2, kPhi) = 1.0;
    if constexpr (M == 4) H(3, kVr) = 1.0;
    Eigen::Matrix<double, M, 1> z = m.value.template head<M>();
    MatM R = R_.topLeftCorner(M, M);
    // Straight overhead every azimuth names the same point: a Gaussian in θ cannot describe that,
    // and the measured azimuth there (0 from atan2(0, 0), or noise) would wrench θ and v_h. While
    // the vertical axis lies within 3σ of the predicted horizontal position the azimuth is not
    // used: zero H row and innovation, R decorrelated (NIS then has one dimension fewer).
    const bool drop_azimuth = zenith_within_3_sigma();
    if (drop_azimuth) {
      H.row(1).setZero();
      const double raz = R(1, 1);
      R.row(1).setZero();
      R.col(1).setZero();
      R(1, 1) = raz > 0.0 ? raz : 1.0;
      count(kAzimuthDropped);
      if (!zenith_reported_)
        warn("target near the zenith at t=" + std::to_string(m.time) + " s: azimuth not used (the vertical axis "
             "within 3 sigma of the predicted position); counted in the summary, reported once per run");
      zenith_reported_ = true;
    }
    if (std::abs(x_(kPhi)) > kNearZenith || std::abs(z(2)) > kNearZenith)
      nearer_representation<M>(H, drop_azimuth, z, R);
    Eigen::Matrix<double, M, 1> nu = z - H * x_;
    nu(1) = drop_azimuth ? 0.0 : wrap_angle(nu(1));
    Eigen::Matrix<double, kDim, M> PHt;
    MatM S;
    selected_moments<M>(P_, H, PHt, S);
    S += R;
    double nis = 0.0;
    if (joseph_update_cross<kDim, M>(x_, P_, nu, PHt, S, nis)) {
      x_(kTheta) = wrap_angle(x_(kTheta));
      if (fold_over_zenith(x_, P_)) ++folds_;
      accept_update<M>(nu, S, nis);
      return true;
    }
    warn("innovation covariance not positive definite at t=" + std::to_string(m.time) + " s; measurement not used");
    return false;
  }

  // Horizontal range R_h = R cos φ against the std of the predicted position along the horizontal
  // line of sight (first order: ∂R_h/∂R = cos φ, ∂R_h/∂φ = −R sin φ).
  bool zenith_within_3_sigma() const {
    const double R = x_(kR), c = std::cos(x_(kPhi)), sn = std::sin(x_(kPhi));
    const double dR = c, dphi = -R * sn;
    const double var_h = dR * dR * P_(kR, kR) + 2.0 * dR * dphi * P_(kR, kPhi) + dphi * dphi * P_(kPhi, kPhi);
    const double Rh = R * c;
    return Rh * Rh < 9.0 * var_h;
  }

  // (az, el) and (az + π, ±π − el) are the same direction. Near the zenith the measured azimuth
  // jumps by π at the pass while the state moves on continuously (and may be folded, see
  // fold_over_zenith), so the measurement is used in whichever form has the smaller NIS; the
  // folded form negates the elevation's covariances with the other channels.
  template <int M>
  void nearer_representation(const Eigen::Matrix<double, M, kDim>& H, bool drop_azimuth,
                             Eigen::Matrix<double, M, 1>& z, Eigen::Matrix<double, M, M>& R) const {
    using MatM = Eigen::Matrix<double, M, M>;
    using VecM = Eigen::Matrix<double, M, 1>;
    VecM z_fold = z;
    z_fold(1) = wrap_angle(z(1) + std::numbers::pi);
    z_fold(2) = std::copysign(std::numbers::pi, z(2)) - z(2);
    MatM R_fold = R;
    R_fold.row(2) *= -1.0;
    R_fold.col(2) *= -1.0;
    Eigen::Matrix<double, kDim, M> PHt;
    MatM HPH;
    selected_moments<M>(P_, H, PHt, HPH);
    auto nis = [&](const VecM& zz, const MatM& RR) {
      VecM nu = zz - H * x_;
      nu(1) = drop_azimuth ? 0.0 : wrap_angle(nu(1));
      const Eigen::LLT<MatM> llt(HPH + RR);
      return llt.info() == Eigen::Success ? nu.dot(llt.solve(nu)) : std::numeric_limits<double>::infinity();
    };
    if (nis(z_fold, R_fold) < nis(z, R)) {
      z = z_fold;
      R = R_fold;
    }
  }

  // Two-point differencing in (r, θ, φ): spherical_two_point.hpp.
  bool initiate(const Measurement& m, int dim) override {
    Meas4 z = Meas4::Zero();
    Cov4 R = Cov4::Zero();
    z.head(dim) = m.value.head(dim);
    R.topLeftCorner(dim, dim) = R_.topLeftCorner(dim, dim);
    if (points_ == 0 || m.time == t1_) {  // first point, or a newer one with the same time stamp
      z1_ = z;
      R1_ = R;
      t1_ = m.time;
      points_ = 1;
      return false;
    }
    two_point_state(z1_, R1_, z, R, m.time - t1_, dim == 4, s_.sigma_accel, x_, P_);
    points_ = 2;
    return true;
  }

  // ENU block for metrics: p = sensor + R e_r, v = v_r e_r + v_h e_θ + v_v e_φ, cov J P J'.
  void fill(Estimate& e) const override {
    e.state.resize(kDim);
    e.state.head<kDim>() = x_;
    e.covariance.resize(kDim, kDim);
    e.covariance.topLeftCorner<kDim, kDim>() = P_;
    e.enu = to_enu(x_, convention_, &J_enu_);
    e.enu.head<3>() += sensor_;
    JP_ = J_enu_.lazyProduct(P_);  // coefficient-wise products: no general matrix-product kernel for 6x9
    Mat6 C = JP_.lazyProduct(J_enu_.transpose());
    e.enu_covariance = 0.5 * (C + C.transpose());
  }

  SphericalEkfSettings s_;
  double q_[3] = {};
  State x_ = State::Zero();
  Matrix P_ = Matrix::Identity(), F_ = Matrix::Identity(), Q_ = Matrix::Zero(), FP_ = Matrix::Zero();
  Eigen::Matrix3d unit_Q1_ = Eigen::Matrix3d::Zero();
  // fill's scratch (fill is const: products, no state)
  mutable EnuJacobian J_enu_ = EnuJacobian::Zero();
  mutable Eigen::Matrix<double, 6, kDim> JP_ = Eigen::Matrix<double, 6, kDim>::Zero();
  double last_T_ = -1.0;
  bool has_sensor_ = false, zenith_reported_ = false;
  Vec3 sensor_ = Vec3::Zero();
  AzimuthConvention convention_ = AzimuthConvention::NorthClockwise;
  int points_ = 0;
  Meas4 z1_ = Meas4::Zero();
  Cov4 R1_ = Cov4::Zero();
  double t1_ = 0.0;
  long long guard_steps_ = 0, predictions_ = 0, folds_ = 0;
  double first_guard_time_ = 0.0;
};

// The estimator of one track from the node's parameters (the node and a tracker take it alike).
SphericalEkf make_estimator(const Params& p) {
  using S = SphericalEkfSettings;
  S s;
  s.node = p.node();
  s.q[0] = p.real("q_r");
  s.q[1] = p.real("q_h");
  s.q[2] = p.real("q_v");
  s.range_rate = p.choice<RangeRateUse>("range_rate");
  s.guard.max_elevation = p.real("max_elevation");
  s.guard.min_range = p.real("min_range");
  s.two_point = p.choice<Init>("init") == Init::TwoPoint;
  const char* explicit_only[] = {"initial_range",        "initial_azimuth",        "initial_elevation",
                                 "initial_velocity",     "initial_acceleration",   "initial_sigma_range",
                                 "initial_sigma_angle",  "initial_sigma_velocity"};
  if (s.two_point) {
    for (const char* name : explicit_only)
      if (p.given(name)) throw p.error(name, std::string(name) + " is only used with init: explicit");
  } else {
    for (const char* req : {"initial_range", "initial_azimuth", "initial_elevation", "initial_sigma_range",
                            "initial_sigma_angle", "initial_sigma_velocity"})
      if (!p.has(req)) throw p.error(req, "required with init: explicit");
    const Vec3 v = p.vec3("initial_velocity"), a = p.vec3("initial_acceleration");
    s.x0 << p.real("initial_range"), v(0), a(0), wrap_angle(p.real("initial_azimuth")), v(1), a(1),
        p.real("initial_elevation"), v(2), a(2);
    const double sr = p.real("initial_sigma_range"), sang = p.real("initial_sigma_angle"),
                 sv = p.real("initial_sigma_velocity"), sa = p.real("initial_sigma_acceleration");
    const double sd[kDim] = {sr, sv, sa, sang, sv, sa, sang, sv, sa};
    for (int i = 0; i < kDim; ++i) s.P0(i, i) = sd[i] * sd[i];
    if (std::abs(s.x0(kPhi)) >= s.guard.max_elevation)
      throw p.error("initial_elevation", "must lie inside ±max_elevation, where the spherical model is defined");
    if (s.x0(kR) <= s.guard.min_range) throw p.error("initial_range", "must exceed min_range");
  }
  s.sigma_accel = p.real("initial_sigma_acceleration");
  return SphericalEkf(s);
}

std::unique_ptr<Component> create(const Params& p) {
  return make_single_track_filter("filter.ekf_spherical", p.node(), make_estimator(p));
}

std::unique_ptr<Estimator> create_estimator(const Params& p) { return std::make_unique<SphericalEkf>(make_estimator(p)); }

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.ekf_spherical";
  d.kind = ComponentKind::Filter;
  d.summary = "Spherical-coordinate EKF (paper 000): 9-state constant-acceleration model in range, azimuth and "
              "elevation, linear [r, az, el(, rdot)] measurement";
  d.doc =
      "State [R, v_r, v̇_r, θ, v_h, v̇_h, φ, v_v, v̇_v] relative to the (stationary) sensor, v_r = Ṙ, "
      "v_h = R cos φ θ̇, v_v = R φ̇ (paper 000 eq 3.41-3.42), θ in the sensor's azimuth convention. Nonlinear "
      "second-order propagation of R, θ, φ with the v̇ states constant (eq 3.49-3.57), analytic Jacobian (eq 3.60 "
      "corrected). Process noise: white jerk of PSD q_r, q_h, q_v (m2/s5) on the radial, horizontal and vertical "
      "linear channels, Q1 of eq 3.58 with the angle rows divided by R cos φ and R. Linear H picks R, θ, φ (and v_r "
      "for range rate); azimuth innovation wrapped; Joseph form. Estimates carry the 9 spherical states and the ENU "
      "position/velocity with J P J'. The model is singular overhead and at the sensor: its coefficients are held at "
      "max_elevation / min_range there (warning per run). Invalid measurements: predict only. See docs/filters.md.";
  d.accepts = mask(ItemKind::Measurement);
  d.accepts_frames = mask(Frame::Spherical);
  d.produces = mask(ItemKind::Estimate);
  d.params = {
      ParamSpec::real("q_r", dim::jerk_psd, "jerk PSD of the radial channel [R, v_r, v̇_r] (paper 000 eq 3.58, q_r)")
          .def("1 m2/s5")
          .at_least(0),
      ParamSpec::real("q_h", dim::jerk_psd,
                      "jerk PSD of the horizontal cross-range channel [θ, v_h, v̇_h] (paper's q_θ, as a linear PSD)")
          .def("1 m2/s5")
          .at_least(0),
      ParamSpec::real("q_v", dim::jerk_psd,
                      "jerk PSD of the vertical cross-range channel [φ, v_v, v̇_v] (paper's q_φ, as a linear PSD)")
          .def("1 m2/s5")
          .at_least(0),
      range_rate_param(),
      ParamSpec::choice<Init>("init", {{Init::TwoPoint, "two_point"}, {Init::Explicit, "explicit"}},
                              "two-point differencing in (r, az, el) or the initial_* values")
          .def("two_point"),
      ParamSpec::real("initial_range", dim::length, "init explicit: range R").positive(),
      ParamSpec::real("initial_azimuth", dim::angle, "init explicit: azimuth θ in the measurements' convention"),
      ParamSpec::real("initial_elevation", dim::angle, "init explicit: elevation φ"),
      ParamSpec::real_list("initial_velocity", dim::velocity, "init explicit: [v_r, v_h, v_v]", 3).def("[0, 0, 0]"),
      ParamSpec::real_list("initial_acceleration", dim::acceleration, "init explicit: [v̇_r, v̇_h, v̇_v]", 3)
          .def("[0, 0, 0]"),
      ParamSpec::real("initial_sigma_range", dim::length, "init explicit: std of R").positive(),
      ParamSpec::real("initial_sigma_angle", dim::angle, "init explicit: std of θ and φ").positive(),
      ParamSpec::real("initial_sigma_velocity", dim::velocity, "init explicit: std of v_r, v_h, v_v").positive(),
      ParamSpec::real("initial_sigma_acceleration", dim::acceleration, "both inits: std of v̇_r, v̇_h, v̇_v")
          .def("50 m/s2")
          .positive(),
      ParamSpec::real("max_elevation", dim::angle,
                      "|elevation| at which the propagation's 1/cos φ and tan φ are held (zenith guard)")
          .def("89 deg")
          .at_least(0.1)
          .at_most(1.5707),
      ParamSpec::real("min_range", dim::length, "range at which the propagation's 1/R is held (guard at the sensor)")
          .def("1 m")
          .positive(),
  };
  d.create = create;
  d.create_estimator = create_estimator;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.ekf_spherical", trackflow::register_components)
