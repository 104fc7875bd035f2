// Purpose: filter.alpha_beta — example third-party plugin: the classic fixed-gain α-β tracker on each ENU axis.
#include "alpha_beta_gains.hpp"

#include <trackflow/plugin.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

namespace {

using namespace trackflow;

// Variances published for quantities nothing has been measured about yet: finite, so no
// consumer ever meets inf or NaN, and far too large to be mistaken for information.
constexpr double kUnknownPositionVariance = 1e12;  // (1000 km)^2
constexpr double kUnknownVelocityVariance = 1e8;   // (10 km/s)^2

const char* const kAxisName[3] = {"x", "y", "z"};

std::string seconds(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "t = %g s", t);
  return buf;
}

// Per axis: predict x̂⁻ = x + T v, residual r = z − x̂⁻, x = x̂⁻ + α r, v = v + (β/T) r, with the
// actual T = t_k − t_{k−1} of each step. Two-point start: the first measurement gives the
// position, the second the velocity by difference. The published covariance is the α-β
// steady state (alpha_beta_gains.hpp) for the measurement's own variance on that axis.
class AlphaBetaFilter final : public Filter {
 public:
  AlphaBetaFilter(alpha_beta::Gains gains, std::string node, SourceLoc where)
      : gains_(gains), node_(std::move(node)), where_(std::move(where)) {
    est_.state.resize(6);
    est_.covariance.resize(6, 6);
    R_ = MeasCov::Zero(3, 3);
  }

  // Adapters may rescale R before each update; the gains themselves are fixed.
  NoiseHandles noise() override {
    NoiseHandles h;
    h.measurement_noise = &R_;
    h.measurement_space = "cartesian_position";
    return h;
  }

  void start_run(const RunContext& ctx) override {
    diagnostics_ = ctx.diagnostics;
    points_ = 0;
    time_ = 0.0;
    position_.setZero();
    velocity_.setZero();
  }

  void on_measurement(const Measurement& m, int) override {
    if (m.frame != Frame::Cartesian)
      throw ConfigError("received a spherical measurement (" + seconds(m.time) +
                            "); filter.alpha_beta needs Cartesian positions: put convert.classical (or another "
                            "convert.* node) between the radar and this node",
                        where_, node_);
    if (points_ > 0 && !(m.time > time_)) {
      warn("measurement at " + seconds(m.time) + " is not later than the track (" + seconds(time_) +
           "); update skipped");
      return;
    }
    if (!m.valid) {
      coast(m);
      return;
    }
    if (m.value.size() < 3 || m.covariance.rows() < 3 || m.covariance.cols() < 3) {
      warn("measurement at " + seconds(m.time) + " has fewer than 3 position elements; skipped");
      return;
    }
    R_ = m.covariance.topLeftCorner(3, 3);
    before_update(m);
    const Vec3 z = m.value.head<3>();
    for (int a = 0; a < 3; ++a) {
      if (!(R_(a, a) > 0.0) || !std::isfinite(R_(a, a)) || !std::isfinite(z(a))) {
        warn("measurement at " + seconds(m.time) + " has a non-finite value or a non-positive variance on " +
             kAxisName[a] + "; skipped");
        return;
      }
    }
    if (points_ == 0) {
      first_point(m, z);
    } else if (points_ == 1) {
      second_point(m, z);
    } else {
      update(m, z);
    }
  }

 private:
  void first_point(const Measurement& m, const Vec3& z) {
    position_ = z;
    velocity_.setZero();
    for (int a = 0; a < 3; ++a) {
      first_variance_(a) = R_(a, a);
      p11_(a) = R_(a, a);
      p12_(a) = 0.0;
      p22_(a) = kUnknownVelocityVariance;
    }
    time_ = m.time;
    points_ = 1;
    publish_without_update(m, false);
  }

  // Two-point differencing: var(x) = σ₂², cov(x, v) = σ₂²/T, var(v) = (σ₁² + σ₂²)/T².
  void second_point(const Measurement& m, const Vec3& z) {
    const double T = m.time - time_;
    velocity_ = (z - position_) / T;
    position_ = z;
    for (int a = 0; a < 3; ++a) {
      const double s2 = R_(a, a);
      p11_(a) = s2;
      p12_(a) = s2 / T;
      p22_(a) = (first_variance_(a) + s2) / (T * T);
    }
    time_ = m.time;
    points_ = 2;
    publish_without_update(m, true);
  }

