// Purpose: filter.decoupled — paper 001's decoupled CV Kalman filter on converted Cartesian position measurements.
#include "decoupled_cv.hpp"

#include <trackflow/estimate_state.hpp>
#include <trackflow/single_track_filter.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/transition_model.hpp>

#include <string>

namespace trackflow {
namespace {

using decoupled::DecoupledCv;

enum class FrameChange { Reproject, Carry };

struct DecoupledSettings {
  TransitionModel transition;  // as configured (constant velocity); q and noise below are what adapters retune
  enum class Noise { Continuous, Discrete } noise = Noise::Continuous;
  double q = 1.0;  // continuous: white-acceleration PSD, m2/s3; discrete: its std, m/s2 (every axis)
  bool reproject = true;
  std::string node;
};

// The estimator of one track; the filter node around it is the SDK's SingleTrackFilter (single_track_filter.hpp).
class DecoupledEstimator final : public Estimator {

 public:
  explicit DecoupledEstimator(DecoupledSettings s)
      : Estimator(MeasurementSpec{mask(Frame::Cartesian), RangeRateUse::Ignore, {}}),
        s_(std::move(s)) {
    for (int a = 0; a < 3; ++a) {
      idx_[a] = decoupled::pos(a);
      idx_[a + 3] = decoupled::vel(a);
    }
  }

  NoiseHandles noise() override {
    NoiseHandles h;
    h.measurement = {&R_, MeasurementSpace::CartesianPosition};
    h.process.values = &s_.q;
    h.process.count = 1;
    h.process.axes = NoiseAxes::Common;
    const bool continuous = s_.noise == DecoupledSettings::Noise::Continuous;
    h.process.kind = continuous ? NoiseKind::SpectralDensity : NoiseKind::StandardDeviation;
    h.process.dimension = continuous ? dim::accel_psd : dim::acceleration;
    return h;
  }

  const TransitionModel* transition_model() const override { return &s_.transition; }
  StateLayout layout() const override {
    static constexpr StateComponent kLayout[] = {{"x", "m"}, {"vx", "m/s"}, {"y", "m"},
                                                 {"vy", "m/s"}, {"z", "m"}, {"vz", "m/s"}};
    return {kLayout, 6};
  }

 private:
  bool reset() override {
    has_first_ = false;
    last_T_ = -1.0;
    last_q_ = -1.0;
    f_ = DecoupledCv{};
    return false;
  }

  void predict(double T) override {
    const double q = s_.q;
    if (!same_interval(T, last_T_) || q != last_q_) {  // an adapter may retune q between steps
      Q_axis_ = s_.noise == DecoupledSettings::Noise::Continuous ? ConstantVelocity::axis_noise_continuous(T, q)
                                                                 : ConstantVelocity::axis_noise_discrete(T, q);
      last_T_ = T;
      last_q_ = q;
    }
    f_.predict(T, Q_axis_);
  }

  bool update(const Measurement& m, int dim) override {
    return dim == 4 ? update_values<4>(m) : update_values<3>(m);
  }
  bool predict_measurement(const SensorFrame& s, const MeasCov& R, PredictedMeasurement& p) const override {
    return predicted_by_update<DecoupledEstimator>(s, R, p);
  }
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<DecoupledEstimator>(*this); }

  template <int M>
  bool update_values(const Measurement& m) {
    const Vec3 z = m.value.head<3>();
    Mat3 next = f_.D;
    if (decoupled::line_of_sight_frame(z - m.sensor_position, next)) {
      if (s_.reproject)
        f_.reframe(next);
      else
        f_.D = next;  // paper as written: P̄ carried over unchanged into the new frame
    }
    const Mat3 R = R_.topLeftCorner(3, 3);
    if (f_.update(z, R, result_)) {
      accept_update<3>(result_.innovation, result_.innovation_covariance, result_.nis);
      return true;
    }
    warn("measurement noise R is not a covariance (negative or non-finite variance in the line-of-sight frame) at "
         "t=" + std::to_string(m.time) + " s; measurement not used");
    return false;
  }

  void scale_covariance(double k) override {
    for (auto& B : f_.P) B *= k;
  }

  bool initiate(const Measurement& m, int) override {
    const Vec3 z = m.value.head<3>();
    const Mat3 R = R_.topLeftCorner(3, 3);
    const double T = m.time - t1_;
    if (!has_first_ || T <= 0.0) {  // first point, or a newer one with the same time stamp
      z1_ = z;
      R1_ = R;
      t1_ = m.time;
      has_first_ = true;
      return false;
    }
    Mat3 frame = f_.D;
    decoupled::line_of_sight_frame(z - m.sensor_position, frame);
    f_.initialise(z1_, R1_, z, R, T, frame);
    return true;
  }

