// Purpose: tests of filter.alpha_beta: gains and covariance against the Kalman Riccati recursion, the recursion by hand, Monte Carlo consistency, errors.
#include "alpha_beta_gains.hpp"

#include <trackflow/rng.hpp>
#include <trackflow/testing/plugin_fixture.hpp>

#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

// The plugins are loaded through the same host code `trackflow run` uses, from the files just
// built, by the fixture installed with the SDK (trackflow/testing/plugin_fixture.hpp).
const testing::PluginFixture& fixture() {
  static const testing::PluginFixture f({ALPHA_BETA_PLUGIN_FILE, FADING_MEMORY_PLUGIN_FILE});
  return f;
}

std::shared_ptr<Component> make(const std::string& yaml_params, const std::string& node = "ab") {
  return fixture().make("filter.alpha_beta", yaml_params, node);
}

using testing::Collector;

Measurement cartesian(double t, const Vec3& z, const Vec3& variance) {
  Measurement m;
  m.time = t;
  m.frame = Frame::Cartesian;
  m.value = z;
  m.covariance = MeasCov::Zero(3, 3);
  m.covariance.diagonal() = variance;
  return m;
}

// Discrete white-noise-acceleration model of one axis: x_{k+1} = F x_k + G a_k, a_k ~ N(0, σ_a²),
// G = [T²/2, T] (Bar-Shalom, Li & Kirubarajan 2001 §6.3.2); position measured with variance σ_w².
struct Dwna {
  Eigen::Matrix2d F, Q;
  explicit Dwna(double T, double sigma_a) {
    F << 1, T, 0, 1;
    const Eigen::Vector2d G(T * T / 2, T);
    Q = sigma_a * sigma_a * G * G.transpose();
  }
};

}  // namespace

// Kalata gains and the steady-state covariance equal the converged Kalman filter of the DWNA model
TEST_CASE("Kalata gains and P equal the steady-state DWNA filter") {
  const double sigma_w = 7.0;
  for (double lambda : {0.05, 0.5, 2.0, 10.0}) {
    for (double T : {0.1, 1.0, 3.0}) {
      CAPTURE(lambda, T);
      const Dwna model(T, lambda * sigma_w / (T * T));  // Λ = σ_a T² / σ_w
      const double R = sigma_w * sigma_w;
      Eigen::Matrix2d P = Eigen::Vector2d(R, 1e6).asDiagonal();
      Eigen::Vector2d K = Eigen::Vector2d::Zero();
      double S = 0;
      for (int k = 0; k < 5000; ++k) {
        const Eigen::Matrix2d Pp = model.F * P * model.F.transpose() + model.Q;
        S = Pp(0, 0) + R;
        K = Pp.col(0) / S;
        P = Pp - K * K.transpose() * S;
      }
      const alpha_beta::Gains g = alpha_beta::gains_from_tracking_index(lambda);
      CHECK(g.alpha == Approx(K(0)).epsilon(1e-9));
      CHECK(g.beta == Approx(K(1) * T).epsilon(1e-9));
      const alpha_beta::AxisCovariance c = alpha_beta::steady_state_covariance(g, T, R);
      CHECK(c.s == Approx(S).epsilon(1e-9));
      CHECK(c.p11 == Approx(P(0, 0)).epsilon(1e-9));
      CHECK(c.p12 == Approx(P(0, 1)).epsilon(1e-9));
      CHECK(c.p22 == Approx(P(1, 1)).epsilon(1e-9));
      CHECK(alpha_beta::has_steady_state_covariance(g));
      CHECK(alpha_beta::error_correlation_squared(g) == Approx(P(0, 1) * P(0, 1) / (P(0, 0) * P(1, 1))).epsilon(1e-6));
    }
  }
}

