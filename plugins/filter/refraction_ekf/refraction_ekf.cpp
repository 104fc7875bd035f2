// Purpose: filter.refraction_ekf — paper 004's 13-state augmented EKF that estimates the tropospheric refraction bias b on elevation with the target's Cartesian and radar states (Clark b-dot dynamics, linear measurement [range, azimuth, elevation + b], gain normalisation, state scaling, low-pass noise estimate).
#include "lpf_noise.hpp"
#include "refraction_ekf_model.hpp"

#include <trackflow/single_track_filter.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/plugin.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>
#include <string>

namespace trackflow {
namespace {

using refraction_ekf::kN;
using State = refraction_ekf::State;
using Matrix = refraction_ekf::Matrix;
namespace rx = refraction_ekf;

enum class Normalisation { Off, Always, WhenLarge };
enum class NoiseSource { Reported, LowPass };

struct Settings {
  std::string node;
  rx::Model model;
  double sigma_accel = 1.0;                                   // m/s^2, w per axis
  double q_range = 0.0, q_azimuth = 0.0, q_elevation = 0.0, q_bias = 0.0;  // random-walk PSDs
  Normalisation normalisation = Normalisation::Always;
  double lambda = 0.1;
  double scale = 1e-6;
  NoiseSource noise = NoiseSource::Reported;
  double lpf_cutoff = 100.0, lpf_window = 10.0;
  bool lpf_correction = true;
  long lpf_warmup = 100;
  double init_span = 1.0;
  double sigma_a0 = 50.0;
  double bias_uncertainty = 0.2;
  double convergence_window = 20.0, convergence_ratio = 10.0;
};

class RefractionEkf final : public Estimator {

 public:
  enum Counter { kConverged, kNotConverged, kNonFinite, kNormalised };

  explicit RefractionEkf(Settings s)
      : Estimator(MeasurementSpec{mask(Frame::Spherical), RangeRateUse::Ignore,
                                    {"converged_runs", "not_converged_runs", "non_finite_steps", "gain_normalised"}}),
        s_(std::move(s)) {
    for (int i = 0; i < kN; ++i) scale_(i) = i < 9 ? s_.scale : 1.0;
    q_[0] = q_[1] = q_[2] = s_.sigma_accel;
  }

  NoiseHandles noise() override {
    NoiseHandles h;
    // With its own low-pass estimate the filter sets R itself, so an adapter may not.
    if (s_.noise == NoiseSource::Reported) h.measurement = {&R_, MeasurementSpace::Spherical};
    h.process.values = q_;
    h.process.count = 3;
    h.process.kind = NoiseKind::StandardDeviation;
    h.process.dimension = dim::acceleration;
    h.process.axes = NoiseAxes::Enu;
    return h;
  }
  StateLayout layout() const override { return {rx::kLayout, kN}; }

  void finish(Summary& s) const override {
    s.notes.push_back("a run converged when it ended with a finite state and its innovations within " +
                      std::to_string(s_.convergence_ratio) + " measurement sigmas: sqrt of the exponential average "
                      "(time constant " + std::to_string(s_.convergence_window) + " s) of nu' R^-1 nu / 3 (not the "
                      "NIS: a filter whose P has grown huge has a small NIS however far off it is); "
                      "non_finite_steps: steps whose result was not finite and were undone (the state before the "
                      "step is kept)");
  }

 private:
  // --- front-end hooks ---
  bool reset() override {
    points_ = 0;
    finite_ = true;
    ratio_avg_ = -1.0;
    for (auto& c : lpf_) c.reset();
    return false;
  }

