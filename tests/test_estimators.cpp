// Purpose: the per-track estimator contract (estimator.hpp) held by every filter type that declares one: predict_measurement agrees with the update it predicts, clone() runs on identically, the estimator alone gives what its filter node publishes, and the Cartesian ones name their transition model, declared by the one block.
#include <trackflow/geometry.hpp>
#include <trackflow/rng.hpp>
#include <trackflow/single_track_filter.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <cmath>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

// A target at ~20 km, climbing and turning gently, measured every 0.1 s by a radar at the
// origin: spherical [r, az, el] (north-clockwise) or the same points in ENU.
std::vector<Measurement> track(Frame frame, int steps) {
  Rng rng(7);
  std::vector<Measurement> out;
  for (int k = 0; k < steps; ++k) {
    const double t = 0.1 * k;
    const Vec3 p(15000.0 + 200.0 * t, 12000.0 - 50.0 * t + 2.0 * t * t, 3000.0 + 20.0 * t);
    Measurement m;
    m.time = t;
    m.frame = frame;
    m.origin = 0;
    if (frame == Frame::Spherical) {
      const double r = p.norm(), az = std::atan2(p.x(), p.y()), el = std::asin(p.z() / r);
      const Vec3 sigma(10.0, 1e-3, 1e-3);
      m.value = Vec3(r + sigma(0) * rng.normal(), wrap_angle(az + sigma(1) * rng.normal()), el + sigma(2) * rng.normal());
      m.covariance = Vec3(sigma.array().square()).asDiagonal();
    } else if (frame == Frame::Polar) {  // a 2-D radar: [r, az] of the target's ground position
      const double r = std::hypot(p.x(), p.y()), az = std::atan2(p.x(), p.y());
      m.value = Eigen::Vector2d(r + 10.0 * rng.normal(), wrap_angle(az + 1e-3 * rng.normal()));
      m.covariance = Eigen::Vector2d(100.0, 1e-6).asDiagonal();
    } else if (frame == Frame::Planar) {
      m.value = Eigen::Vector2d(p.x() + 20.0 * rng.normal(), p.y() + 20.0 * rng.normal());
      m.covariance = MeasCov::Identity(2, 2) * 400.0;
    } else {
      m.value = p + 20.0 * Vec3(rng.normal(), rng.normal(), rng.normal());
      m.covariance = MeasCov::Identity(3, 3) * 400.0;
    }
    out.push_back(m);
  }
  return out;
}

// What an estimator reports, collected as a single-track node would.
struct Track final : TrackContext {
  void warn(const std::string& w) override { warnings.push_back(w); }
  void count(int) override {}
  void annotate(int, double) override {}
  Estimate e;
  std::vector<std::string> warnings;
};

struct Case {
  std::string type, params;
  Frame frame;
  // An IMM with a constant-velocity mode among modes with acceleration: its published acceleration
  // is borrowed from the accelerating modes (imm_mixing.hpp, combine), not a Gaussian mixture's.
  bool borrowed_acceleration = false;
};