// gains are accepted exactly where the steady-state covariance is positive definite
TEST_CASE("gains accepted exactly where steady-state P is PD") {
  for (double alpha : {0.05, 0.1, 0.5, 0.9, 0.99}) {
    const double b = alpha_beta::max_beta_for_covariance(alpha);
    for (double beta : {0.5 * b, 0.99 * b, 1.01 * b, 1.5 * b}) {
      CAPTURE(alpha, beta);
      const auto c = alpha_beta::steady_state_covariance({alpha, beta}, 1.0, 1.0);
      const double det = c.p11 * c.p22 - c.p12 * c.p12;
      CHECK((det > 0 && c.p22 > 0) == (beta < b));
      CHECK(alpha_beta::has_steady_state_covariance({alpha, beta}) == (beta < b));
      if (det > 0) CHECK(alpha_beta::error_correlation_squared({alpha, beta}) == Approx(c.p12 * c.p12 / (c.p11 * c.p22)));
    }
  }
  // On the bound itself the covariance is singular: refused even when rounding lands just below.
  CHECK_FALSE(alpha_beta::has_steady_state_covariance({0.4, 0.2}));
  CHECK_FALSE(alpha_beta::has_steady_state_covariance({0.5, alpha_beta::max_beta_for_covariance(0.5)}));
}

// two-point start, then the alpha-beta recursion with the actual time step
TEST_CASE("two-point start then recursion with the actual time step") {
  const double alpha = 0.6, beta = 0.3;
  auto f = make("{alpha: 0.6, beta: 0.3}");
  Collector out;
  out.attach_to(*f);
  Diagnostics diag;
  f->start_run({0, 1, &diag});
  const Vec3 var(4.0, 9.0, 16.0);
  const Vec3 z1(0, 0, 0), z2(10, 20, -5), z3(25, 35, -5);
  f->on_measurement(cartesian(0.0, z1, var), 0);
  f->on_measurement(cartesian(1.0, z2, var), 0);
  f->on_measurement(cartesian(3.0, z3, var), 0);  // T = 2 s
  REQUIRE(out.estimates.size() == 3);
  CHECK_FALSE(out.estimates[0].initialised);
  CHECK(out.estimates[0].enu.head<3>() == Vec3::Zero());  // the SDK publishes no state before initialisation
  CHECK(out.estimates[1].initialised);
  CHECK_FALSE(out.estimates[1].updated);
  CHECK(out.estimates[1].enu.head<3>() == z2);
  CHECK(out.estimates[1].enu.tail<3>() == z2 - z1);
  // Two-point covariance: var(v) = (σ₁² + σ₂²)/T².
  CHECK(out.estimates[1].enu_covariance(4, 4) == Approx(18.0));
  CHECK(out.estimates[1].enu_covariance(1, 4) == Approx(9.0));

  const Vec3 v2 = z2 - z1;
  const Vec3 predicted = z2 + 2.0 * v2;
  const Vec3 r = z3 - predicted;
  const Vec3 x3 = predicted + alpha * r;
  const Vec3 v3 = v2 + beta / 2.0 * r;
  const Estimate& e = out.estimates[2];
  CHECK(e.updated);
  CHECK(e.time == 3.0);
  for (int a = 0; a < 3; ++a) {
    CAPTURE(a);
    CHECK(e.enu(a) == Approx(x3(a)));
    CHECK(e.enu(a + 3) == Approx(v3(a)));
    CHECK(e.state(2 * a) == Approx(x3(a)));
    CHECK(e.state(2 * a + 1) == Approx(v3(a)));
    CHECK(e.innovation(a) == Approx(r(a)));
    CHECK(e.innovation_covariance(a, a) == Approx(var(a) / (1 - alpha)));
    CHECK(e.enu_covariance(a, a) == Approx(alpha * var(a)));
    CHECK(e.enu_covariance(a, a + 3) == Approx(beta / 2.0 * var(a)));
    CHECK(e.covariance(2 * a, 2 * a + 1) == Approx(beta / 2.0 * var(a)));
    CHECK(e.covariance(2 * a + 1, 2 * a + 1) == Approx(e.enu_covariance(a + 3, a + 3)));
  }
  CHECK(e.enu_covariance(0, 1) == 0.0);
  const double nis = (r.array().square() * (1 - alpha) / var.array()).sum();
  CHECK(e.nis == Approx(nis));
  CHECK(diag.warnings.empty());
}

