// Purpose: filter.kalman — linear Kalman filter on Cartesian position measurements with CV or CA motion.
#include <trackflow/estimate_state.hpp>
#include <trackflow/single_track_filter.hpp>
#include <trackflow/kalman.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/transition_model.hpp>

#include <cmath>
#include <limits>
#include <vector>

namespace trackflow {
namespace {

enum class Init { TwoPoint, Explicit };

struct KalmanSettings {
  TransitionModel transition;  // as configured; q and noise below are what adapters may retune
  enum class Noise { Continuous, Discrete } noise = Noise::Continuous;
  double q = 1.0;  // continuous: PSD of the highest derivative (CV m2/s3, CA m2/s5); discrete: its std
  bool two_point = true;
  bool constant_acceleration = false;
  Vec3 p0 = Vec3::Zero(), v0 = Vec3::Zero(), a0 = Vec3::Zero();
  double sp0 = 0, sv0 = 0, sa0 = 0;  // initial standard deviations
};

// State [x vx (ax) y vy (ay) z vz (az)]: Model::kOrder states per axis (motion.hpp). The
// estimator of one track (estimator.hpp); the filter node around it is the SDK's
// SingleTrackFilter (single_track_filter.hpp).
template <class Model>
class KalmanEstimator final : public Estimator {
  static constexpr int N = Model::kDim;
  using StateN = typename Model::State;
  using MatN = typename Model::Matrix;

 public:
  static constexpr int kStateDim = N;  // fill()'s state size: the node's non-finite check is fixed-size
  explicit KalmanEstimator(KalmanSettings s)
      : Estimator(MeasurementSpec{mask(Frame::Cartesian) | mask(Frame::Planar), RangeRateUse::Ignore, {}}),
        s_(std::move(s)) {}
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<KalmanEstimator>(*this); }

  const TransitionModel* transition_model() const override { return &s_.transition; }
  NoiseHandles noise() override {
    NoiseHandles h;
    h.measurement = {&R_, MeasurementSpace::CartesianPosition};
    h.process.values = &s_.q;
    h.process.count = 1;
    h.process.axes = NoiseAxes::Common;
    if (s_.noise == KalmanSettings::Noise::Continuous) {
      h.process.kind = NoiseKind::SpectralDensity;
      h.process.dimension = Model::kOrder == 3 ? dim::jerk_psd : dim::accel_psd;
    } else {
      h.process.kind = NoiseKind::StandardDeviation;
      h.process.dimension = dim::acceleration;
    }
    return h;
  }

  StateLayout layout() const override { return Model::state_layout(); }

  bool reset() override {
    has_first_ = false;
    planar_ = false;
    independent_axes_ = true;  // explicit: P diagonal; two-point: set by initialise
    if (s_.two_point) return false;
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
    return true;  // the explicit state holds at the first measurement's time
  }

  void predict(double T) override {
    if (!same_interval(T, last_T_)) {  // fixed-rate data: the unit-intensity Q is computed once per T
      unit_Q_ = s_.noise == KalmanSettings::Noise::Continuous ? Model::axis_noise_continuous(T, 1.0)
                                                               : Model::axis_noise_discrete(T, 1.0);
      last_T_ = T;
    }
    // Scaled every step: an adapter may have changed q (or sigma) since the last one.
    const double scale = s_.noise == KalmanSettings::Noise::Continuous ? s_.q : s_.q * s_.q;
    Model::propagate(T, x_);
    Model::propagate_covariance(T, P_);
    for (int a = 0; a < (planar_ ? 2 : 3); ++a)
      P_.template block<Model::kOrder, Model::kOrder>(a * Model::kOrder, a * Model::kOrder) += scale * unit_Q_;
  }

  // H selects the three positions, so P H' is three columns of P and H P H' their position rows:
  // the Joseph-form update from them (kalman.hpp, joseph_update_cross) needs no H and no 6x6x6
  // products. When R is diagonal and P has no cross-axis terms (independent_axes_), the three
  // axes are three independent filters on scalar measurements: the same update, per axis.
  bool update(const Measurement& m, int) override {
    // range_rate: ignore makes every measurement its positions: 3, or x and y of a planar one.
    return m.frame == Frame::Planar ? update_position<2>(m) : update_position<3>(m);
  }