const std::vector<Case>& cases() {
  static const std::vector<Case> c = {
      {"filter.kalman", "{q: 1 m2/s3}", Frame::Cartesian},
      {"filter.kalman", "{motion: constant_acceleration}", Frame::Cartesian},
      {"filter.decoupled", "{}", Frame::Cartesian},
      {"filter.ekf", "{}", Frame::Spherical},
      {"filter.ekf", "{motion: constant_acceleration}", Frame::Spherical},
      {"filter.ukf", "{}", Frame::Spherical},
      {"filter.ekf_spherical", "{}", Frame::Spherical},
      {"filter.gain_transform", "{singer_alpha: 1 1/s, singer_sigma: 20 m/s2}", Frame::Spherical},
      {"filter.imm", "{modes: [{motion: constant_velocity, q: 1 m2/s3}, {motion: constant_acceleration, q_jerk: 100 m2/s5}], transition: [0.95, 0.05, 0.05, 0.95]}", Frame::Spherical, true},
      {"filter.imm", "{modes: [{motion: constant_acceleration}, {motion: singer, singer_alpha: 1 1/s, singer_sigma: 20 m/s2}], transition: [0.9, 0.1, 0.1, 0.9]}", Frame::Spherical},
      {"filter.refraction_ekf", "{}", Frame::Spherical},
      // The 2-D frames (SDK 0.7): a 2-D radar's polar plots, a planar sensor's x-y ones.
      {"filter.ekf", "{}", Frame::Polar},
      {"filter.kalman", "{q: 1 m2/s3}", Frame::Planar},
      // filter.imm's component form (modes given as nested filters), unequal and equal state sizes.
      {"filter.imm", "{modes: [{type: filter.ekf, motion: constant_velocity, q: 1 m2/s3}, {type: filter.ukf, motion: constant_acceleration, q_jerk: 100 m2/s5}], transition: [0.95, 0.05, 0.05, 0.95]}", Frame::Spherical, true},
      {"filter.imm", "{modes: [{type: filter.ekf, motion: constant_acceleration}, {type: filter.ukf, motion: singer, singer_alpha: 1 1/s, singer_sigma: 20 m/s2}], transition: [0.9, 0.1, 0.1, 0.9]}", Frame::Spherical},
  };
  return c;
}

// Runs `e` over `ms` as the single-track node does (initiate until formed, then predict and
// update), calling `before(m)` before and `after(m, used)` after every update once formed.
template <class Before, class After>
void run(Estimator& e, Track& t, const std::vector<Measurement>& ms, Before&& before, After&& after) {
  e.bind(t);
  t.estimate = &t.e;
  bool formed = e.reset();
  double last = 0.0;
  for (const Measurement& m : ms) {
    const double T = m.time - last;
    last = t.time = m.time;
    e.measurement_noise() = m.covariance;
    const int dim = static_cast<int>(m.value.size());
    if (!formed) {
      formed = e.initiate(m, dim);
      continue;
    }
    if (T > 0.0) e.predict(T);
    before(m);
    t.e.updated = false;
    const bool used = e.update(m, dim);
    after(m, used);
  }
}

}  // namespace

TEST_CASE("every filter with an estimator is covered") {
  std::vector<std::string> declared;
  for (const auto& r : test::registry().types())
    if (r.decl.create_estimator && r.decl.type.rfind("filter.", 0) == 0) declared.push_back(r.decl.type);
  for (const std::string& type : declared) {
    bool covered = false;
    for (const Case& c : cases()) covered = covered || c.type == type;
    INFO(type);
    CHECK(covered);
  }
  CHECK(declared.size() >= 8);
}

// predict_measurement gives the z^, S and log det S of the update that follows it.
TEST_CASE("predicted measurement is what the update uses") {
  for (const Case& c : cases()) {
    INFO(c.type << " " << c.params);
    auto e = test::fixture().make_estimator(c.type, c.params);
    Track t;
    PredictedMeasurement p;
    bool predicted = false;
    int checked = 0;
    run(
        *e, t, track(c.frame, 60),
        [&](const Measurement& m) {
          predicted = e->predict_measurement(m, m.covariance, p);
          // Twice: predicting changes nothing.
          PredictedMeasurement again;
          if (predicted) {
            REQUIRE(e->predict_measurement(m, m.covariance, again));
            CHECK(again.log_det_S == p.log_det_S);
          }
        },
        [&](const Measurement& m, bool used) {
          if (!predicted || !used) return;
          ++checked;
          const MeasVec& nu = t.e.innovation;
          const MeasCov& S = t.e.innovation_covariance;
          REQUIRE(nu.size() == p.z.size());
          REQUIRE(S.rows() == p.S.rows());
          // log det S against an independent factorisation.
          CHECK(p.log_det_S == Approx(std::log(Eigen::MatrixXd(p.S).determinant())).epsilon(1e-9));
          // NIS and det S do not depend on the axes an update works in (filter.decoupled updates
          // in the line-of-sight frame of each measurement): compared for every estimator.
          const Eigen::MatrixXd Sd = S;
          const Eigen::VectorXd nud = nu;
          CHECK(std::log(Sd.determinant()) == Approx(p.log_det_S).epsilon(1e-8));
          MeasVec r = m.value.head(p.z.size()) - p.z;
          wrap_residual(c.frame, r);
          const Eigen::VectorXd rd = r;
          const Eigen::MatrixXd Sp = p.S;
          CHECK(rd.dot(Sp.ldlt().solve(rd)) == Approx(nud.dot(Sd.ldlt().solve(nud))).epsilon(1e-7));
          CHECK(t.e.nis == Approx(nud.dot(Sd.ldlt().solve(nud))).epsilon(1e-8));
          if (c.type == "filter.decoupled") return;
          // In the measurement's own axes: nu = z - z^ (azimuth wrapped) and the same S.
          for (int i = 0; i < r.size(); ++i) CHECK(nu(i) == Approx(r(i)).epsilon(1e-9).margin(1e-9));
          for (int i = 0; i < S.rows(); ++i)
            for (int j = 0; j < S.cols(); ++j) CHECK(p.S(i, j) == Approx(S(i, j)).epsilon(1e-9).margin(1e-12));
        });
    CHECK(checked > 40);
  }
}

