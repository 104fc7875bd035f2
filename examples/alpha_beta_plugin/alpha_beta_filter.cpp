// Purpose: filter.alpha_beta — example third-party plugin: the classic fixed-gain α-β tracker on each ENU axis, as a per-track estimator (a filter node, and what a tracker runs per track).
#include "alpha_beta_gains.hpp"

#include <trackflow/plugin.hpp>
#include <trackflow/single_track_filter.hpp>

#include <cmath>
#include <string>
#include <utility>

namespace {

using namespace trackflow;

// Per axis: predict x̂⁻ = x + T v, residual r = z − x̂⁻, x = x̂⁻ + α r, v = v + (β/T) r, with the
// actual T = t_k − t_{k−1} of each step. Two-point start: the first measurement gives the
// position, the second the velocity by difference. The published covariance is the α-β
// steady state (alpha_beta_gains.hpp) for the measurement's own variance on that axis.
// This class is one track's estimator (trackflow/estimator.hpp). The SDK's SingleTrackFilter
// (single_track_filter.hpp) makes it a filter node and does everything around it: validity and
// frame checks, time order, R from the measurement, adapter hooks, coasting, publishing and
// counting; a multi-target tracker clones it for every track it starts.
class AlphaBetaEstimator final : public Estimator {
 public:
  explicit AlphaBetaEstimator(alpha_beta::Gains gains)
      : Estimator(MeasurementSpec{mask(Frame::Cartesian), RangeRateUse::Ignore, {}}), gains_(gains) {}

  std::unique_ptr<Estimator> clone() const override { return std::make_unique<AlphaBetaEstimator>(*this); }

  // Adapters may replace R before each update; the gains themselves are fixed, so there is no
  // process noise to expose.
  NoiseHandles noise() override {
    NoiseHandles h;
    h.measurement = {&R_, MeasurementSpace::CartesianPosition};
    return h;
  }

  StateLayout layout() const override {
    static constexpr StateComponent kLayout[] = {{"x", "m"}, {"vx", "m/s"}, {"y", "m"},
                                                 {"vy", "m/s"}, {"z", "m"}, {"vz", "m/s"}};
    return {kLayout, 6};
  }

 private:
  bool reset() override {
    has_first_ = false;
    return false;
  }

  // Two-point differencing: var(x) = σ₂², cov(x, v) = σ₂²/T, var(v) = (σ₁² + σ₂²)/T².
  bool initiate(const Measurement& m, int) override {
    const Vec3 z = m.value.head<3>();
    const double T = m.time - first_time_;
    if (!has_first_ || !(T > 0.0)) {
      position_ = z;
      for (int a = 0; a < 3; ++a) first_variance_(a) = R_(a, a);
      first_time_ = m.time;
      has_first_ = true;
      return false;
    }
    velocity_ = (z - position_) / T;
    position_ = z;
    for (int a = 0; a < 3; ++a) {
      const double s2 = R_(a, a);
      p11_(a) = s2;
      p12_(a) = s2 / T;
      p22_(a) = (first_variance_(a) + s2) / (T * T);
    }
    return true;
  }

  // The α-β model has no process noise, so while coasting the covariance grows only by F P F'
  // (an optimistic bound).
  void predict(double T) override {
    T_ = T;
    position_ += T * velocity_;
    for (int a = 0; a < 3; ++a) {
      p11_(a) += 2.0 * T * p12_(a) + T * T * p22_(a);
      p12_(a) += T * p22_(a);
    }
  }

  // z^ = the predicted position; S per axis from the alpha-beta steady state for R's variance.
  bool predict_measurement(const SensorFrame&, const MeasCov& R, PredictedMeasurement& p) const override {
    if (!(T_ > 0.0) || R.rows() != 3) return false;
    p.z = position_;
    p.S = MeasCov::Zero(3, 3);
    for (int a = 0; a < 3; ++a) p.S(a, a) = alpha_beta::steady_state_covariance(gains_, T_, R(a, a)).s;
    return set_log_det(p);
  }

  bool update(const Measurement& m, int) override {
    if (!(T_ > 0.0)) {
      warn("measurement at t=" + std::to_string(m.time) + " s is not later than the track; not used");
      return false;
    }
    const Vec3 z = m.value.head<3>();
    for (int a = 0; a < 3; ++a)
      if (!(R_(a, a) > 0.0)) {
        warn("measurement at t=" + std::to_string(m.time) + " s has a non-positive variance on axis " +
             std::to_string(a) + "; not used");
        return false;
      }
    Vec3 nu, s;
    for (int a = 0; a < 3; ++a) {
      const double r = z(a) - position_(a);  // position_ is already the prediction
      position_(a) += gains_.alpha * r;
      velocity_(a) += gains_.beta / T_ * r;
      const alpha_beta::AxisCovariance c = alpha_beta::steady_state_covariance(gains_, T_, R_(a, a));
      p11_(a) = c.p11;
      p12_(a) = c.p12;
      p22_(a) = c.p22;
      nu(a) = r;
      s(a) = c.s;
    }
    const Mat3 S = s.asDiagonal();
    accept_update<3>(nu, S, nu.cwiseAbs2().cwiseQuotient(s).sum());
    T_ = 0.0;  // the next update needs a prediction (a later time) first
    return true;
  }