  // Two measurements init_span apart (or more): position from the later one with the bias taken
  // out by Clark at the first elevation, velocity by differencing (previous velocity the same).
  bool initiate(const Measurement& m, int) override {
    lpf_update(m);
    const double step = points_ > 0 ? m.time - collect_time_ : 0.0;  // this measurement's interval
    collect_time_ = m.time;
    sign_ = m.azimuth == AzimuthConvention::NorthClockwise ? -1.0 : 1.0;
    conv_ = m.azimuth;
    s_.model.azimuth_sign = sign_;
    if (points_ == 0 || m.time - t0_ < s_.init_span - 1e-9) {
      if (points_ == 0) {
        z0_ = m.value.head<3>();
        R0_ = R_.topLeftCorner(3, 3);
        t0_ = m.time;
        points_ = 1;
      }
      return false;
    }
    const Eigen::Vector3d z1 = m.value.head<3>();
    const Eigen::Matrix3d R1 = R_.topLeftCorner(3, 3);
    const double dt = m.time - t0_;
    // b at the true elevation: theta + b(theta) = z solved by fixed-point iteration (|b'| < 0.3
    // above 2 deg, so 8 steps leave (0.3)^8 of the first step's error).
    auto debias = [&](double z) {
      if (!s_.model.bias) return 0.0;
      double b = s_.model.clark.bias(z);
      for (int k = 0; k < 8; ++k) b = s_.model.clark.bias(z - b);
      return b;
    };
    const double b1 = debias(z1(2)), b0 = debias(z0_(2));
    const double sb = s_.model.bias ? s_.bias_uncertainty * b1 : 0.0;
    const Vec3 p1 = spherical_to_enu(z1(0), z1(1), z1(2) - b1, conv_);
    const Vec3 p0 = spherical_to_enu(z0_(0), z0_(1), z0_(2) - b0, conv_);
    const Mat3 J1 = spherical_to_enu_jacobian(z1(0), z1(1), z1(2) - b1, conv_);
    const Mat3 J0 = spherical_to_enu_jacobian(z0_(0), z0_(1), z0_(2) - b0, conv_);
    const Vec3 v = (p1 - p0) / dt;
    // The initial error is linear in independent sources w = [noise of z1 (3), noise of z0 (3),
    // error db of Clark's b (1), common to both points]: e = L w, P0 = L diag(R1, R0, sb^2) L'.
    // p1 = J1 (n1 - e3 db), v = (p1 - p0) / dt, range/azimuth = z1, elevation = z1 - b, b = b + db.
    Eigen::Matrix<double, kN, 7> L = Eigen::Matrix<double, kN, 7>::Zero();
    Eigen::Matrix<double, 7, 7> W = Eigen::Matrix<double, 7, 7>::Zero();
    W.topLeftCorner<3, 3>() = R1;
    W.block<3, 3>(3, 3) = R0_;
    W(6, 6) = sb * sb;
    for (int a = 0; a < 3; ++a) {
      for (int i = 0; i < 3; ++i) {
        L(rx::pos(a), i) = J1(a, i);
        L(rx::vel(a), i) = L(rx::prev(a), i) = J1(a, i) / dt;
        L(rx::vel(a), 3 + i) = L(rx::prev(a), 3 + i) = -J0(a, i) / dt;
      }
      L(rx::pos(a), 6) = -J1(a, 2);
      L(rx::vel(a), 6) = L(rx::prev(a), 6) = -(J1(a, 2) - J0(a, 2)) / dt;
    }
    L(rx::kRange, 0) = 1.0;
    L(rx::kAzimuth, 1) = 1.0;
    L(rx::kElevation, 2) = 1.0;
    L(rx::kElevation, 6) = -1.0;
    if (s_.model.bias) L(rx::kBias, 6) = 1.0;
    Matrix P = L * W * L.transpose();
    // The previous velocity also differs from the velocity by an unknown acceleration step.
    const double Tstep = step > 0.0 ? step : dt;
    for (int a = 0; a < 3; ++a) P(rx::prev(a), rx::prev(a)) += std::pow(s_.sigma_a0 * Tstep, 2);
    State X = State::Zero();
    for (int a = 0; a < 3; ++a) {
      X(rx::pos(a)) = p1(a);
      X(rx::vel(a)) = v(a);
      X(rx::prev(a)) = v(a);
    }
    X(rx::kRange) = z1(0);
    X(rx::kAzimuth) = z1(1);
    X(rx::kElevation) = z1(2) - b1;
    X(rx::kBias) = b1;
    Xs_ = scale_.asDiagonal() * X;
    Ps_ = scale_.asDiagonal() * P * scale_.asDiagonal();
    last_time_ = m.time;
    return true;
  }