TEST_CASE("a clone runs on exactly as its original") {
  for (const Case& c : cases()) {
    INFO(c.type << " " << c.params);
    auto e = test::fixture().make_estimator(c.type, c.params);
    const auto ms = track(c.frame, 60);
    const std::vector<Measurement> first(ms.begin(), ms.begin() + 30), rest(ms.begin() + 30, ms.end());
    Track t;
    run(*e, t, first, [](const Measurement&) {}, [](const Measurement&, bool) {});
    std::unique_ptr<Estimator> copy = e->clone();
    Track tc = t;
    copy->bind(tc);
    tc.estimate = &tc.e;
    for (const Measurement& m : rest) {
      const double T = m.time - t.time;
      for (auto* pair : {&t, &tc}) pair->time = m.time;
      e->measurement_noise() = copy->measurement_noise() = m.covariance;
      e->predict(T);
      copy->predict(T);
      const int dim = static_cast<int>(m.value.size());
      REQUIRE(e->update(m, dim) == copy->update(m, dim));
    }
    Estimate a, b;
    e->fill(a);
    copy->fill(b);
    CHECK(a.state == b.state);
    CHECK(a.covariance == b.covariance);
    CHECK(t.e.nis == tc.e.nis);
  }
}

TEST_CASE("the estimator alone gives what its node publishes") {
  for (const Case& c : cases()) {
    INFO(c.type << " " << c.params);
    auto node = test::make(c.type, c.params);
    auto& filter = dynamic_cast<Filter&>(*node);
    test::Collector out;
    out.attach_to(filter);
    test::start_run(filter);
    const auto ms = track(c.frame, 40);
    for (const Measurement& m : ms) filter.on_measurement(m, 0);
    auto e = test::fixture().make_estimator(c.type, c.params);
    Track t;
    std::vector<Estimate> alone;
    run(*e, t, ms, [](const Measurement&) {}, [&](const Measurement&, bool) {
      Estimate x;
      e->fill(x);
      alone.push_back(x);
    });
    REQUIRE(!alone.empty());
    REQUIRE(out.estimates.size() >= alone.size());
    const Estimate& last_node = out.estimates.back();
    CHECK(last_node.state == alone.back().state);
    CHECK(last_node.covariance == alone.back().covariance);
    CHECK(filter.state_layout().dim == e->layout().dim);
  }
}

