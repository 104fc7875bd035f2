// Purpose: filter.gain_transform — paper 002's gain-transformation filter: Cartesian Singer state, polar [r, az, el] measurements, gains of three decoupled LOS-frame filters rotated to ENU.
#include "gain_transform_core.hpp"

#include <trackflow/single_track_filter.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/transition_model.hpp>
#include <trackflow/spherical_measurement.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace trackflow {
namespace {

using namespace gain_transform;

enum class FrameChange { Reproject, Carry };

struct GainTransformSettings {
  TransitionModel transition;  // as configured (Singer)
  double alpha = 1.0;          // Singer inverse correlation time, 1/s, the same on all axes
  double sigma = 1.0;          // Singer sigma_m, m/s2 (per ENU axis, adapters may retune each)
  double sigma_accel0 = 1.0;   // initial acceleration std
  bool reproject = true;
  std::string node;
};

// When the zenith is within this many standard deviations of the predicted horizontal
// position, the azimuth can flip by pi over the uncertainty and is not used (as filter.ekf).
constexpr double kZenithSigmas = 3.0;

// The estimator of one track; the filter node around it is the SDK's SingleTrackFilter (single_track_filter.hpp).
class GainTransformEstimator final : public Estimator {

 public:
  explicit GainTransformEstimator(GainTransformSettings s)
      : Estimator(MeasurementSpec{mask(Frame::Spherical), RangeRateUse::Ignore, {"azimuth_dropped"}}),
        s_(std::move(s)) {
    for (double& q : q_) q = s_.sigma;
  }

  const TransitionModel* transition_model() const override { return &s_.transition; }
  NoiseHandles noise() override {
    NoiseHandles h;
    h.measurement = {&R_, MeasurementSpace::Spherical};
    h.process = {q_, 3, NoiseKind::StandardDeviation, dim::acceleration, NoiseAxes::Enu};  // Singer sigma_m
    return h;
  }

  StateLayout layout() const override { return ConstantAcceleration::state_layout(); }

 private:
  enum Counter { kAzimuthDropped };

  bool reset() override {
    points_ = 0;
    last_T_ = -1.0;
    has_frame_ = false;
    zenith_reported_ = false;
    return false;
  }

  void predict(double T) override {
    if (!same_interval(T, last_T_)) {  // fixed-rate data: F and the unit-sigma Q are computed once
      const Eigen::Matrix3d F = SingerModel::axis_transition(s_.alpha, T);
      const Eigen::Matrix3d Q = (2.0 * s_.alpha) * SingerModel::noise_per_psd(s_.alpha, T);
      model_ = {F(0, 1), F(0, 2), F(1, 2), F(2, 2), {Q(0, 0), Q(0, 1), Q(0, 2), Q(1, 1), Q(1, 2), Q(2, 2)}};
      last_T_ = T;
    }
    predict_state(x_, model_);
    // Q in the LOS frame is (D' diag(sigma_a^2) D) ⊗ Q1; with one sigma_m on all axes it is
    // sigma^2 I ⊗ Q1 in every frame (exact). Per-axis values (an adapter) keep its diagonal.
    double s2[3];
    if (q_[0] == q_[1] && q_[1] == q_[2]) {
      s2[0] = s2[1] = s2[2] = q_[0] * q_[0];
    } else {
      for (int i = 0; i < 3; ++i) {
        s2[i] = 0.0;
        for (int a = 0; a < 3; ++a) s2[i] += frame_.u[i][a] * frame_.u[i][a] * q_[a] * q_[a];
      }
    }
    for (int i = 0; i < 3; ++i) predict_axis(B_[i], model_, s2[i]);
  }

  void scale_covariance(double k) override {
    for (auto& B : B_) B = {k * B.pp, k * B.pv, k * B.pa, k * B.vv, k * B.va, k * B.aa};
  }

  // The LOS frame at relative position d. Straight above the sensor the azimuth axis is
  // undefined: the frame is built at a horizontal offset of kZenithFraction r in the previous
  // frame's horizontal direction (east if none) and the azimuth is not used.
  bool frame_at(const Vec3& d, LosFrame<double>& f) const {
    const double rho = std::hypot(d.x(), d.y()), r = d.norm();
    if (rho >= kZenithFraction * r && rho > 0.0) {
      const double dd[3] = {d.x(), d.y(), d.z()};
      line_of_sight_frame(dd, azimuth_, f);
      return false;
    }
    double hx = 1.0, hy = 0.0;
    const double ph = std::hypot(frame_.u[0][0], frame_.u[0][1]);
    if (has_frame_ && ph > 0.0) {
      hx = frame_.u[0][0] / ph;
      hy = frame_.u[0][1] / ph;
    }
    const double floor = kZenithFraction * r;
    const double dd[3] = {hx * floor, hy * floor, d.z()};
    line_of_sight_frame(dd, azimuth_, f);
    return true;
  }