  void predict(double T) override {
    const State X = unscaled();
    Matrix A;
    State Y = rx::propagate(X, T, s_.model, &A);
    Y(rx::kAzimuth) = wrap_angle(Y(rx::kAzimuth));
    // Process noise: w per axis enters position T^2/2 and velocity T (paper 004 §2.1.3); the
    // radar states and b take random-walk PSDs (0 in the paper).
    Matrix Q = Matrix::Zero();
    for (int a = 0; a < 3; ++a) {
      const Eigen::Vector3d G(0.5 * T * T, T, 0.0);
      const double var = q_[a] * q_[a];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) Q(3 * a + i, 3 * a + j) = var * G(i) * G(j);
    }
    Q(rx::kRange, rx::kRange) = s_.q_range * T;
    Q(rx::kAzimuth, rx::kAzimuth) = s_.q_azimuth * T;
    Q(rx::kElevation, rx::kElevation) = s_.q_elevation * T;
    if (s_.model.bias) Q(rx::kBias, rx::kBias) = s_.q_bias * T;
    // In the scaled state Xs = S X: A_s = S A S^-1, Q_s = S Q S.
    const Matrix As = scale_.asDiagonal() * A * scale_.cwiseInverse().asDiagonal();
    const State Ys = scale_.asDiagonal() * Y;
    Matrix Pn = As * Ps_ * As.transpose() + scale_.asDiagonal() * Q * scale_.asDiagonal();
    Pn = 0.5 * (Pn + Pn.transpose()).eval();
    if (!Ys.allFinite() || !Pn.allFinite()) {
      step_failed(T);
      return;
    }
    Xs_ = Ys;
    Ps_ = Pn;
    last_T_ = T;
  }

  bool update(const Measurement& m, int dim) override {
    return dim == 4 ? update_values<4>(m) : update_values<3>(m);
  }
  bool predict_measurement(const SensorFrame& s, const MeasCov& R, PredictedMeasurement& p) const override {
    return predicted_by_update<RefractionEkf>(s, R, p);
  }
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<RefractionEkf>(*this); }

  template <int M>
  bool update_values(const Measurement& m) {
    lpf_update(m);
    last_time_ = m.time;
    Eigen::Matrix3d R = R_.topLeftCorner(3, 3);
    if (s_.noise == NoiseSource::LowPass && lpf_[0].samples() >= s_.lpf_warmup) {
      R.setZero();
      for (int i = 0; i < 3; ++i) R(i, i) = lpf_[i].variance();
    }
    Eigen::Matrix<double, 3, kN> C = Eigen::Matrix<double, 3, kN>::Zero();
    C(0, rx::kRange) = 1.0;
    C(1, rx::kAzimuth) = 1.0;
    C(2, rx::kElevation) = 1.0;
    if (s_.model.bias) C(2, rx::kBias) = 1.0;
    const Eigen::Vector3d z = m.value.head<3>();
    Eigen::Vector3d nu = z - C * Xs_;  // C reads unscaled entries only
    nu(1) = wrap_angle(nu(1));
    const Eigen::Matrix<double, kN, 3> PCt = Ps_ * C.transpose();
    const Eigen::Matrix3d S = C * PCt + R;
    const Eigen::LLT<Eigen::Matrix3d> llt(S);
    if (llt.info() != Eigen::Success) {
      warn("innovation covariance not positive definite at t=" + std::to_string(m.time) + " s; measurement not used");
      return false;
    }
    Eigen::Matrix<double, kN, 3> K = llt.solve(PCt.transpose()).transpose();
    if (normalise(K)) count(kNormalised);
    Matrix IKC = -K * C;
    IKC.diagonal().array() += 1.0;
    const State Xn = Xs_ + K * nu;
    Matrix Pn = IKC * Ps_ * IKC.transpose() + K * R * K.transpose();
    Pn = 0.5 * (Pn + Pn.transpose()).eval();
    const double nis = nu.dot(llt.solve(nu));
    if (!Xn.allFinite() || !Pn.allFinite() || !std::isfinite(nis)) {
      step_failed(0.0);
      return false;
    }
    Xs_ = Xn;
    Xs_(rx::kAzimuth) = wrap_angle(Xs_(rx::kAzimuth));
    Ps_ = Pn;
    // Exponential average over convergence_window of the innovations in units of the measurement
    // noise, nu' R^-1 nu / 3 (about 1 for a filter that tracks; large for one that has lost the target
    // whatever its P says).
    const Eigen::LLT<Eigen::Matrix3d> rllt(R);
    const double q = rllt.info() == Eigen::Success ? nu.dot(rllt.solve(nu)) / 3.0 : nis / 3.0;
    const double w = 1.0 - std::exp(-(last_T_ > 0.0 ? last_T_ : 0.0) / s_.convergence_window);
    ratio_avg_ = ratio_avg_ < 0.0 ? q : ratio_avg_ + w * (q - ratio_avg_);
    accept_update<3>(nu, S, nis);
    return true;
  }