// The estimators with a Cartesian kinematic state name the transition model they predict with
// (a fusion node predicts their estimates with it), as their parameters give it; the others
// (spherical state, paper-specific states, a mixture of modes) name none.
TEST_CASE("estimators name the transition model of their parameters") {
  using Motion = TransitionModel::Motion;
  using Noise = TransitionModel::Noise;
  struct Expected {
    std::string type, params;
    bool has;
    Motion motion;
    Noise noise;
    double intensity;
  };
  const std::vector<Expected> expected = {
      {"filter.kalman", "{q: 2 m2/s3}", true, Motion::ConstantVelocity, Noise::Continuous, 2.0},
      {"filter.kalman", "{motion: constant_acceleration, sigma_accel: 3 m/s2}", true, Motion::ConstantAcceleration,
       Noise::Discrete, 3.0},
      {"filter.decoupled", "{q: 4 m2/s3}", true, Motion::ConstantVelocity, Noise::Continuous, 4.0},
      {"filter.ekf", "{motion: constant_acceleration, q_jerk: 5 m2/s5}", true, Motion::ConstantAcceleration,
       Noise::Continuous, 5.0},
      {"filter.ukf", "{motion: singer, singer_alpha: 0.5 1/s, singer_sigma: 6 m/s2}", true, Motion::Singer, Noise::Singer, 6.0},
      {"filter.gain_transform", "{singer_sigma: 7 m/s2}", true, Motion::Singer, Noise::Singer, 7.0},
      {"filter.ekf_spherical", "{}", false, Motion::ConstantVelocity, Noise::Continuous, 0.0},
      {"filter.refraction_ekf", "{}", false, Motion::ConstantVelocity, Noise::Continuous, 0.0},
      {"filter.imm", cases()[8].params, false, Motion::ConstantVelocity, Noise::Continuous, 0.0},
  };
  for (const Expected& x : expected) {
    INFO(x.type << " " << x.params);
    auto e = test::fixture().make_estimator(x.type, x.params);
    const TransitionModel* t = e->transition_model();
    REQUIRE((t != nullptr) == x.has);
    if (!t) continue;
    CHECK(t->motion == x.motion);
    CHECK(t->noise == x.noise);
    CHECK(t->intensity == x.intensity);
  }
  // gain_transform's Singer alpha defaults to paper 002's 1/s; ukf's is the one given.
  CHECK(test::fixture().make_estimator("filter.gain_transform", "{singer_sigma: 7 m/s2}")->transition_model()->singer_alpha == 1.0);
  CHECK(test::fixture()
            .make_estimator("filter.ukf", "{motion: singer, singer_alpha: 0.5 1/s, singer_sigma: 6 m/s2}")
            ->transition_model()
            ->singer_alpha == 0.5);
}

// The motion block is declared once (transition_model.hpp): every filter that offers a motion
// parameter declares each of the block's parameters with the same dimension and text.
TEST_CASE("filters declare the one transition-model block") {
  const std::vector<ParamSpec> block = transition_param_specs();
  int users = 0;
  for (const char* type : {"filter.kalman", "filter.decoupled", "filter.ekf", "filter.ukf", "filter.gain_transform",
                           "filter.track_fusion"}) {
    INFO(type);
    const ComponentDecl* d = nullptr;
    for (const auto& r : test::registry().types())
      if (r.decl.type == type) d = &r.decl;
    REQUIRE(d);
    bool uses = false;
    for (const ParamSpec& mine : d->params)
      for (const ParamSpec& ref : block) {
        if (mine.name != ref.name) continue;
        uses = true;
        CHECK(mine.type == ref.type);
        CHECK(mine.dimension == ref.dimension);
        if (mine.name != "motion" && mine.name != "sigma_accel") CHECK(mine.doc == ref.doc);
      }
    users += uses;
  }
  CHECK(users == 6);
}