// default gains are alpha 0.5 and beta 0.2 and tracking_index gives the Kalata gains
TEST_CASE("default gains and Kalata gains from tracking_index") {
  struct Case {
    std::string yaml;
    alpha_beta::Gains expected;
  };
  for (const Case& c : {Case{"{}", {0.5, 0.2}}, Case{"{tracking_index: 0.8}", alpha_beta::gains_from_tracking_index(0.8)}}) {
    CAPTURE(c.yaml);
    auto f = make(c.yaml);
    Collector out;
    out.attach_to(*f);
    Diagnostics diag;
    f->start_run({0, 1, &diag});
    f->on_measurement(cartesian(0.0, Vec3(0, 0, 0), Vec3::Ones()), 0);
    f->on_measurement(cartesian(1.0, Vec3(1, 1, 1), Vec3::Ones()), 0);
    f->on_measurement(cartesian(2.0, Vec3(3, 2, 2), Vec3::Ones()), 0);  // residual (1, 0, 0)
    REQUIRE(out.estimates.size() == 3);
    CHECK(out.estimates[2].enu(0) == Approx(2 + c.expected.alpha));
    CHECK(out.estimates[2].enu(3) == Approx(1 + c.expected.beta));
  }
}

// a noiseless constant-velocity target is tracked exactly through irregular steps
TEST_CASE("noiseless CV target tracked exactly over irregular steps") {
  auto f = make("{alpha: 0.3, beta: 0.05}");
  Collector out;
  out.attach_to(*f);
  Diagnostics diag;
  f->start_run({0, 1, &diag});
  const Vec3 p0(1000, -2000, 300), v(-120, 45, 3);
  double t = 0;
  for (double step : {0.0, 0.5, 1.7, 0.1, 3.0, 0.9}) {
    t += step;
    f->on_measurement(cartesian(t, p0 + t * v, Vec3(25, 25, 100)), 0);
  }
  REQUIRE(out.estimates.size() == 6);
  for (size_t k = 1; k < out.estimates.size(); ++k) {
    const Estimate& e = out.estimates[k];
    CHECK((e.enu.head<3>() - (p0 + e.time * v)).norm() < 1e-9);
    CHECK((e.enu.tail<3>() - v).norm() < 1e-9);
  }
}

// Monte Carlo on a DWNA target: errors and NIS agree with the published covariance
TEST_CASE("Monte Carlo DWNA target: errors and NIS match covariance") {
  const double T = 1.0, sigma_w = 10.0, lambda = 0.5, sigma_a = lambda * sigma_w / (T * T);
  const int runs = 1500, steps = 40;
  const Dwna model(T, sigma_a);
  auto f = make("{tracking_index: 0.5}");
  Collector out;
  out.attach_to(*f);
  Rng rng(20240611);
  double pos = 0, vel = 0, nis = 0;  // sums of e²/p over runs and axes, and of NIS
  for (int run = 0; run < runs; ++run) {
    Diagnostics diag;
    out.estimates.clear();
    f->start_run({static_cast<std::uint64_t>(run), 1, &diag});
    Eigen::Matrix<double, 2, 3> x;  // [position; velocity] per axis
    x.row(0).setZero();
    x.row(1) << 100, -50, 10;
    for (int k = 0; k < steps; ++k) {
      if (k > 0) {
        for (int a = 0; a < 3; ++a) {
          const double acc = rng.normal(0, sigma_a);
          x.col(a) = (model.F * x.col(a)).eval() + Eigen::Vector2d(T * T / 2, T) * acc;
        }
      }
      const Vec3 z(x(0, 0) + rng.normal(0, sigma_w), x(0, 1) + rng.normal(0, sigma_w), x(0, 2) + rng.normal(0, sigma_w));
      f->on_measurement(cartesian(k * T, z, Vec3::Constant(sigma_w * sigma_w)), 0);
    }
    REQUIRE(out.estimates.size() == static_cast<size_t>(steps));
    const Estimate& e = out.estimates.back();
    for (int a = 0; a < 3; ++a) {
      pos += std::pow(e.enu(a) - x(0, a), 2) / e.enu_covariance(a, a);
      vel += std::pow(e.enu(a + 3) - x(1, a), 2) / e.enu_covariance(a + 3, a + 3);
    }
    nis += e.nis;
  }
  // Each normalised squared error is χ²(1): mean 1, variance 2; over n = 3·runs samples the
  // mean has standard deviation √(2/n). NIS is χ²(3): mean 3, std of the mean √(6/runs).
  const double n = 3.0 * runs;
  CHECK(std::abs(pos / n - 1.0) < 5 * std::sqrt(2 / n));
  CHECK(std::abs(vel / n - 1.0) < 5 * std::sqrt(2 / n));
  CHECK(std::abs(nis / runs - 3.0) < 5 * std::sqrt(6.0 / runs));
}