  // Paper 004 eq 11: K <- blkdiag(I_9, lambda I_4) K / ||K||, ||K|| the spectral norm, in the
  // scaled state. WhenLarge applies it only when ||K|| > 1 (the gain is "abnormally large").
  bool normalise(Eigen::Matrix<double, kN, 3>& K) const {
    if (s_.normalisation == Normalisation::Off) return false;
    const Eigen::Matrix3d KtK = K.transpose() * K;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(KtK, Eigen::EigenvaluesOnly);
    const double norm = std::sqrt(std::max(eig.eigenvalues().maxCoeff(), 0.0));
    if (!(norm > 0.0) || (s_.normalisation == Normalisation::WhenLarge && norm <= 1.0)) return false;
    K /= norm;
    K.bottomRows<4>() *= s_.lambda;
    return true;
  }

  void fill(Estimate& e) const override {
    const State X = unscaled();
    const Matrix P = scale_.cwiseInverse().asDiagonal() * Ps_ * scale_.cwiseInverse().asDiagonal();
    e.state = X;
    e.covariance = P;
    // Position from the estimated radar quantities (range, azimuth, true elevation), velocity from
    // the Cartesian state; covariance through the spherical Jacobian.
    const double r = X(rx::kRange), az = X(rx::kAzimuth), el = X(rx::kElevation);
    const Mat3 J = spherical_to_enu_jacobian(r, az, el, conv_);
    Eigen::Matrix<double, 6, kN> G = Eigen::Matrix<double, 6, kN>::Zero();
    for (int i = 0; i < 3; ++i) {
      for (int a = 0; a < 3; ++a) G(a, rx::kRange + i) = J(a, i);
      G(3 + i, rx::vel(i)) = 1.0;
    }
    e.enu.head<3>() = sensor_ + spherical_to_enu(r, az, el, conv_);
    for (int a = 0; a < 3; ++a) e.enu(3 + a) = X(rx::vel(a));
    e.enu_covariance = G * P * G.transpose();
  }

  void scale_covariance(double k) override { Ps_ *= k; }

  void check(const Measurement& m) override {
    sensor_ = m.sensor_position;
  }

  void end_run(bool initialised) override {
    const bool converged = finite_ && ratio_avg_ >= 0.0 && std::isfinite(ratio_avg_) &&
                           std::sqrt(ratio_avg_) < s_.convergence_ratio && initialised;
    count(converged ? kConverged : kNotConverged);
  }

  // --- helpers ---
  State unscaled() const { return scale_.cwiseInverse().asDiagonal() * Xs_; }

  void step_failed(double T) {
    count(kNonFinite);
    if (finite_)
      warn("a non-finite state after " + std::string(T > 0.0 ? "the prediction" : "the update") + " at t=" +
           std::to_string(time()) + " s: the step is undone (the run is marked not converged; further ones counted)");
    finite_ = false;
  }

  void lpf_update(const Measurement& m) {
    if (s_.noise != NoiseSource::LowPass) return;
    const double T = m.time - lpf_time_;
    for (int i = 0; i < 3; ++i)
      lpf_[i].add(m.value(i), T, s_.lpf_cutoff, s_.lpf_window, s_.lpf_correction, i == 1);
    lpf_time_ = m.time;
  }

  Settings s_;
  State scale_ = State::Ones();
  State Xs_ = State::Zero();
  Matrix Ps_ = Matrix::Identity();
  double q_[3] = {};
  double sign_ = -1.0;
  AzimuthConvention conv_ = AzimuthConvention::NorthClockwise;
  Vec3 sensor_ = Vec3::Zero();
  int points_ = 0;
  Eigen::Vector3d z0_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R0_ = Eigen::Matrix3d::Zero();
  double t0_ = 0.0, collect_time_ = 0.0, last_time_ = 0.0, last_T_ = 0.0, lpf_time_ = 0.0;
  bool finite_ = true;
  double ratio_avg_ = -1.0;
  rx::LowPassNoise lpf_[3];
};