// The one-point start (Estimator::initiate_one_point): position and its covariance from the
// measurement (converted for a radar), velocity 0 with variance velocity_sigma^2 per axis, no
// position-velocity cross term; the estimators without it say so.
TEST_CASE("one-point starts: at rest with the velocity prior") {
  for (const Case& c : cases()) {
    INFO(c.type << " " << c.params << " frame " << int(c.frame));
    auto e = test::fixture().make_estimator(c.type, c.params);
    const bool can = c.type == "filter.kalman" || c.type == "filter.ekf" || c.type == "filter.ukf";
    CHECK(e->starts_from_one_point() == can);
    if (!can) continue;
    Track t;
    e->bind(t);
    t.estimate = &t.e;
    const Measurement m = track(c.frame, 1).front();
    e->reset();
    e->measurement_noise() = m.covariance;
    REQUIRE(e->initiate_one_point(m, static_cast<int>(m.value.size()), 30.0));
    Estimate x;
    e->fill(x);
    const Vec3 p = measured_position(m);
    CHECK((x.enu.head<3>() - p).norm() < 1e-9 * p.norm());
    CHECK(x.enu.tail<3>().isZero());
    const bool planar = c.frame == Frame::Polar || c.frame == Frame::Planar;
    for (int a = 0; a < 3; ++a) {
      CHECK(x.enu_covariance(3 + a, 3 + a) == Approx(planar && a == 2 ? 0.0 : 900.0));
      for (int b = 0; b < 3; ++b) CHECK(x.enu_covariance(a, 3 + b) == 0.0);
    }
    const Mat3 Rp = measured_position_covariance(m, m.covariance);
    CHECK((x.enu_covariance.topLeftCorner<3, 3>() - Rp).norm() < 1e-9 * Rp.norm());
  }
}