TEST_CASE("bad parameters are refused naming the parameter") {
  auto message = [](const std::string& yaml) {
    try {
      make(yaml);
    } catch (const ConfigError& e) {
      return e.message();
    }
    return std::string("no error");
  };
  CHECK_THAT(message("{alpha: 0.4}"), Catch::Contains("'alpha'") && Catch::Contains("beta"));
  CHECK_THAT(message("{beta: 0.1}"), Catch::Contains("'beta'"));
  CHECK_THAT(message("{alpha: 1, beta: 0.5}"), Catch::Contains("'alpha'") && Catch::Contains("between 0 and 1"));
  CHECK_THAT(message("{alpha: 0.5, beta: 0}"), Catch::Contains("'beta'"));
  CHECK_THAT(message("{alpha: 0.2, beta: 1.5}"), Catch::Contains("'beta'") && Catch::Contains("2 alpha^2 / (2 - alpha)"));
  CHECK_THAT(message("{alpha: 0.4, beta: 0.2}"), Catch::Contains("singular"));  // exactly on the bound
  CHECK_THAT(message("{alpha: 0.5, beta: 0.2, tracking_index: 1}"), Catch::Contains("not both"));
  CHECK_THAT(message("{tracking_index: 0}"), Catch::Contains("tracking_index"));
  CHECK_THAT(message("{tracking_index: 1 m}"), Catch::Contains("tracking_index"));
  CHECK(message("{alpha: 0.5, beta: 0.2}") == "no error");
}

TEST_CASE("spherical measurement is a config error naming the node") {
  auto f = make("{}", "my_ab");
  Diagnostics diag;
  f->start_run({0, 1, &diag});
  Measurement m = cartesian(0.0, Vec3(1000, 0.1, 0.02), Vec3::Ones());
  m.frame = Frame::Spherical;
  // The SDK's front end refuses it as a data error naming the filter, the node and the fix.
  CHECK_THROWS_AS(f->on_measurement(m, 0), DataError);
  CHECK_THROWS_WITH(f->on_measurement(m, 0), Catch::Contains("my_ab") && Catch::Contains("convert."));
}

// a time step of zero or less skips the update with a warning and invalid measurements coast
TEST_CASE("non-positive time step skips update and invalid coasts") {
  auto f = make("{}", "ab");
  Collector out;
  out.attach_to(*f);
  Diagnostics diag;
  f->start_run({0, 1, &diag});
  f->on_measurement(cartesian(0.0, Vec3(0, 0, 0), Vec3::Ones()), 0);
  f->on_measurement(cartesian(1.0, Vec3(2, 0, 0), Vec3::Ones()), 0);
  f->on_measurement(cartesian(1.0, Vec3(50, 0, 0), Vec3::Ones()), 0);  // same time: published, not used
  f->on_measurement(cartesian(0.5, Vec3(50, 0, 0), Vec3::Ones()), 0);  // older: skipped by the front end
  REQUIRE(out.estimates.size() == 3);
  CHECK_FALSE(out.estimates[2].updated);
  CHECK(out.estimates[2].enu(0) == 2.0);
  REQUIRE(diag.warnings.size() == 1);
  CHECK(diag.warnings[0].node == "ab");
  CHECK_THAT(diag.warnings[0].message, Catch::Contains("not later"));
  REQUIRE(diag.skips.size() == 1);
  CHECK_THAT(diag.skips[0].message, Catch::Contains("older"));

  Measurement lost = cartesian(2.0, Vec3(0, 0, 0), Vec3::Ones());
  lost.valid = false;
  f->on_measurement(lost, 0);
  REQUIRE(out.estimates.size() == 4);
  const Estimate& e = out.estimates.back();
  CHECK_FALSE(e.updated);
  CHECK(e.innovation.size() == 0);
  CHECK(e.enu(0) == Approx(4.0));  // 2 m + 1 s × 2 m/s
  CHECK(e.enu_covariance(0, 0) > out.estimates[1].enu_covariance(0, 0));
  CHECK(e.enu_covariance.allFinite());
}