  bool update(const Measurement& m, int dim) override {
    return dim == 4 ? update_values<4>(m) : update_values<3>(m);
  }
  bool predict_measurement(const SensorFrame& s, const MeasCov& R, PredictedMeasurement& p) const override {
    return predicted_by_update<GainTransformEstimator>(s, R, p);
  }
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<GainTransformEstimator>(*this); }

  template <int M>
  bool update_values(const Measurement& m) {
    const Vec3 d = Vec3(x_[state_index(0, 0)], x_[state_index(1, 0)], x_[state_index(2, 0)]) - m.sensor_position;
    if (!(d.norm() >= kMinRange)) {
      warn("predicted position at the sensor at t=" + std::to_string(m.time) +
           " s: no line of sight to decouple along; measurement not used");
      return false;
    }
    azimuth_ = m.azimuth;
    LosFrame<double> next;
    const bool zenith = frame_at(d, next);
    if (s_.reproject) reframe(B_, frame_.u, next.u);  // P̄ follows the line of sight
    frame_ = next;                                    // (carry: the paper's equations as written)
    has_frame_ = true;

    const double R_diag[3] = {R_(0, 0), R_(1, 1), R_(2, 2)};
    double rbar[3];
    const bool drop_azimuth = measurement_variances(B_, frame_, d.z(), R_diag, kZenithSigmas, rbar) || zenith;
    const bool use[3] = {true, !drop_azimuth, true};
    for (int i = 0; i < 3; ++i)
      if (use[i] && (!(rbar[i] >= 0.0) || !(B_[i].pp + rbar[i] > 0.0) || !std::isfinite(rbar[i]))) {
        warn("measurement variance not usable (negative or non-finite) at t=" + std::to_string(m.time) +
             " s; measurement not used");
        return false;
      }
    if (drop_azimuth) count(kAzimuthDropped);
    if (drop_azimuth && !zenith_reported_) {
      warn("target near the zenith at t=" + std::to_string(m.time) +
           " s: azimuth not used (its linearisation fails over the predicted uncertainty); counted in the summary, "
           "reported once per run");
      zenith_reported_ = true;
    }
    const SphericalVec<3> z = m.value.head<3>();
    SphericalVec<3> nu = spherical_residual<3>(z, SphericalVec<3>(frame_.h[0], frame_.h[1], frame_.h[2]));
    if (drop_azimuth) nu(1) = 0.0;
    const double nu_polar[3] = {nu(0), nu(1), nu(2)};
    decoupled_gain(B_, frame_, rbar, use, result_);
    correct_state(x_, frame_, nu_polar, use, result_);

    Mat3 S = Mat3::Zero();
    for (int i = 0; i < 3; ++i) S(i, i) = result_.s[i] / (frame_.scale[i] * frame_.scale[i]);
    if (drop_azimuth) S(1, 1) = R_(1, 1) > 0.0 ? R_(1, 1) : 1.0;
    accept_update<3>(nu, S, result_.nis);
    return true;
  }

  // Paper 002 §4 2): the state from the first two measurements (position = the second converted
  // measurement, velocity = difference / T; the paper prints the velocity and acceleration
  // lines swapped), acceleration 0 with variance initial_sigma_acceleration^2. The covariance is
  // two-point differencing (Bar-Shalom, Li & Kirubarajan 2001 §5.5.3) per LOS axis of the
  // second point's frame, where its converted covariance is diagonal.
  bool initiate(const Measurement& m, int) override {
    if (points_ > 0 && m.time == tc_[points_ - 1]) --points_;  // same time stamp: keep the newer one
    const double r = m.value(0), az = m.value(1), el = m.value(2);
    const Mat3 J = spherical_to_enu_jacobian(r, az, el, m.azimuth);
    zc_[points_] = spherical_to_enu(r, az, el, m.azimuth) + m.sensor_position;
    const Mat3 Rc = J * R_.topLeftCorner<3, 3>() * J.transpose();
    Rc_[points_] = 0.5 * (Rc + Rc.transpose());
    tc_[points_] = m.time;
    ++points_;
    if (points_ < 2) return false;
    const double T = tc_[1] - tc_[0];
    azimuth_ = m.azimuth;
    has_frame_ = false;
    frame_at(zc_[1] - m.sensor_position, frame_);
    has_frame_ = true;
    for (int a = 0; a < 3; ++a) {
      x_[state_index(a, 0)] = zc_[1](a);
      x_[state_index(a, 1)] = (zc_[1](a) - zc_[0](a)) / T;
      x_[state_index(a, 2)] = 0.0;
    }
    for (int i = 0; i < 3; ++i) {
      const Vec3 u(frame_.u[i][0], frame_.u[i][1], frame_.u[i][2]);
      const double r1 = u.dot(Rc_[0] * u), r2 = u.dot(Rc_[1] * u);
      B_[i] = {r2, r2 / T, 0.0, (r1 + r2) / (T * T), 0.0, s_.sigma_accel0 * s_.sigma_accel0};
    }
    return true;
  }