// The combined update of probabilistic association (Estimator::update_weighted): the moment-matched
// mixture of the prediction and of each candidate's own update, checked against clones updated one
// detection each and, for filter.kalman, against the textbook PDA equations with H written out
// (Bar-Shalom, Willett & Tian 2011, eq. 3.4.2-1 to 3.4.2-4).
TEST_CASE("weighted updates: the mixture of the candidates' updates") {
  int covered = 0;
  for (const Case& c : cases()) {
    auto e = test::fixture().make_estimator(c.type, c.params);
    if (!e->takes_weighted_updates()) continue;
    ++covered;
    INFO(c.type << " " << c.params << " " << to_string(c.frame));
    const auto ms = track(c.frame, 40);
    Track t;
    run(*e, t, std::vector<Measurement>(ms.begin(), ms.begin() + 30), [](const Measurement&) {},
        [](const Measurement&, bool) {});
    const Measurement& next = ms[30];
    t.time = next.time;
    e->predict(next.time - ms[29].time);
    // Three candidates around the next measurement (a few sigma apart), and their probabilities.
    std::vector<Measurement> cand(3, next);
    const int dim = static_cast<int>(next.value.size());
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < dim; ++a) cand[static_cast<size_t>(k)].value(a) += (k - 1) * 2.0 * std::sqrt(next.covariance(a, a)) * (a % 2 ? -1 : 1);
    const std::vector<double> p = {0.3, 0.45, 0.15};
    const double none = 0.1;
    Estimate predicted;
    if (c.type == "filter.imm") {
      // An IMM's prediction is its modes' predictions with the predicted mode probabilities
      // c_j = sum_i pi_ij mu_i; its fill() after predict() combines them with the last posterior
      // mu instead (what a coasting track publishes, kept as it was for hard association). The
      // share of "none" is then the weighted update's own limit: one candidate of vanishing
      // probability (the none share's mode probabilities are checked in test_imm_pda.cpp).
      auto limit = e->clone();
      Track tl;
      tl.time = t.time;
      tl.estimate = &tl.e;
      limit->bind(tl);
      const std::vector<Measurement> one = {next};
      REQUIRE(limit->update_weighted(one, std::vector<double>{1e-200}, 1.0, dim));
      limit->fill(predicted);
    } else {
      e->fill(predicted);
    }
    // Independent: each candidate's update on its own clone, mixed here.
    const int n = static_cast<int>(predicted.state.size());
    Eigen::VectorXd mean = none * Eigen::VectorXd(predicted.state);
    std::vector<Eigen::VectorXd> xs;
    std::vector<Eigen::MatrixXd> Ps;
    for (int k = 0; k < 3; ++k) {
      auto one = e->clone();
      Track tk;
      tk.time = t.time;
      tk.estimate = &tk.e;
      one->bind(tk);
      one->measurement_noise() = next.covariance;
      REQUIRE(one->update(cand[static_cast<size_t>(k)], dim));
      Estimate u;
      one->fill(u);
      xs.emplace_back(u.state);
      Ps.emplace_back(u.covariance);
      mean += p[static_cast<size_t>(k)] * xs.back();
    }
    Eigen::MatrixXd cov = none * (Eigen::MatrixXd(predicted.covariance) +
                                  (Eigen::VectorXd(predicted.state) - mean) * (Eigen::VectorXd(predicted.state) - mean).transpose());
    for (int k = 0; k < 3; ++k)
      cov += p[static_cast<size_t>(k)] * (Ps[static_cast<size_t>(k)] + (xs[static_cast<size_t>(k)] - mean) * (xs[static_cast<size_t>(k)] - mean).transpose());
    t.e.updated = false;
    REQUIRE(e->update_weighted(cand, p, none, dim));
    Estimate mixed;
    e->fill(mixed);
    // With a borrowed acceleration (a CV mode among accelerating ones), the IMM's combined
    // estimate is the modes' mixture in position and velocity only: its acceleration entries
    // follow the accelerating modes, weighted within each candidate's posterior, so they are not
    // linear in the candidates' weights. Exact there, compared there.
    auto compared = [&](int i) { return !c.borrowed_acceleration || i % 3 != 2; };
    for (int i = 0; i < n; ++i) {
      if (!compared(i)) continue;
      CHECK(mixed.state(i) == Approx(mean(i)).epsilon(1e-10).margin(1e-9));
      for (int j = 0; j < n; ++j)
        if (compared(j)) CHECK(mixed.covariance(i, j) == Approx(cov(i, j)).epsilon(1e-9).margin(1e-9));
    }
    CHECK((mixed.covariance - mixed.covariance.transpose()).cwiseAbs().maxCoeff() == 0.0);
    // PSD (a planar track's z rows are zero: semi-definite).
    CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Eigen::MatrixXd(mixed.covariance)).eigenvalues().minCoeff() >= -1e-9 * mixed.covariance.norm());
    CHECK(t.e.updated);  // the combined innovation is published
    CHECK(t.e.innovation.size() == dim);

    if (c.type == "filter.kalman" && c.frame == Frame::Cartesian && c.params == "{q: 1 m2/s3}") {
      // The textbook PDA with H selecting [x y z] of [x vx y vy z vz]: x = x^ + K nu_bar,
      // P = b0 P^ + (1 - b0) (P^ - K S K') + K (sum b nu nu' - nu_bar nu_bar') K'.
      Eigen::MatrixXd H = Eigen::MatrixXd::Zero(3, n);
      for (int a = 0; a < 3; ++a) H(a, 2 * a) = 1.0;
      const Eigen::MatrixXd P0 = predicted.covariance;
      const Eigen::VectorXd x0 = predicted.state;
      const Eigen::MatrixXd S = H * P0 * H.transpose() + Eigen::MatrixXd(next.covariance);
      const Eigen::MatrixXd K = P0 * H.transpose() * S.inverse();
      Eigen::VectorXd nu_bar = Eigen::VectorXd::Zero(3);
      Eigen::MatrixXd spread = Eigen::MatrixXd::Zero(3, 3);
      for (int k = 0; k < 3; ++k) {
        const Eigen::VectorXd nu = Eigen::VectorXd(cand[static_cast<size_t>(k)].value) - H * x0;
        nu_bar += p[static_cast<size_t>(k)] * nu;
        spread += p[static_cast<size_t>(k)] * nu * nu.transpose();
      }
      spread -= nu_bar * nu_bar.transpose();
      const Eigen::VectorXd x = x0 + K * nu_bar;
      const Eigen::MatrixXd P = none * P0 + (1.0 - none) * (P0 - K * S * K.transpose()) + K * spread * K.transpose();
      for (int i = 0; i < n; ++i) {
        CHECK(mixed.state(i) == Approx(x(i)).epsilon(1e-10).margin(1e-9));
        for (int j = 0; j < n; ++j) CHECK(mixed.covariance(i, j) == Approx(P(i, j)).epsilon(1e-8).margin(1e-8));
      }
      for (int a = 0; a < 3; ++a) CHECK(t.e.innovation(a) == Approx(nu_bar(a)).epsilon(1e-10).margin(1e-10));
    }
  }
  CHECK(covered >= 11);  // kalman (CV, CA, planar), ekf (spherical, CA, polar), ukf, imm (two records, two components)
}