  void fill(Estimate& e) const override {
    f_.cartesian_covariance(P_);
    set_estimate_state(e, f_.x, P_, idx_);
  }

  DecoupledSettings s_;
  DecoupledCv f_;
  decoupled::UpdateResult result_;
  decoupled::Mat2 Q_axis_ = decoupled::Mat2::Zero();
  mutable Mat6 P_ = Mat6::Zero();  // fill's ENU covariance (fill is const: a product, no state)
  double last_T_ = -1.0, last_q_ = -1.0;
  bool has_first_ = false;
  Vec3 z1_ = Vec3::Zero();
  Mat3 R1_ = Mat3::Zero();
  double t1_ = 0.0;
  int idx_[6] = {};
};

// The estimator of one track from the node's parameters (the node and a tracker take it alike).
DecoupledEstimator make_estimator(const Params& p) {
  DecoupledSettings s;
  s.node = p.node();
  s.transition = parse_transition(p, TransitionChoices::constant_velocity_only());
  s.noise = s.transition.noise == TransitionModel::Noise::Discrete ? DecoupledSettings::Noise::Discrete
                                                                    : DecoupledSettings::Noise::Continuous;
  s.q = s.transition.intensity;
  s.reproject = p.choice<FrameChange>("frame_change") == FrameChange::Reproject;
  return DecoupledEstimator(s);
}

std::unique_ptr<Component> create(const Params& p) {
  return make_single_track_filter("filter.decoupled", p.node(), make_estimator(p));
}

std::unique_ptr<Estimator> create_estimator(const Params& p) { return std::make_unique<DecoupledEstimator>(make_estimator(p)); }

const char* const kDoc =
    "Paper 001 eq 21-27 (Kim & Hwang 2013, after Fitzgerald 1985). State [x vx y vy z vz] in ENU, constant "
    "velocity; measurements: converted Cartesian positions from any convert.* node. The gain is K = D2 Kbar D' "
    "(eq 26; D2 = blkdiag(D, D) in eq 27's [x y z vx vy vz] order), where D = [u_r u_az u_el] is the orthonormal "
    "line-of-sight frame at the measured position relative to the measurement's sensor_position (the exact "
    "Jacobian of the spherical-to-Cartesian map with its angle columns divided by r cos(el) and r; classical "
    "converted covariances are diagonal in it), and Kbar holds three independent 2-state gains, one per "
    "line-of-sight axis, computed from that axis' 2x2 covariance block and the variance (D' R D)_ii. The filter "
    "propagates only these three 2x2 blocks (Pbar, eq 22/24, Joseph form per axis); it publishes the ENU "
    "covariance D2 Pbar D2'. Exact (identical to filter.kalman) when R is diagonal in the line-of-sight frame "
    "and that frame does not turn; otherwise the off-diagonal terms of D' R D are ignored, and when the line of "
    "sight turns Pbar is re-expressed in the new frame keeping its block diagonal (frame_change: reproject) or, "
    "as the paper writes it, carried over unchanged (carry). Process noise must be the same on all axes (that is "
    "what lets the prediction run in any frame): continuous white acceleration q [[T^3/3, T^2/2], [T^2/2, T]] or, "
    "with sigma_accel, paper eq 16-17's discrete sigma^2 G G', G = [T^2/2, T]. Two-point initialisation; invalid "
    "measurements: predict only (coast). R comes from each measurement's covariance; adapters (e.g. "
    "adapt.innovation_r) may replace it (measurement space cartesian_position).";

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.decoupled";
  d.kind = ComponentKind::Filter;
  d.summary = "Decoupled CV Kalman filter (paper 001): three 2-state gains in the line-of-sight frame, state in ENU";
  d.doc = kDoc;
  d.accepts = mask(ItemKind::Measurement);
  d.accepts_frames = mask(Frame::Cartesian);
  d.produces = mask(ItemKind::Estimate);
  d.params = transition_param_specs(TransitionChoices::constant_velocity_only());
  d.params.push_back(
      ParamSpec::choice<FrameChange>("frame_change", {{FrameChange::Reproject, "reproject"}, {FrameChange::Carry, "carry"}},
                        "when the line of sight turns: re-express the per-axis covariances in the new frame, or carry "
                        "them over unchanged as the paper writes it")
          .def("reproject"));
  d.create = create;
  d.create_estimator = create_estimator;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.decoupled", trackflow::register_components)