  // z^ = H x (the positions the sensor measures), S = H P H' + R: those rows and columns of P.
  bool predict_measurement(const SensorFrame& s, const MeasCov& R, PredictedMeasurement& p) const override {
    const int k = position_values(s.frame);
    if (R.rows() != k || R.cols() != k) return false;
    p.z.resize(k);
    p.S.resize(k, k);
    for (int a = 0; a < k; ++a) {
      p.z(a) = x_(Model::position_index(a));
      for (int b = 0; b < k; ++b) p.S(a, b) = P_(Model::position_index(a), Model::position_index(b)) + R(a, b);
    }
    return set_log_det(p);
  }

  void scale_covariance(double k) override { P_ *= k; }

  // Two-point differencing (Bar-Shalom, Li & Kirubarajan 2001, §5.5.3): position from the
  // second point, velocity from the difference; covariance from the two R's. A second point
  // with the same time stamp replaces the first. A track started from planar (x, y) points lives
  // in the plane z = 0: z, vz (az) are 0 with zero variance and get no process noise, so the
  // sensor's plane is the track's (its z is never updated).
  bool initiate(const Measurement& m, int) override {
    const bool planar = m.frame == Frame::Planar;
    const Vec3 z = measured_position(m);
    const Mat3 R = measured_position_covariance(m, R_);  // a planar point: zero z row and column
    if (has_first_ && planar != first_planar_) has_first_ = false;  // a planar and a 3-D point do not pair
    const double T = m.time - t1_;
    if (!has_first_ || T <= 0.0) {
      z1_ = z;
      R1_ = R;
      t1_ = m.time;
      has_first_ = true;
      first_planar_ = planar;
      return false;
    }
    planar_ = planar;
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
      if constexpr (Model::kOrder == 3)
        if (!(planar && a == 2)) P_(a * 3 + 2, a * 3 + 2) = s_.sa0 * s_.sa0;
    }
    P_ = 0.5 * (P_ + P_.transpose()).eval();
    // Diagonal R at both points: no cross-axis terms in P (exactly zero, not merely small).
    independent_axes_ = diagonal(R) && diagonal(R1_);
    return true;
  }

  // One-point start: position the measurement's, P_pp its R; velocity 0 with variance
  // velocity_sigma^2 per axis (none on z for a planar point), CA acceleration 0 with
  // initial_sigma_acceleration; no cross terms between position and velocity.
  bool starts_from_one_point() const override { return true; }
  bool initiate_one_point(const Measurement& m, int, double velocity_sigma) override {
    const bool planar = m.frame == Frame::Planar;
    const Vec3 z = measured_position(m);
    const Mat3 R = measured_position_covariance(m, R_);  // a planar point: zero z row and column
    x_.setZero();
    P_.setZero();
    for (int a = 0; a < 3; ++a) {
      const int p = Model::position_index(a), v = Model::velocity_index(a);
      x_(p) = z(a);
      for (int b = 0; b < 3; ++b) P_(p, Model::position_index(b)) = R(a, b);
      if (!(planar && a == 2)) P_(v, v) = velocity_sigma * velocity_sigma;
      if constexpr (Model::kOrder == 3)
        if (!(planar && a == 2)) P_(a * 3 + 2, a * 3 + 2) = s_.sa0 * s_.sa0;
    }
    planar_ = planar;
    has_first_ = false;
    independent_axes_ = diagonal(R);
    return true;
  }

  void fill(Estimate& e) const override { set_estimate_state(e, x_, P_, kEnuIndex); }
  // A state from outside (an IMM's mixed start, a PDA's combined posterior): it may couple the
  // axes, so the per-axis shortcut is off until the next start.
  bool assign(const StateVec& x, const StateCov& P) override {
    if (x.size() != N || P.rows() != N || P.cols() != N) return false;
    x_ = x.template head<N>();
    P_ = P.template topLeftCorner<N, N>();
    independent_axes_ = false;
    return true;
  }
  bool takes_weighted_updates() const override { return true; }
  bool copy_from(const Estimator& other) override { return copy_by_assignment<KalmanEstimator>(other); }