  // The published covariance is blkdiag(D) P̄ blkdiag(D)' (enu_covariance()): the ENU covariance
  // the decoupled blocks stand for, in motion.hpp's layout like filter.ekf's Singer state.
  void fill(Estimate& e) const override {
    e.state.resize(9);
    for (int i = 0; i < 9; ++i) e.state(i) = x_[i];
    // Formed in place: a 9x9 Estimate::covariance is 81 contiguous doubles, column-major, as a
    // fixed-size 9x9 is (no copy of a local one).
    e.covariance.resize(9, 9);
    Eigen::Map<Eigen::Matrix<double, 9, 9>> P(e.covariance.data());
    enu_covariance(B_, frame_.u, P);
    constexpr int kIndex[6] = {state_index(0, 0), state_index(1, 0), state_index(2, 0),
                               state_index(0, 1), state_index(1, 1), state_index(2, 1)};
    for (int j = 0; j < 6; ++j) {
      e.enu(j) = x_[kIndex[j]];
      for (int i = 0; i < 6; ++i) e.enu_covariance(i, j) = P(kIndex[i], kIndex[j]);
    }
  }

  GainTransformSettings s_;
  double q_[3] = {};
  double x_[9] = {};
  AxisCov<double> B_[3] = {};
  LosFrame<double> frame_ = {};
  SingerAxis<double> model_ = {};
  UpdateResult<double> result_ = {};
  AzimuthConvention azimuth_ = AzimuthConvention::NorthClockwise;
  double last_T_ = -1.0;
  bool has_frame_ = false, zenith_reported_ = false;
  int points_ = 0;
  Vec3 zc_[2];
  Mat3 Rc_[2];
  double tc_[2] = {};
};

// Paper 002's model is Singer's, alpha 1/s by default.
TransitionChoices transition_choices() { return TransitionChoices::singer_only("1 1/s"); }

// The estimator of one track from the node's parameters (the node and a tracker take it alike).
GainTransformEstimator make_estimator(const Params& p) {
  GainTransformSettings s;
  s.node = p.node();
  s.transition = parse_transition(p, transition_choices());
  s.alpha = s.transition.singer_alpha;
  s.sigma = s.transition.intensity;
  s.sigma_accel0 = p.real_or("initial_sigma_acceleration", s.sigma);
  s.reproject = p.choice<FrameChange>("frame_change") == FrameChange::Reproject;
  return GainTransformEstimator(s);
}

std::unique_ptr<Component> create(const Params& p) {
  return make_single_track_filter("filter.gain_transform", p.node(), make_estimator(p));
}

std::unique_ptr<Estimator> create_estimator(const Params& p) { return std::make_unique<GainTransformEstimator>(make_estimator(p)); }

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.gain_transform";
  d.kind = ComponentKind::Filter;
  d.summary = "Gain-transformation filter (paper 002): Cartesian Singer state on spherical [r, az, el], gains of "
              "three decoupled line-of-sight filters rotated to ENU";
  d.doc =
      "Yun, Kim, Hwang & Lee, 'Structural improvement of the EKF using coordinate transformation' (paper 002). "
      "State [x vx ax y vy ay z vz az] in ENU with the Singer model (one alpha for all axes, sigma_m per axis; exact "
      "discretisation). The covariance is kept as three 3x3 blocks [position, velocity, acceleration] along the "
      "line-of-sight axes x0 (range), y0 (horizontal, azimuth), z0 (elevation) - paper eq 21's decoupled P0 - and "
      "re-expressed in the new frame at each update (frame_change: reproject) or carried unchanged (carry). Each "
      "axis is a 3-state filter measuring its own position with variance sigma_r^2, (r cos el sigma_az)^2, "
      "(r sigma_el)^2 (eq 18-22); the ENU gain on the polar innovation is K = blkdiag(D) K0 (eq 35, F(X) G0(X) = D "
      "with the cos el the paper omits). Innovation in [r, az, el] with the azimuth wrapped to (-pi, pi]; the range "
      "rate, if present, is ignored. Published covariance: blkdiag(D) P0 blkdiag(D)'. Two-point initialisation "
      "from the first two measurements. Invalid measurements: predict only. R (spherical) and sigma_m per ENU axis "
      "exposed to adapters; dropped azimuths are counted in the summary. See docs/filters.md.";
  d.accepts = mask(ItemKind::Measurement);
  d.accepts_frames = mask(Frame::Spherical);
  d.produces = mask(ItemKind::Estimate);
  d.params = transition_param_specs(transition_choices());
  d.params.insert(d.params.end(), {
      ParamSpec::real("initial_sigma_acceleration", dim::acceleration,
                      "initial acceleration std (default: singer_sigma, the stationary prior)")
          .positive(),
      ParamSpec::choice<FrameChange>("frame_change", {{FrameChange::Reproject, "reproject"}, {FrameChange::Carry, "carry"}},
                        "when the line of sight turns: re-express the LOS covariance blocks in the new frame, or "
                        "carry them unchanged (the paper's equations)")
          .def("reproject"),
  });
  d.create = create;
  d.create_estimator = create_estimator;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.gain_transform", trackflow::register_components)
