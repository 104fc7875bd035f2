// Purpose: filter.kalman — linear Kalman filter on Cartesian position measurements with CV or CA motion.
#include <trackflow/kalman.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/plugin.hpp>

#include <cmath>
#include <limits>

namespace trackflow {
namespace {

struct KalmanSettings {
  enum class Noise { Continuous, Discrete } noise = Noise::Continuous;
  double q = 1.0;            // continuous PSD of the highest derivative (CV: m2/s3, CA: m2/s5)
  double sigma = 0.0;        // discrete model: std of the piecewise-constant highest derivative
  bool two_point = true;
  Vec3 p0 = Vec3::Zero(), v0 = Vec3::Zero(), a0 = Vec3::Zero();
  double sp0 = 0, sv0 = 0, sa0 = 0;  // initial standard deviations
  std::string node;
};

// State [x vx (ax) y vy (ay) z vz (az)]: Model::kOrder states per axis (motion.hpp).
template <class Model>
class KalmanFilter final : public Filter {
  static constexpr int N = Model::kDim;
  using StateN = typename Model::State;
  using MatN = typename Model::Matrix;
  using Mat3N = Eigen::Matrix<double, 3, N>;

 public:
  explicit KalmanFilter(KalmanSettings s) : s_(s), configured_(std::move(s)) {
    H_.setZero();
    for (int a = 0; a < 3; ++a) H_(a, Model::position_index(a)) = 1.0;
    // Published before initialisation too (initialised = false): keep it defined.
    est_.state = StateN::Zero();
    est_.covariance = MatN::Zero();
    est_.enu.setZero();
    est_.enu_covariance.setZero();
    est_.innovation.resize(3);
    est_.innovation_covariance.resize(3, 3);
    R_ = MeasCov::Zero(3, 3);
  }

  NoiseHandles noise() override {
    NoiseHandles h;
    h.measurement_noise = &R_;
    h.process_noise = s_.noise == KalmanSettings::Noise::Continuous ? &s_.q : &s_.sigma;
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
    have_time_ = false;
    if (!s_.two_point) {
      x_.setZero();
      P_.setZero();
      for (int a = 0; a < 3; ++a) {
        x_(Model::position_index(a)) = s_.p0(a);
        x_(Model::velocity_index(a)) = s_.v0(a);
        P_(Model::position_index(a), Model::position_index(a)) = s_.sp0 * s_.sp0;
        P_(Model::velocity_index(a), Model::velocity_index(a)) = s_.sv0 * s_.sv0;
        if constexpr (Model::kOrder == 3) {
          x_(a * 3 + 2) = s_.a0(a);
          P_(a * 3 + 2, a * 3 + 2) = s_.sa0 * s_.sa0;
        }
      }
      points_ = 2;
      have_time_ = false;  // the explicit state holds at the first measurement's time
    }
  }

  void on_measurement(const Measurement& m, int) override {
    if (m.frame != Frame::Cartesian)
      throw DataError("filter.kalman (node '" + s_.node +
                      "') needs Cartesian position measurements; put a convert.* node between the radar and it");
    if (points_ >= 2 && have_time_ && m.time < time_) {
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
      const Vec3 nu = m.value.template head<3>() - H_ * x_;
      Mat3 S;
      double nis = 0.0;
      const Mat3 R = R_;
      if (joseph_update<N, 3>(x_, P_, nu, H_, R, S, nis)) {
        est_.updated = true;
        est_.innovation = nu;
        est_.innovation_covariance = S;
        est_.nis = nis;
      } else if (diag_) {
        diag_->warn(s_.node, "innovation covariance not positive definite at t=" + std::to_string(m.time) +
                                 " s; measurement not used");
      }
    }
    fill_estimate(m.time, true);
    publish(m, est_);
  }