TEST_CASE("weighted updates: a sure detection is the plain update") {
  for (const Case& c : cases()) {
    auto e = test::fixture().make_estimator(c.type, c.params);
    if (!e->takes_weighted_updates()) continue;
    INFO(c.type << " " << c.params);
    const auto ms = track(c.frame, 35);
    Track t;
    run(*e, t, std::vector<Measurement>(ms.begin(), ms.begin() + 30), [](const Measurement&) {},
        [](const Measurement&, bool) {});
    t.time = ms[30].time;
    e->predict(ms[30].time - ms[29].time);
    auto plain = e->clone();
    Track tp;
    tp.time = t.time;
    tp.estimate = &tp.e;
    plain->bind(tp);
    const int dim = static_cast<int>(ms[30].value.size());
    plain->measurement_noise() = ms[30].covariance;
    REQUIRE(plain->update(ms[30], dim));
    const std::vector<Measurement> one = {ms[30]};
    REQUIRE(e->update_weighted(one, std::vector<double>{1.0}, 0.0, dim));
    Estimate a, b;
    e->fill(a);
    plain->fill(b);
    for (int i = 0; i < a.state.size(); ++i) CHECK(a.state(i) == Approx(b.state(i)).epsilon(1e-12).margin(1e-9));
    CHECK(t.e.nis == Approx(tp.e.nis).epsilon(1e-9));
    // Probability 0 for the only candidate: nothing used, the state is the prediction.
    Estimate before, after;
    e->predict(0.1);
    e->fill(before);
    CHECK_FALSE(e->update_weighted(one, std::vector<double>{0.0}, 1.0, dim));
    e->fill(after);
    CHECK(after.state == before.state);
  }
}

// Estimator::copy_from: a spare made into a copy of another track's estimator runs on exactly as
// that estimator does (as a clone would), and keeps its own binding; where it is not offered it
// says so (false) and the caller clones.
TEST_CASE("copy_from makes a spare run on as its original") {
  int copied = 0;
  for (const Case& c : cases()) {
    INFO(c.type << " " << c.params);
    auto e = test::fixture().make_estimator(c.type, c.params);
    auto spare = test::fixture().make_estimator(c.type, c.params);
    const auto ms = track(c.frame, 60);
    Track t, ts;
    run(*e, t, std::vector<Measurement>(ms.begin(), ms.begin() + 30), [](const Measurement&) {}, [](const Measurement&, bool) {});
    run(*spare, ts, std::vector<Measurement>(ms.begin() + 40, ms.end()), [](const Measurement&) {}, [](const Measurement&, bool) {});
    if (!spare->copy_from(*e)) continue;
    ++copied;
    ts = t;
    ts.estimate = &ts.e;
    for (const Measurement& m : std::vector<Measurement>(ms.begin() + 30, ms.begin() + 40)) {
      const double T = m.time - t.time;
      t.time = ts.time = m.time;
      e->measurement_noise() = spare->measurement_noise() = m.covariance;
      e->predict(T);
      spare->predict(T);
      const int dim = static_cast<int>(m.value.size());
      REQUIRE(e->update(m, dim) == spare->update(m, dim));
    }
    Estimate a, b;
    e->fill(a);
    spare->fill(b);
    CHECK(a.state == b.state);
    CHECK(a.covariance == b.covariance);
    CHECK(ts.e.nis == t.e.nis);  // the spare reported to its own track
  }
  CHECK(copied >= 7);  // filter.kalman, filter.ekf, filter.ukf cases
}
