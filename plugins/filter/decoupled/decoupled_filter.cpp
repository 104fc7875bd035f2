// Purpose: filter.decoupled — paper 001's decoupled CV Kalman filter on converted Cartesian position measurements.
#include "decoupled_cv.hpp"

#include <trackflow/motion.hpp>
#include <trackflow/plugin.hpp>

#include <string>

namespace trackflow {
namespace {

using decoupled::DecoupledCv;

struct DecoupledSettings {
  enum class Noise { Continuous, Discrete } noise = Noise::Continuous;
  double q = 1.0;      // continuous white-acceleration PSD, m2/s3, the same on every axis
  double sigma = 0.0;  // discrete model: std of the piecewise-constant acceleration, m/s2
  bool reproject = true;
  std::string node;
};

class DecoupledFilter final : public Filter {
 public:
  explicit DecoupledFilter(DecoupledSettings s) : s_(s), configured_(std::move(s)) {
    est_.state.resize(6);
    est_.covariance.resize(6, 6);
    est_.innovation.resize(3);
    est_.innovation_covariance.resize(3, 3);
    R_ = MeasCov::Zero(3, 3);
  }

  NoiseHandles noise() override {
    NoiseHandles h;
    h.measurement_noise = &R_;
    h.process_noise = s_.noise == DecoupledSettings::Noise::Continuous ? &s_.q : &s_.sigma;
    h.process_noise_count = 1;
    h.measurement_space = "cartesian_position";
    return h;
  }

  void start_run(const RunContext& ctx) override {
    // Adapters may have retuned the noise during the previous run on this instance; every run
    // starts from the configured values, or results would depend on which thread ran what.
    s_.q = configured_.q;
    s_.sigma = configured_.sigma;
    diag_ = ctx.diagnostics;
    points_ = 0;
    last_T_ = -1.0;
    last_q_ = -1.0;
    f_ = DecoupledCv{};
  }

  void on_measurement(const Measurement& m, int) override {
    if (m.frame != Frame::Cartesian)
      throw DataError("filter.decoupled (node '" + s_.node +
                      "') needs Cartesian position measurements; put a convert.* node (e.g. convert.classical) "
                      "between the radar and it");
    if (points_ >= 2 && m.time < time_) {
      if (diag_) diag_->skip(s_.node, "measurement at t=" + std::to_string(m.time) + " s is older than the track (t=" +
                                          std::to_string(time_) + " s)");
      return;
    }
    R_ = m.covariance.topLeftCorner(3, 3);
    before_update(m);  // adapters may replace R_ (and q)
    if (points_ < 2) {
      initialise(m);
      return;
    }
    predict(m.time);
    est_.updated = false;
    if (m.valid) {
      const Vec3 z = m.value.head<3>();
      Mat3 next = f_.D;
      if (decoupled::line_of_sight_frame(z - m.sensor_position, next)) {
        if (s_.reproject)
          f_.reframe(next);
        else
          f_.D = next;  // paper as written: P̄ carried over unchanged into the new frame
      }
      const Mat3 R = R_;
      if (f_.update(z, R, result_)) {
        est_.updated = true;
        est_.innovation = result_.innovation;
        est_.innovation_covariance = result_.innovation_covariance;
        est_.nis = result_.nis;
      } else if (diag_) {
        diag_->warn(s_.node, "measurement noise R is not a covariance (negative or non-finite variance in the "
                             "line-of-sight frame) at t=" + std::to_string(m.time) + " s; measurement not used");
      }
    }
    fill_estimate(m.time);
    publish(m, est_);
  }

 private:
  void predict(double t) {
    const double T = t - time_;
    const double q = s_.noise == DecoupledSettings::Noise::Continuous ? s_.q : s_.sigma;
    if (T > 0.0) {
      if (T != last_T_ || q != last_q_) {  // an adapter may retune q between steps
        Q_axis_ = s_.noise == DecoupledSettings::Noise::Continuous ? ConstantVelocity::axis_noise_continuous(T, q)
                                                                   : ConstantVelocity::axis_noise_discrete(T, q);
        last_T_ = T;
        last_q_ = q;
      }
      f_.predict(T, Q_axis_);
    }
    time_ = t;
  }