// The estimator of one track from the node's parameters (the node and a tracker take it alike).
RefractionEkf make_estimator(const Params& p) {
  Settings s;
  s.node = p.node();
  s.model.clark = sim::read_clark(p, false);
  s.model.clark.below = sim::ClarkBelow::Hold;
  s.model.bias = p.boolean("bias_state");
  s.model.position = p.choice<rx::Position>("position_update");
  s.sigma_accel = p.real("sigma_accel");
  s.q_range = p.real("q_range");
  s.q_azimuth = p.real("q_azimuth");
  s.q_elevation = p.real("q_elevation");
  s.q_bias = p.real("q_bias");
  if (!s.model.bias && p.given("q_bias")) throw p.error("q_bias", "is for the bias state; bias_state is false");
  s.normalisation = p.choice<Normalisation>("gain_normalisation");
  s.lambda = p.real("gain_lambda");
  if (s.normalisation == Normalisation::Off && p.given("gain_lambda"))
    throw p.error("gain_lambda", "is set but gain_normalisation is off");
  s.scale = p.real("state_scale");
  s.noise = p.choice<NoiseSource>("measurement_noise");
  for (const char* name : {"lpf_cutoff", "lpf_window", "lpf_correction", "lpf_warmup"})
    if (s.noise != NoiseSource::LowPass && p.given(name))
      throw p.error(name, std::string(name) + " is for measurement_noise: low_pass");
  s.lpf_cutoff = p.real("lpf_cutoff");
  s.lpf_window = p.real("lpf_window");
  s.lpf_correction = p.boolean("lpf_correction");
  s.lpf_warmup = p.integer("lpf_warmup");
  s.init_span = p.real("init_span");
  s.sigma_a0 = p.real("initial_sigma_acceleration");
  s.bias_uncertainty = p.real("initial_bias_uncertainty");
  s.convergence_window = p.real("convergence_window");
  s.convergence_ratio = p.real("convergence_ratio");
  return RefractionEkf(std::move(s));
}

std::unique_ptr<Component> create(const Params& p) {
  return make_single_track_filter("filter.refraction_ekf", p.node(), make_estimator(p));
}

std::unique_ptr<Estimator> create_estimator(const Params& p) { return std::make_unique<RefractionEkf>(make_estimator(p)); }