  void update(const Measurement& m, const Vec3& z) {
    const double T = m.time - time_;
    est_.innovation.resize(3);
    est_.innovation_covariance = MeasCov::Zero(3, 3);
    est_.nis = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double predicted = position_(a) + T * velocity_(a);
      const double r = z(a) - predicted;
      position_(a) = predicted + gains_.alpha * r;
      velocity_(a) += gains_.beta / T * r;
      const alpha_beta::AxisCovariance c = alpha_beta::steady_state_covariance(gains_, T, R_(a, a));
      p11_(a) = c.p11;
      p12_(a) = c.p12;
      p22_(a) = c.p22;
      est_.innovation(a) = r;
      est_.innovation_covariance(a, a) = c.s;
      est_.nis += r * r / c.s;
    }
    time_ = m.time;
    est_.time = m.time;
    est_.updated = true;
    est_.initialised = true;
    fill_estimate();
    publish(m, est_);
  }

  // Invalid measurement: the track moves on without a correction. The α-β model has no process
  // noise, so the covariance grows only by F P F' (an optimistic bound while coasting).
  void coast(const Measurement& m) {
    if (points_ < 2) {
      publish_without_update(m, false);  // nothing to extrapolate yet
      return;
    }
    const double T = m.time - time_;
    position_ += T * velocity_;
    for (int a = 0; a < 3; ++a) {
      p11_(a) += 2.0 * T * p12_(a) + T * T * p22_(a);
      p12_(a) += T * p22_(a);
    }
    time_ = m.time;
    publish_without_update(m, true);
  }

  void publish_without_update(const Measurement& m, bool initialised) {
    if (points_ == 0) {
      // Not even a position yet: publish an estimate that carries no information.
      p11_.setConstant(kUnknownPositionVariance);
      p12_.setZero();
      p22_.setConstant(kUnknownVelocityVariance);
    }
    est_.time = m.time;
    est_.updated = false;
    est_.initialised = initialised;
    est_.innovation.resize(0);
    est_.innovation_covariance.resize(0, 0);
    est_.nis = 0.0;
    fill_estimate();
    publish(m, est_);
  }

  // state [x vx y vy z vz]; enu [x y z vx vy vz]; axes are uncorrelated in the α-β model.
  void fill_estimate() {
    est_.covariance.setZero();
    est_.enu_covariance.setZero();
    for (int a = 0; a < 3; ++a) {
      est_.state(2 * a) = position_(a);
      est_.state(2 * a + 1) = velocity_(a);
      est_.covariance(2 * a, 2 * a) = p11_(a);
      est_.covariance(2 * a, 2 * a + 1) = est_.covariance(2 * a + 1, 2 * a) = p12_(a);
      est_.covariance(2 * a + 1, 2 * a + 1) = p22_(a);
      est_.enu(a) = position_(a);
      est_.enu(a + 3) = velocity_(a);
      est_.enu_covariance(a, a) = p11_(a);
      est_.enu_covariance(a, a + 3) = est_.enu_covariance(a + 3, a) = p12_(a);
      est_.enu_covariance(a + 3, a + 3) = p22_(a);
    }
  }

  void warn(std::string message) {
    if (diagnostics_) diagnostics_->warn(node_, std::move(message));
  }

  const alpha_beta::Gains gains_;
  const std::string node_;
  const SourceLoc where_;
  Diagnostics* diagnostics_ = nullptr;
  int points_ = 0;  // measurements used so far, up to the two the start needs
  double time_ = 0.0;
  Vec3 position_ = Vec3::Zero(), velocity_ = Vec3::Zero();
  Vec3 p11_ = Vec3::Zero(), p12_ = Vec3::Zero(), p22_ = Vec3::Zero();
  Vec3 first_variance_ = Vec3::Zero();
  MeasCov R_;
  Estimate est_;
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
  d.produces = mask(ItemKind::Estimate);
  d.params = {
      ParamSpec::real("alpha", dim::none, "position gain, 0 < alpha < 1; give with beta").def("0.5").at_least(0).at_most(1),
      ParamSpec::real("beta", dim::none, "velocity gain, 0 < beta < 2; give with alpha").def("0.2").at_least(0).at_most(2),
      ParamSpec::real("tracking_index", dim::none,
                      "instead of alpha and beta: Kalata's Lambda = sigma_accel T^2 / sigma_measurement")
          .positive(),
  };
  d.create = [](const Params& p) -> std::unique_ptr<Component> {
    return std::make_unique<AlphaBetaFilter>(gains_from(p), p.node(), p.where());
  };
  r.add(std::move(d));
}

}  // namespace

TRACKFLOW_PLUGIN("filter.alpha_beta", register_components)