  void scale_covariance(double k) override {
    p11_ *= k;
    p12_ *= k;
    p22_ *= k;
  }

  // state [x vx y vy z vz]; enu [x y z vx vy vz]; axes are uncorrelated in the α-β model.
  void fill(Estimate& e) const override {
    e.covariance.setZero();
    e.enu_covariance.setZero();
    for (int a = 0; a < 3; ++a) {
      e.state(2 * a) = position_(a);
      e.state(2 * a + 1) = velocity_(a);
      e.covariance(2 * a, 2 * a) = p11_(a);
      e.covariance(2 * a, 2 * a + 1) = e.covariance(2 * a + 1, 2 * a) = p12_(a);
      e.covariance(2 * a + 1, 2 * a + 1) = p22_(a);
      e.enu(a) = position_(a);
      e.enu(a + 3) = velocity_(a);
      e.enu_covariance(a, a) = p11_(a);
      e.enu_covariance(a, a + 3) = e.enu_covariance(a + 3, a) = p12_(a);
      e.enu_covariance(a + 3, a + 3) = p22_(a);
    }
  }

  const alpha_beta::Gains gains_;
  bool has_first_ = false;
  double first_time_ = 0.0, T_ = 0.0;
  Vec3 position_ = Vec3::Zero(), velocity_ = Vec3::Zero();
  Vec3 p11_ = Vec3::Zero(), p12_ = Vec3::Zero(), p22_ = Vec3::Zero();
  Vec3 first_variance_ = Vec3::Zero();
};

alpha_beta::Gains gains_from(const Params& p) {
  const bool alpha = p.given("alpha"), beta = p.given("beta");
  if (p.given("tracking_index")) {
    if (alpha || beta)
      throw p.error(alpha ? "alpha" : "beta", "give either alpha and beta, or tracking_index, not both");
    const alpha_beta::Gains g = alpha_beta::gains_from_tracking_index(p.real("tracking_index"));
    if (!(g.alpha < 1.0))
      throw p.error("tracking_index", "is so large that alpha rounds to 1 (the filter would ignore its prediction)");
    return g;
  }
  if (alpha && !beta) throw p.error("alpha", "give beta together with alpha (or tracking_index instead of both)");
  if (beta && !alpha) throw p.error("beta", "give alpha together with beta (or tracking_index instead of both)");
  alpha_beta::Gains g{p.real("alpha"), p.real("beta")};
  if (!(g.alpha > 0.0 && g.alpha < 1.0)) throw p.error("alpha", "must lie strictly between 0 and 1");
  if (!(g.beta > 0.0 && g.beta < 2.0)) throw p.error("beta", "must lie strictly between 0 and 2");
  if (!alpha_beta::has_steady_state_covariance(g))
    throw p.error("beta", "must be below 2 alpha^2 / (2 - alpha) = " +
                              std::to_string(alpha_beta::max_beta_for_covariance(g.alpha)) +
                              " for alpha " + std::to_string(g.alpha) +
                              ", or the steady-state covariance is singular or not a covariance at all (Kalata's optimal beta for "
                              "this alpha is 2(2 - alpha) - 4 sqrt(1 - alpha) = " +
                              std::to_string(2.0 * (2.0 - g.alpha) - 4.0 * std::sqrt(1.0 - g.alpha)) + ")");
  return g;
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.alpha_beta";
  d.kind = ComponentKind::Filter;
  d.summary = "Fixed-gain alpha-beta tracker on Cartesian position measurements (example third-party plugin)";
  d.doc =
      "Per ENU axis: x- = x + T v, r = z - x-, x = x- + alpha r, v = v + (beta/T) r, with the actual T of each "
      "step. Two-point start. Gains from alpha and beta, or from Kalata's tracking index "
      "Lambda = sigma_a T^2 / sigma_w (Kalata 1984). Covariance: the alpha-beta steady state for each measurement's "
      "variance (Bar-Shalom, Li & Kirubarajan 2001, 6.5). State [x vx y vy z vz].";
  d.accepts = mask(ItemKind::Measurement);
  d.accepts_frames = mask(Frame::Cartesian);
  d.produces = mask(ItemKind::Estimate);
  d.params = {
      ParamSpec::real("alpha", dim::none, "position gain, 0 < alpha < 1; give with beta").def("0.5").at_least(0).at_most(1),
      ParamSpec::real("beta", dim::none, "velocity gain, 0 < beta < 2; give with alpha").def("0.2").at_least(0).at_most(2),
      ParamSpec::real("tracking_index", dim::none,
                      "instead of alpha and beta: Kalata's Lambda = sigma_accel T^2 / sigma_measurement")
          .positive(),
  };
  // One estimator, two uses: the filter node, and the estimator a tracker runs per track.
  d.create = [](const Params& p) -> std::unique_ptr<Component> {
    return make_single_track_filter("filter.alpha_beta", p.node(), AlphaBetaEstimator(gains_from(p)));
  };
  d.create_estimator = [](const Params& p) -> std::unique_ptr<Estimator> {
    return std::make_unique<AlphaBetaEstimator>(gains_from(p));
  };
  r.add(std::move(d));
}

}  // namespace

TRACKFLOW_PLUGIN("filter.alpha_beta", register_components)