const char* const kDoc =
    "Paper 004 (Seo et al. 2017): the refraction bias b on elevation estimated as a state. State (13) [x, vx, vx_prev, "
    "y, vy, vy_prev, z, vz, vz_prev, range, azimuth, elevation, b], Cartesian part from the radar in the ENU axes. "
    "Prediction (§2.1.3): v' = 2v - v_prev (acceleration (v - v_prev)/T), v_prev' = v, x' = x + T v (position_update: "
    "euler, the paper's) or x + T(3v - v_prev)/2 (adams_bashforth2); range, azimuth, elevation and b advance by T times "
    "their rates from the Cartesian state, b-dot = b'(elevation) elevation-dot with Clark's b (n0, clark_*; below 2 deg "
    "b is held, b-dot = 0); analytic Jacobian (eq 10, corrected). Process noise: w ~ N(0, sigma_accel^2) per axis into "
    "position (T^2/2) and velocity (T); random-walk PSDs q_range, q_azimuth, q_elevation, q_bias on the radar states "
    "(0: the paper's model). Measurement (eq 9) linear: [range, azimuth, elevation + b], azimuth residual wrapped; R "
    "from the measurement (measurement_noise: reported) or from paper 004 §2.2's low-pass residual estimate "
    "(low_pass: first-order low-pass at lpf_cutoff, residual variance over lpf_window, divided by the white-noise "
    "share of the residual when lpf_correction). Gain normalisation (eq 11): K <- blkdiag(I_9, gain_lambda I_4) "
    "K / ||K||_2 on every update (always, the paper's), only when ||K|| > 1 (when_large) or never (off); Joseph-form "
    "covariance update with the gain used. State scaling (§2.4): the filter works on S X, S = state_scale on the nine "
    "Cartesian states, 1 on the others (1: no scaling); the published state and covariance are unscaled (SI). "
    "bias_state: false removes b (the model without refraction). Initialisation: two measurements init_span apart, "
    "Clark's b at the first elevation taken out (b0 solves b0 = b(z - b0)), velocity by differencing. The estimate's ENU "
    "position is the radar states' (range, azimuth, elevation) from the sensor; ENU velocity the Cartesian one. "
    "Summary: converged_runs / not_converged_runs (a run converges when it ends finite with the RMS of its "
    "innovations over the last convergence_window, in measurement sigmas, below convergence_ratio), "
    "non_finite_steps (undone), gain_normalised (updates). See docs/filters.md and docs/papers/004-refraction-bias.md.";

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.refraction_ekf";
  d.kind = ComponentKind::Filter;
  d.summary = "Paper 004 13-state augmented EKF: Cartesian + radar states and the elevation refraction bias b (Clark "
              "b-dot), gain normalisation, state scaling";
  d.doc = kDoc;
  d.accepts = mask(ItemKind::Measurement);
  d.produces = mask(ItemKind::Estimate);
  d.accepts_frames = mask(Frame::Spherical);
  d.params = {
      sim::n0_param(),
      ParamSpec::boolean("bias_state", "estimate the refraction bias b as a state (false: b = 0, the plain model)")
          .def("true"),
      ParamSpec::choice<rx::Position>("position_update",
                                      {{rx::Position::Euler, "euler"}, {rx::Position::AdamsBashforth2, "adams_bashforth2"}},
                                      "Cartesian position step: x + T v (paper) or x + T (3 v - v_prev) / 2")
          .def("euler"),
      ParamSpec::real("sigma_accel", dim::acceleration, "std of the white acceleration w per axis per step (paper: 'e.g. 1')")
          .def("1 m/s2")
          .at_least(0),
      ParamSpec::real("q_range", Dimension{2, -1, 0, 0}, "random-walk PSD on the range state (paper: 0)").def("0 m2/s").at_least(0),
      ParamSpec::real("q_azimuth", Dimension{0, -1, 2, 0}, "random-walk PSD on the azimuth state").def("0 rad2/s").at_least(0),
      ParamSpec::real("q_elevation", Dimension{0, -1, 2, 0}, "random-walk PSD on the elevation state").def("0 rad2/s").at_least(0),
      ParamSpec::real("q_bias", Dimension{0, -1, 2, 0}, "random-walk PSD on b (model error of Clark's b-dot)")
          .def("0 rad2/s")
          .at_least(0),
      ParamSpec::choice<Normalisation>("gain_normalisation",
                                       {{Normalisation::Always, "always"},
                                        {Normalisation::WhenLarge, "when_large"},
                                        {Normalisation::Off, "off"}},
                                       "paper 004 eq 11 on every update, only when ||K|| > 1, or not at all")
          .def("always"),
      ParamSpec::real("gain_lambda", dim::none, "eq 11's lambda on the radar-state rows (paper: 0.1)").def("0.1").positive().at_most(1e3),
      // Scaling only conditions the arithmetic (paper 004 §2.4: 1e-6); the covariance is scaled by
      // S^2, so at 1e-300 (accepted before, issue 27) every velocity variance underflowed to 0. 1e-12
      // already puts a 1 mm^2 variance at 1e-30 with the whole double range left.
      ParamSpec::real("state_scale", dim::none,
                      "factor on the nine Cartesian states inside the filter, 1e-12 to 1e6 (paper: 1e-6; 1: off; the "
                      "covariance scales by its square, so smaller factors only push the scaled variances towards "
                      "underflow)")
          .def("1e-6")
          .at_least(1e-12)
          .at_most(1e6),
      ParamSpec::choice<NoiseSource>("measurement_noise",
                                     {{NoiseSource::Reported, "reported"}, {NoiseSource::LowPass, "low_pass"}},
                                     "R from each measurement, or estimated from low-pass residuals (paper 004 §2.2)")
          .def("reported"),
      ParamSpec::real("lpf_cutoff", dim::angular_rate, "low_pass: cut-off of the first-order low-pass (paper: 100 rad/s)")
          .def("100 rad/s")
          .positive(),
      ParamSpec::real("lpf_window", dim::time, "low_pass: time constant of the residuals' running mean and variance")
          .def("10 s")
          .positive(),
      ParamSpec::boolean("lpf_correction", "low_pass: divide the residual variance by the share of white noise it keeps")
          .def("true"),
      ParamSpec::integer("lpf_warmup", "low_pass: residuals before the estimate replaces the reported R").def("100").at_least(2),
      ParamSpec::real("init_span", dim::time, "time between the two measurements that initialise the track").def("1 s").positive(),
      ParamSpec::real("initial_sigma_acceleration", dim::acceleration, "initial std of the acceleration (previous velocity)")
          .def("50 m/s2")
          .at_least(0),
      ParamSpec::real("initial_bias_uncertainty", dim::none, "initial std of b as a fraction of Clark's b")
          .def("0.2")
          .at_least(0),
      ParamSpec::real("convergence_window", dim::time, "time constant of the innovation average judged at the end of a run")
          .def("20 s")
          .positive(),
      ParamSpec::real("convergence_ratio", dim::none,
                      "a run has converged when its RMS innovation, in measurement sigmas, ends below this (1 expected)")
          .def("10")
          .positive(),
  };
  for (auto& spec : sim::clark_param_specs(false)) d.params.push_back(std::move(spec));
  d.create = create;
  d.create_estimator = create_estimator;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.refraction_ekf", trackflow::register_components)