 private:
  void predict(double t) {
    const double T = have_time_ ? t - time_ : 0.0;
    if (T > 0.0) {
      if (T != last_T_) {  // fixed-rate data: the unit-intensity Q is computed once per T
        unit_Q_ = s_.noise == KalmanSettings::Noise::Continuous ? Model::axis_noise_continuous(T, 1.0)
                                                                 : Model::axis_noise_discrete(T, 1.0);
        last_T_ = T;
      }
      // Scaled every step: an adapter may have changed q (or sigma) since the last one.
      const double scale = s_.noise == KalmanSettings::Noise::Continuous ? s_.q : s_.sigma * s_.sigma;
      Model::propagate(T, x_);
      Model::propagate_covariance(T, P_);
      for (int a = 0; a < 3; ++a) P_.template block<Model::kOrder, Model::kOrder>(a * Model::kOrder, a * Model::kOrder) += scale * unit_Q_;
    }
    time_ = t;
    have_time_ = true;
  }

  // Two-point differencing (Bar-Shalom, Li & Kirubarajan 2001, §5.5.3): position from the
  // second point, velocity from the difference; covariance from the two R's.
  void initialise(const Measurement& m) {
    const Vec3 z = m.value.template head<3>();
    const Mat3 R = R_;
    if (points_ == 0 || !m.valid) {
      if (m.valid) {
        z1_ = z;
        R1_ = R;
        t1_ = m.time;
        points_ = 1;
      }
      publish_uninitialised(m);
      return;
    }
    const double T = m.time - t1_;
    if (T <= 0.0) {  // same time stamp: restart from the newer point
      z1_ = z;
      R1_ = R;
      t1_ = m.time;
      publish_uninitialised(m);
      return;
    }
    x_.setZero();
    P_.setZero();
    for (int a = 0; a < 3; ++a) {
      const int p = Model::position_index(a), v = Model::velocity_index(a);
      x_(p) = z(a);
      x_(v) = (z(a) - z1_(a)) / T;
      for (int b = 0; b < 3; ++b) {
        const int pb = Model::position_index(b), vb = Model::velocity_index(b);
        P_(p, pb) = R(a, b);
        P_(p, vb) = P_(vb, p) = R(a, b) / T;
        P_(v, vb) = (R(a, b) + R1_(a, b)) / (T * T);
      }
      if constexpr (Model::kOrder == 3) P_(a * 3 + 2, a * 3 + 2) = s_.sa0 * s_.sa0;
    }
    P_ = 0.5 * (P_ + P_.transpose()).eval();
    time_ = m.time;
    have_time_ = true;
    points_ = 2;
    est_.updated = false;
    fill_estimate(m.time, true);
    publish(m, est_);
  }

  void publish_uninitialised(const Measurement& m) {
    set_uninitialised(est_, m.time);
    publish(m, est_);
  }

  void fill_estimate(double t, bool initialised) {
    est_.time = t;
    est_.initialised = initialised;
    est_.state = x_;
    est_.covariance = P_;
    for (int a = 0; a < 3; ++a) {
      idx_[a] = Model::position_index(a);
      idx_[a + 3] = Model::velocity_index(a);
    }
    for (int i = 0; i < 6; ++i) {
      est_.enu(i) = x_(idx_[i]);
      for (int j = 0; j < 6; ++j) est_.enu_covariance(i, j) = P_(idx_[i], idx_[j]);
    }
  }