 private:

  // K positions measured: 3, or x and y (planar).
  template <int K>
  bool update_position(const Measurement& m) {
    using VecK = Eigen::Matrix<double, K, 1>;
    using MatK = Eigen::Matrix<double, K, K>;
    const VecK z = m.value.template head<K>();
    const MatK R = R_.template topLeftCorner<K, K>();
    VecK nu;
    for (int a = 0; a < K; ++a) nu(a) = z(a) - x_(Model::position_index(a));
    MatK S;
    double nis = 0.0;
    bool ok;
    if (independent_axes_ && diagonal<K>(R)) {
      ok = update_per_axis<K>(nu, R, S, nis);
    } else {
      independent_axes_ = false;  // cross-axis terms from here on
      Eigen::Matrix<double, N, K> PHt;
      for (int a = 0; a < K; ++a) PHt.col(a) = P_.col(Model::position_index(a));
      for (int a = 0; a < K; ++a)
        for (int b = 0; b < K; ++b) S(a, b) = PHt(Model::position_index(a), b) + R(a, b);
      ok = joseph_update_cross<N, K>(x_, P_, nu, PHt, S, nis);
    }
    if (ok) {
      accept_update<K>(nu, S, nis);
      return true;
    }
    warn("innovation covariance not positive definite at t=" + std::to_string(m.time) +
               " s; measurement not used");
    return false;
  }

  template <int K>
  static bool diagonal(const Eigen::Matrix<double, K, K>& A) {
    if constexpr (K == 2) {
      return A(0, 1) == 0.0 && A(1, 0) == 0.0;
    } else {
      return A(0, 1) == 0.0 && A(0, 2) == 0.0 && A(1, 2) == 0.0 && A(1, 0) == 0.0 && A(2, 0) == 0.0 && A(2, 1) == 0.0;
    }
  }

  // P block-diagonal per axis and R diagonal: each axis block is updated with its own position,
  // exactly the update above with the zero cross terms left out.
  template <int K>
  bool update_per_axis(const Eigen::Matrix<double, K, 1>& nu, const Eigen::Matrix<double, K, K>& R,
                       Eigen::Matrix<double, K, K>& S, double& nis) {
    constexpr int O = Model::kOrder;
    for (int a = 0; a < K; ++a)
      if (!(P_(a * O, a * O) + R(a, a) > 0.0)) return false;  // x, P untouched, as the full update
    S.setZero();
    nis = 0.0;
    for (int a = 0; a < K; ++a) {
      Eigen::Matrix<double, O, 1> xa = x_.template segment<O>(a * O);
      typename Model::AxisMatrix Pa = P_.template block<O, O>(a * O, a * O);
      const Eigen::Matrix<double, O, 1> PHt = Pa.col(0);
      Eigen::Matrix<double, 1, 1> s, nu_a;
      s(0, 0) = Pa(0, 0) + R(a, a);
      nu_a(0) = nu(a);
      double nis_a = 0.0;
      joseph_update_cross<O, 1>(xa, Pa, nu_a, PHt, s, nis_a);
      x_.template segment<O>(a * O) = xa;
      P_.template block<O, O>(a * O, a * O) = Pa;
      S(a, a) = s(0, 0);
      nis += nis_a;
    }
    return true;
  }


  KalmanSettings s_;
  StateN x_ = StateN::Zero();
  MatN P_ = MatN::Identity();
  typename Model::AxisMatrix unit_Q_ = Model::AxisMatrix::Zero();
  double last_T_ = -1.0;
  bool has_first_ = false;
  bool first_planar_ = false;  // the first point was planar (x, y)
  bool planar_ = false;        // the track lives in z = 0: no z process noise
  // P has no cross-axis terms (R diagonal so far): F, Q and a diagonal-R update keep it so.
  bool independent_axes_ = true;
  Vec3 z1_ = Vec3::Zero();
  Mat3 R1_ = Mat3::Zero();
  double t1_ = 0.0;
  // State indices of [x y z vx vy vz]: compile-time constants, so fill() picks out the ENU block
  // with fixed loads instead of loading each index (a gather of 42 entries per estimate).
  static constexpr int kEnuIndex[6] = {Model::position_index(0), Model::position_index(1), Model::position_index(2),
                                       Model::velocity_index(0), Model::velocity_index(1), Model::velocity_index(2)};
};