  void initialise(const Measurement& m) {
    const Vec3 z = m.value.head<3>();
    const Mat3 R = R_;
    if (points_ == 0 || !m.valid) {
      if (m.valid) remember_first(m, z, R);
      publish_uninitialised(m);
      return;
    }
    const double T = m.time - t1_;
    if (T <= 0.0) {  // same time stamp: restart from the newer point
      remember_first(m, z, R);
      publish_uninitialised(m);
      return;
    }
    Mat3 frame = f_.D;
    decoupled::line_of_sight_frame(z - m.sensor_position, frame);
    f_.initialise(z1_, R1_, z, R, T, frame);
    time_ = m.time;
    points_ = 2;
    est_.updated = false;
    fill_estimate(m.time);
    publish(m, est_);
  }

  void remember_first(const Measurement& m, const Vec3& z, const Mat3& R) {
    z1_ = z;
    R1_ = R;
    t1_ = m.time;
    points_ = 1;
  }

  void publish_uninitialised(const Measurement& m) {
    set_uninitialised(est_, m.time);
    publish(m, est_);
  }

  void fill_estimate(double t) {
    est_.time = t;
    est_.initialised = true;
    f_.cartesian_covariance(P_);
    est_.state = f_.x;
    est_.covariance = P_;
    for (int a = 0; a < 3; ++a) {
      idx_[a] = decoupled::pos(a);
      idx_[a + 3] = decoupled::vel(a);
    }
    for (int i = 0; i < 6; ++i) {
      est_.enu(i) = f_.x(idx_[i]);
      for (int j = 0; j < 6; ++j) est_.enu_covariance(i, j) = P_(idx_[i], idx_[j]);
    }
  }

  DecoupledSettings s_;
  DecoupledSettings configured_;  // s_ as configured; s_.q and s_.sigma may be retuned by adapters
  DecoupledCv f_;
  decoupled::UpdateResult result_;
  decoupled::Mat2 Q_axis_ = decoupled::Mat2::Zero();
  Mat6 P_ = Mat6::Zero();
  MeasCov R_;
  Estimate est_;
  Diagnostics* diag_ = nullptr;
  double time_ = 0.0, last_T_ = -1.0, last_q_ = -1.0;
  int points_ = 0;
  Vec3 z1_ = Vec3::Zero();
  Mat3 R1_ = Mat3::Zero();
  double t1_ = 0.0;
  int idx_[6] = {};
};

std::unique_ptr<Component> create(const Params& p) {
  DecoupledSettings s;
  s.node = p.node();
  if (p.given("sigma_accel") && p.given("q"))
    throw p.error("sigma_accel", "give either the continuous-noise intensity q or sigma_accel, not both");
  if (p.given("sigma_accel")) {
    s.noise = DecoupledSettings::Noise::Discrete;
    s.sigma = p.real("sigma_accel");
  } else {
    s.q = p.real("q");
  }
  s.reproject = p.text("frame_change") == "reproject";
  return std::make_unique<DecoupledFilter>(s);
}

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
  d.produces = mask(ItemKind::Estimate);
  d.params = {
      ParamSpec::real("q", dim::accel_psd, "spectral density of the white acceleration noise, every axis").def("1 m2/s3").at_least(0),
      ParamSpec::real("sigma_accel", dim::acceleration,
                      "discrete white-noise model instead (paper eq 16-17): std of the acceleration, every axis")
          .at_least(0),
      ParamSpec::choice("frame_change", {"reproject", "carry"},
                        "when the line of sight turns: re-express the per-axis covariances in the new frame, or carry "
                        "them over unchanged as the paper writes it")
          .def("reproject"),
  };
  d.create = create;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.decoupled", trackflow::register_components)