  KalmanSettings s_;
  KalmanSettings configured_;  // s_ as configured; s_.q and s_.sigma may be retuned by adapters
  StateN x_ = StateN::Zero();
  MatN P_ = MatN::Identity();
  typename Model::AxisMatrix unit_Q_ = Model::AxisMatrix::Zero();
  Mat3N H_;
  MeasCov R_;
  Estimate est_;
  Diagnostics* diag_ = nullptr;
  double time_ = 0.0, last_T_ = -1.0;
  bool have_time_ = false;
  int points_ = 0;
  Vec3 z1_ = Vec3::Zero();
  Mat3 R1_ = Mat3::Zero();
  double t1_ = 0.0;
  int idx_[6] = {};
};

std::unique_ptr<Component> create(const Params& p) {
  KalmanSettings s;
  s.node = p.node();
  const bool ca = p.text("motion") == "constant_acceleration";
  if (p.given("sigma_accel") && (p.given("q") || p.given("q_jerk")))
    throw p.error("sigma_accel", "give either a continuous-noise intensity (q / q_jerk) or sigma_accel, not both");
  if (ca && p.given("q")) throw p.error("q", "q (m2/s3) is the CV intensity; the CA model takes q_jerk (m2/s5)");
  if (!ca && p.given("q_jerk")) throw p.error("q_jerk", "q_jerk is for motion: constant_acceleration; CV takes q");
  if (p.given("sigma_accel")) {
    s.noise = KalmanSettings::Noise::Discrete;
    s.sigma = p.real("sigma_accel");
  } else {
    s.q = ca ? p.real("q_jerk") : p.real("q");
  }
  s.two_point = p.text("init") == "two_point";
  if (!s.two_point) {
    for (const char* req : {"initial_position", "initial_sigma_position", "initial_sigma_velocity"})
      if (!p.has(req)) throw p.error(req, "required with init: explicit");
  }
  if (p.has("initial_position")) s.p0 = p.vec3("initial_position");
  s.v0 = p.vec3("initial_velocity");
  s.a0 = p.vec3("initial_acceleration");
  s.sp0 = p.real_or("initial_sigma_position", 0.0);
  s.sv0 = p.real_or("initial_sigma_velocity", 0.0);
  s.sa0 = p.real("initial_sigma_acceleration");
  if (ca) return std::make_unique<KalmanFilter<ConstantAcceleration>>(s);
  return std::make_unique<KalmanFilter<ConstantVelocity>>(s);
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.kalman";
  d.kind = ComponentKind::Filter;
  d.summary = "Linear Kalman filter on Cartesian position measurements; constant-velocity or constant-acceleration motion";
  d.doc =
      "State [x vx (ax) y vy (ay) z vz (az)] in ENU. Process noise: continuous white noise on the highest "
      "derivative (CV: q [[T^3/3, T^2/2], [T^2/2, T]], CA: Wiener-process acceleration, paper 000 eq 3.19) or, "
      "with sigma_accel, the discrete white-noise model (sigma^2 G G'). Joseph-form update. Invalid measurements: "
      "predict only (coast). Measurement noise R from each measurement's covariance; adapters may replace it.";
  d.accepts = mask(ItemKind::Measurement);
  d.produces = mask(ItemKind::Estimate);
  d.params = {
      ParamSpec::choice("motion", {"constant_velocity", "constant_acceleration"}, "motion model").def("constant_velocity"),
      ParamSpec::real("q", dim::accel_psd, "CV: spectral density of the white acceleration noise").def("1 m2/s3").at_least(0),
      ParamSpec::real("q_jerk", dim::jerk_psd, "CA: spectral density of the white jerk noise (paper 000 eq 3.19)")
          .def("1 m2/s5")
          .at_least(0),
      ParamSpec::real("sigma_accel", dim::acceleration,
                      "discrete white-noise model instead: std of the acceleration (CV) or acceleration increment (CA)")
          .at_least(0),
      ParamSpec::choice("init", {"two_point", "explicit"}, "two-point differencing or the initial_* values").def("two_point"),
      ParamSpec::real_list("initial_position", dim::length, "init explicit: position", 3),
      ParamSpec::real_list("initial_velocity", dim::velocity, "init explicit: velocity", 3).def("[0, 0, 0]"),
      ParamSpec::real_list("initial_acceleration", dim::acceleration, "init explicit, CA: acceleration", 3).def("[0, 0, 0]"),
      ParamSpec::real("initial_sigma_position", dim::length, "init explicit: position std").positive(),
      ParamSpec::real("initial_sigma_velocity", dim::velocity, "init explicit: velocity std").positive(),
      ParamSpec::real("initial_sigma_acceleration", dim::acceleration, "CA: initial acceleration std (both inits)")
          .def("50 m/s2")
          .positive(),
  };
  d.create = create;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.kalman", trackflow::register_components)