// filter.kalman's models: constant velocity or acceleration, continuous or discrete noise (no Singer).
TransitionChoices transition_choices() {
  TransitionChoices c;
  c.singer = false;
  return c;
}

KalmanSettings parse_settings(const Params& p) {
  KalmanSettings s;
  s.transition = parse_transition(p, transition_choices());
  const bool ca = s.transition.motion == TransitionModel::Motion::ConstantAcceleration;
  s.noise = s.transition.noise == TransitionModel::Noise::Discrete ? KalmanSettings::Noise::Discrete
                                                                    : KalmanSettings::Noise::Continuous;
  s.q = s.transition.intensity;
  s.two_point = p.choice<Init>("init") == Init::TwoPoint;
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
  s.constant_acceleration = ca;
  return s;
}

std::unique_ptr<Component> create(const Params& p) {
  const KalmanSettings s = parse_settings(p);
  if (s.constant_acceleration)
    return std::make_unique<SingleTrackFilter<KalmanEstimator<ConstantAcceleration>>>(
        "filter.kalman", p.node(), KalmanEstimator<ConstantAcceleration>(s));
  return std::make_unique<SingleTrackFilter<KalmanEstimator<ConstantVelocity>>>(
      "filter.kalman", p.node(), KalmanEstimator<ConstantVelocity>(s));
}

std::unique_ptr<Estimator> create_estimator(const Params& p) {
  const KalmanSettings s = parse_settings(p);
  if (s.constant_acceleration) return std::make_unique<KalmanEstimator<ConstantAcceleration>>(s);
  return std::make_unique<KalmanEstimator<ConstantVelocity>>(s);
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.kalman";
  d.kind = ComponentKind::Filter;
  d.summary = "Linear Kalman filter on Cartesian (x, y, z) or planar (x, y) position measurements; constant-velocity or constant-acceleration motion";
  d.doc =
      "State [x vx (ax) y vy (ay) z vz (az)] in ENU. Process noise: continuous white noise on the highest "
      "derivative (CV: q [[T^3/3, T^2/2], [T^2/2, T]], CA: Wiener-process acceleration, paper 000 eq 3.19) or, "
      "with sigma_accel, the discrete white-noise model (sigma^2 G G'). Joseph-form update (per axis while R is diagonal). Invalid measurements: "
      "predict only (coast). Measurement noise R from each measurement's covariance; adapters may replace it. Planar (x, y) "
      "measurements: H selects x and y; a track started from two planar points lives in the plane z = 0 (z, vz, az zero "
      "with zero variance, no z process noise); with init: explicit the z axis is predicted but never updated.";
  d.accepts = mask(ItemKind::Measurement);
  d.accepts_frames = mask(Frame::Cartesian) | mask(Frame::Planar);
  d.produces = mask(ItemKind::Estimate);
  d.params = transition_param_specs(transition_choices());
  d.params.insert(d.params.end(), {
      ParamSpec::choice<Init>("init", {{Init::TwoPoint, "two_point"}, {Init::Explicit, "explicit"}},
                              "two-point differencing or the initial_* values")
          .def("two_point"),
      ParamSpec::real_list("initial_position", dim::length, "init explicit: position", 3),
      ParamSpec::real_list("initial_velocity", dim::velocity, "init explicit: velocity", 3).def("[0, 0, 0]"),
      ParamSpec::real_list("initial_acceleration", dim::acceleration, "init explicit, CA: acceleration", 3).def("[0, 0, 0]"),
      ParamSpec::real("initial_sigma_position", dim::length, "init explicit: position std").positive(),
      ParamSpec::real("initial_sigma_velocity", dim::velocity, "init explicit: velocity std").positive(),
      ParamSpec::real("initial_sigma_acceleration", dim::acceleration, "CA: initial acceleration std (both inits)")
          .def("50 m/s2")
          .positive(),
  });
  d.create = create;
  d.create_estimator = create_estimator;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.kalman", trackflow::register_components)