// The example adapter rescales the filter's P through the SDK's covariance handle.
TEST_CASE("fading memory scales P by alpha squared before each update") {
  auto f = make("{}", "ab");
  auto a = fixture().make("adapt.fading_memory", "{ alpha: 2 }", "fm");
  auto& filter = dynamic_cast<Filter&>(*f);
  auto& adapter = dynamic_cast<Adapter&>(*a);
  testing::attach(adapter, filter);
  Collector out;
  out.attach_to(*f);
  Diagnostics diag;
  testing::start_run(*f, 0, 1, &diag);
  a->start_run({0, 1, &diag});
  f->on_measurement(cartesian(0.0, Vec3(0, 0, 0), Vec3::Ones()), 0);
  f->on_measurement(cartesian(1.0, Vec3(1, 0, 0), Vec3::Ones()), 0);
  StateCov before;
  filter.read_covariance(before);
  REQUIRE(before.rows() == 6);
  adapter.before_update(cartesian(2.0, Vec3(2, 0, 0), Vec3::Ones()), filter);
  StateCov after;
  filter.read_covariance(after);  // the current P, rescaled by alpha^2 = 4
  CHECK(after(0, 0) == Approx(4.0 * before(0, 0)));
  CHECK(after(1, 3) == Approx(4.0 * before(1, 3)));
  f->on_measurement(cartesian(2.0, Vec3(2, 0, 0), Vec3::Ones()), 0);
  // The adapter ran again inside that step: its annotation is the rescaled position variance.
  REQUIRE(out.estimates.back().annotation_count == 1);
  CHECK(out.estimates.back().annotations[0] == Approx(16.0 * before(0, 0)));
  // An adapter whose needs the filter cannot meet is refused, naming why.
  struct WantsR : Adapter {
    NoiseNeeds needs() const override { return {MeasurementSpace::Spherical}; }
  } wants_spherical_r;
  CHECK_THROWS_WITH(testing::attach(wants_spherical_r, filter), Catch::Contains("spherical"));
}

// The same estimator, unchanged, as a tracker takes it (fixture.make_estimator: the declaration's
// create_estimator): run per track through a TrackContext, its predicted measurement is the z^ and
// S of the update that follows, and a clone continues exactly as the original.
TEST_CASE("estimator alone runs per track and predicts") {
  struct Track final : TrackContext {
    void warn(const std::string&) override {}
    void count(int) override {}
    void annotate(int, double) override {}
    Estimate e;
  } track;
  track.estimate = &track.e;
  auto est = fixture().make_estimator("filter.alpha_beta", "{alpha: 0.6, beta: 0.3}");
  est->bind(track);
  const Vec3 var(4.0, 9.0, 16.0);
  CHECK_FALSE(est->reset());
  est->measurement_noise() = cartesian(0.0, Vec3::Zero(), var).covariance;
  CHECK_FALSE(est->initiate(cartesian(0.0, Vec3(0, 0, 0), var), 3));
  CHECK(est->initiate(cartesian(1.0, Vec3(10, 20, -5), var), 3));
  const Measurement m = cartesian(3.0, Vec3(25, 35, -5), var);
  track.time = m.time;
  est->predict(2.0);
  PredictedMeasurement p;
  REQUIRE(est->predict_measurement(m, m.covariance, p));
  CHECK(p.z == Vec3(30, 60, -15));  // z2 + T v2
  std::unique_ptr<Estimator> copy = est->clone();
  REQUIRE(est->update(m, 3));
  REQUIRE(track.e.updated);
  for (int a = 0; a < 3; ++a) {
    CHECK(track.e.innovation(a) == Approx(m.value(a) - p.z(a)));
    CHECK(track.e.innovation_covariance(a, a) == Approx(p.S(a, a)));
    CHECK(p.S(a, a) == Approx(var(a) / (1 - 0.6)));
  }
  CHECK(p.log_det_S == Approx(std::log(p.S.determinant())));
  Estimate a, b;
  est->fill(a);
  REQUIRE(copy->update(m, 3));
  copy->fill(b);
  CHECK(a.state == b.state);
  CHECK(a.covariance == b.covariance);
}
