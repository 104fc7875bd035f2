// Purpose: tests of filter.kalman against a textbook reference filter, for consistency (NEES), coasting and errors.
#include <trackflow/rng.hpp>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

using namespace trackflow;

namespace {

Measurement cartesian(double t, const Vec3& z, double sigma) {
  Measurement m;
  m.time = t;
  m.frame = Frame::Cartesian;
  m.value = z;
  m.covariance = MeasCov::Identity(3, 3) * sigma * sigma;
  return m;
}

// Plain textbook KF (dynamic sizes, standard covariance update), CV, per-axis interleaved state.
struct ReferenceKf {
  Eigen::VectorXd x;
  Eigen::MatrixXd P;
  double q;
  void predict(double T) {
    Eigen::MatrixXd F = Eigen::MatrixXd::Identity(6, 6), Q = Eigen::MatrixXd::Zero(6, 6);
    for (int a = 0; a < 3; ++a) {
      F(2 * a, 2 * a + 1) = T;
      Q(2 * a, 2 * a) = q * T * T * T / 3;
      Q(2 * a, 2 * a + 1) = Q(2 * a + 1, 2 * a) = q * T * T / 2;
      Q(2 * a + 1, 2 * a + 1) = q * T;
    }
    x = F * x;
    P = F * P * F.transpose() + Q;
  }
  void update(const Eigen::Vector3d& z, const Eigen::Matrix3d& R) {
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(3, 6);
    for (int a = 0; a < 3; ++a) H(a, 2 * a) = 1;
    const Eigen::MatrixXd S = H * P * H.transpose() + R;
    const Eigen::MatrixXd K = P * H.transpose() * S.inverse();
    x = x + K * (z - H * x);
    P = (Eigen::MatrixXd::Identity(6, 6) - K * H) * P;
  }
};

}  // namespace

// CV filter agrees with a textbook Kalman filter step by step
TEST_CASE("CV filter agrees with a textbook Kalman filter") {
  auto kf = test::make("filter.kalman", "{ motion: constant_velocity, q: 2 m2/s3 }");
  test::Collector out;
  out.attach_to(*kf);
  Diagnostics d;
  kf->start_run({0, 1, &d});
  Rng rng(7);
  const double sigma = 5.0, T = 0.1;
  std::vector<Measurement> ms;
  for (int k = 0; k < 60; ++k) {
    const double t = k * T;
    const Vec3 truth(1000 + 50 * t, -200 + 10 * t, 300 - 3 * t);
    ms.push_back(cartesian(t, truth + Vec3(rng.normal(), rng.normal(), rng.normal()) * sigma, sigma));
    kf->on_measurement(ms.back(), 0);
  }
  REQUIRE(out.estimates.size() == 60);
  CHECK_FALSE(out.estimates[0].initialised);
  REQUIRE(out.estimates[1].initialised);
  // Reference initialised from the same two points.
  ReferenceKf ref;
  ref.q = 2.0;
  ref.x = Eigen::VectorXd::Zero(6);
  ref.P = Eigen::MatrixXd::Zero(6, 6);
  const double s2 = sigma * sigma;
  for (int a = 0; a < 3; ++a) {
    ref.x(2 * a) = ms[1].value(a);
    ref.x(2 * a + 1) = (ms[1].value(a) - ms[0].value(a)) / T;
    ref.P(2 * a, 2 * a) = s2;
    ref.P(2 * a, 2 * a + 1) = ref.P(2 * a + 1, 2 * a) = s2 / T;
    ref.P(2 * a + 1, 2 * a + 1) = 2 * s2 / (T * T);
  }
  for (size_t k = 2; k < ms.size(); ++k) {
    ref.predict(T);
    ref.update(ms[k].value.head<3>(), ms[k].covariance.topLeftCorner(3, 3));
    const auto& e = out.estimates[k];
    CHECK((e.state - ref.x).norm() < 1e-8 * ref.x.norm());
    CHECK((e.covariance - ref.P).norm() < 1e-8 * ref.P.norm());
  }
  const auto& last = out.estimates.back();
  CHECK(last.updated);
  CHECK((last.covariance - last.covariance.transpose()).norm() == 0.0);
  CHECK(last.enu(0) == last.state(0));
  CHECK(last.enu(3) == last.state(1));  // vx sits at index 1 of the interleaved state
}

// A diagonal R keeps the axes independent (the per-axis update); the first correlated R switches
// to the full update for good. Both must agree with the textbook filter at every step.
TEST_CASE("diagonal then correlated R agrees with a textbook filter") {
  auto kf = test::make("filter.kalman", "{ motion: constant_velocity, q: 3 m2/s3 }");
  test::Collector out;
  out.attach_to(*kf);
  Diagnostics d;
  kf->start_run({0, 1, &d});
  Rng rng(11);
  const double T = 0.1;
  std::vector<Measurement> ms;
  for (int k = 0; k < 80; ++k) {
    const double t = k * T;
    Measurement m = cartesian(t, Vec3(500 + 40 * t, 700 - 20 * t, 100 + 5 * t), 1.0);
    Mat3 R = Vec3(4.0, 9.0 + k, 16.0).asDiagonal();
    if (k >= 40) {  // correlated from here on
      R(0, 1) = R(1, 0) = 2.0;
      R(1, 2) = R(2, 1) = -3.0;
    }
    const Eigen::LLT<Mat3> llt(R);
    m.value = Vec3(m.value.head<3>() + llt.matrixL() * Vec3(rng.normal(), rng.normal(), rng.normal()));
    m.covariance = R;
    ms.push_back(m);
    kf->on_measurement(m, 0);
  }
  ReferenceKf ref;
  ref.q = 3.0;
  ref.x = Eigen::VectorXd::Zero(6);
  ref.P = Eigen::MatrixXd::Zero(6, 6);
  const Mat3 R0 = ms[0].covariance, R1 = ms[1].covariance;
  for (int a = 0; a < 3; ++a) {
    ref.x(2 * a) = ms[1].value(a);
    ref.x(2 * a + 1) = (ms[1].value(a) - ms[0].value(a)) / T;
    ref.P(2 * a, 2 * a) = R1(a, a);
    ref.P(2 * a, 2 * a + 1) = ref.P(2 * a + 1, 2 * a) = R1(a, a) / T;
    ref.P(2 * a + 1, 2 * a + 1) = (R0(a, a) + R1(a, a)) / (T * T);
  }
  for (size_t k = 2; k < ms.size(); ++k) {
    ref.predict(T);
    ref.update(ms[k].value.head<3>(), ms[k].covariance.topLeftCorner(3, 3));
    const auto& e = out.estimates[k];
    INFO("step " << k);
    CHECK((e.state - ref.x).norm() < 1e-9 * ref.x.norm());
    CHECK((e.covariance - ref.P).norm() < 1e-9 * ref.P.norm());
    CHECK((e.covariance - e.covariance.transpose()).norm() == 0.0);
    if (k < 40) CHECK(e.covariance(0, 2) == 0.0);  // no cross-axis term while R is diagonal
  }
  CHECK(out.estimates.back().covariance(0, 2) != 0.0);
}

// NEES of the CV filter on a CV target is consistent over 300 runs
TEST_CASE("CV filter NEES is consistent over 300 runs") {
  const int runs = 300, steps = 40;
  const double sigma = 10.0, T = 0.5;
  double nees_sum = 0;
  int count = 0;
  auto kf = test::make("filter.kalman", "{ q: 0.01 m2/s3 }");
  test::Collector out;
  out.attach_to(*kf);
  for (int r = 0; r < runs; ++r) {
    Diagnostics d;
    out.estimates.clear();
    kf->start_run({static_cast<std::uint64_t>(r), 1, &d});
    Rng rng(derive_seed(3, r, "test"));
    Vec3 p(5000, 2000, 1000), v(-100, 30, 0);
    for (int k = 0; k < steps; ++k) {
      // Truth with the same white-acceleration statistics the filter assumes (q * T per step in velocity).
      kf->on_measurement(cartesian(k * T, p + Vec3(rng.normal(), rng.normal(), rng.normal()) * sigma, sigma), 0);
      const auto& e = out.estimates.back();
      if (k == steps - 1) {
        Vec6 err;
        err << e.enu.head<3>() - p, e.enu.tail<3>() - v;
        nees_sum += err.dot(e.enu_covariance.ldlt().solve(err));
        ++count;
      }
      // Exact discretisation of continuous white acceleration with PSD q: sample w ~ N(0, Q_axis).
      const Eigen::Matrix2d Qa = (Eigen::Matrix2d() << 0.01 * T * T * T / 3, 0.01 * T * T / 2, 0.01 * T * T / 2,
                                  0.01 * T).finished();
      const Eigen::Matrix2d L = Qa.llt().matrixL();
      for (int a = 0; a < 3; ++a) {
        const Eigen::Vector2d w = L * Eigen::Vector2d(rng.normal(), rng.normal());
        p(a) += v(a) * T + w(0);
        v(a) += w(1);
      }
    }
  }
  const double anees = nees_sum / (6.0 * count);
  // chi-square(6*300) 99 % band divided by 1800: [0.922, 1.081]
  CHECK(anees > 0.92);
  CHECK(anees < 1.08);
}

// an invalid measurement makes the filter coast: prediction only, covariance grows
TEST_CASE("an invalid measurement makes the filter coast") {
  auto kf = test::make("filter.kalman");
  test::Collector out;
  out.attach_to(*kf);
  Diagnostics d;
  kf->start_run({0, 1, &d});
  for (int k = 0; k < 5; ++k) kf->on_measurement(cartesian(k, Vec3(100.0 * k, 0, 0), 3.0), 0);
  Measurement bad = cartesian(5, Vec3(1e9, 1e9, 1e9), 3.0);
  bad.valid = false;
  kf->on_measurement(bad, 0);
  REQUIRE(out.estimates.size() == 6);
  const auto& coast = out.estimates.back();
  CHECK_FALSE(coast.updated);
  CHECK(coast.initialised);
  CHECK(coast.enu(0) == Approx(500).epsilon(0.01));
  CHECK(coast.enu_covariance(0, 0) > out.estimates[4].enu_covariance(0, 0));
}

// constant-acceleration model tracks an accelerating target without lag
TEST_CASE("CA model tracks an accelerating target without lag") {
  auto kf = test::make("filter.kalman", "{ motion: constant_acceleration, q_jerk: 0.001 m2/s5 }");
  test::Collector out;
  out.attach_to(*kf);
  Diagnostics d;
  kf->start_run({0, 1, &d});
  for (int k = 0; k < 400; ++k) {
    const double t = 0.1 * k;
    kf->on_measurement(cartesian(t, Vec3(0.5 * 20 * t * t, 0, 0), 0.5), 0);
  }
  const auto& e = out.estimates.back();
  CHECK(e.state.size() == 9);
  CHECK(e.state(2) == Approx(20).epsilon(0.02));  // ax
  CHECK(e.enu(3) == Approx(20 * 39.9).epsilon(0.001));
}

TEST_CASE("wrong inputs and parameters are clear errors") {
  auto kf = test::make("filter.kalman");
  Diagnostics d;
  kf->start_run({0, 1, &d});
  Measurement m = cartesian(0, Vec3(1, 2, 3), 1);
  m.frame = Frame::Spherical;
  CHECK_THROWS_WITH(kf->on_measurement(m, 0), Catch::Contains("convert"));
  CHECK_THROWS_WITH(test::make("filter.kalman", "{ motion: constant_acceleration, q: 1 }"), Catch::Contains("q_jerk"));
  CHECK_THROWS_WITH(test::make("filter.kalman", "{ init: explicit }"), Catch::Contains("initial_position"));
  CHECK_THROWS_WITH(test::make("filter.kalman", "{ q: 1 m2/s3, sigma_accel: 1 m/s2 }"), Catch::Contains("not both"));
}

// explicit initialisation holds at the first measurement's time (no infinite first step)
TEST_CASE("explicit initialisation holds at the first time") {
  auto kf = test::make("filter.kalman", "{ init: explicit, initial_position: [0, 0, 0], initial_velocity: [10, 0, 0], "
                                        "initial_sigma_position: 5 m, initial_sigma_velocity: 2 m/s }");
  test::Collector out;
  out.attach_to(*kf);
  Diagnostics d;
  kf->start_run({0, 1, &d});
  kf->on_measurement(cartesian(100.0, Vec3(1, 0, 0), 3.0), 0);
  kf->on_measurement(cartesian(101.0, Vec3(11, 0, 0), 3.0), 0);
  REQUIRE(out.estimates.size() == 2);
  for (const auto& e : out.estimates) {
    CHECK(e.initialised);
    CHECK(e.state.allFinite());
    CHECK(e.covariance.allFinite());
  }
  CHECK(out.estimates[1].enu(0) == Approx(11).margin(2));
}

// estimates published before initialisation carry defined (zero) state
TEST_CASE("estimates before initialisation carry zero state") {
  auto kf = test::make("filter.kalman");
  test::Collector out;
  out.attach_to(*kf);
  Diagnostics d;
  kf->start_run({0, 1, &d});
  kf->on_measurement(cartesian(0, Vec3(1, 2, 3), 1), 0);
  REQUIRE(out.estimates.size() == 1);
  CHECK_FALSE(out.estimates[0].initialised);
  CHECK(out.estimates[0].state.size() == 6);
  CHECK(out.estimates[0].state.isZero());
  CHECK(out.estimates[0].enu_covariance.isZero());
  // A second run on the same instance must not show the first run's track.
  for (int k = 1; k < 5; ++k) kf->on_measurement(cartesian(k, Vec3(1 + k, 2, 3), 1), 0);
  kf->start_run({1, 1, &d});
  kf->on_measurement(cartesian(0, Vec3(1, 2, 3), 1), 0);
  CHECK_FALSE(out.estimates.back().initialised);
  CHECK(out.estimates.back().state.isZero());
  CHECK(out.estimates.back().innovation.size() == 0);
}

// a process-noise change through noise() takes effect at the next step even at a fixed T
TEST_CASE("a process-noise change takes effect at next step") {
  auto run = [](double q_after) {
    auto c = test::make("filter.kalman", "{ q: 1 m2/s3 }");
    auto& f = dynamic_cast<Filter&>(*c);
    test::Collector out;
    out.attach_to(f);
    Diagnostics d;
    f.start_run({0, 1, &d});
    for (int k = 0; k < 10; ++k) f.on_measurement(cartesian(k, Vec3(k, 0, 0), 1), 0);
    *f.noise().process.values = q_after;
    f.on_measurement(cartesian(10, Vec3(10, 0, 0), 1), 0);
    return out.estimates.back().enu_covariance(3, 3);
  };
  CHECK(run(100.0) > 2 * run(1.0));
}

TEST_CASE("adapter annotations ride on the next estimates") {
  struct Annotator : Adapter {
    std::vector<std::string> annotation_names() const override { return {"a", "b", "c"}; }
    void before_update(const Measurement& m, Filter& f) override {
      if (m.time >= 1.0) {
        annotate(f, 0, 2.0);
        annotate(f, 2, 0.0);
      }
    }
  } annotator;
  auto c = test::make("filter.kalman");
  auto& f = dynamic_cast<Filter&>(*c);
  test::attach(annotator, f);
  test::Collector out;
  out.attach_to(f);
  Diagnostics d;
  test::start_run(f, 0, 1, &d);
  f.on_measurement(cartesian(0, Vec3(1, 2, 3), 1), 0);
  REQUIRE(out.estimates.back().annotation_count == 3);
  for (int i = 0; i < 3; ++i) CHECK(std::isnan(out.estimates.back().annotations[i]));
  f.on_measurement(cartesian(1, Vec3(1, 2, 3), 1), 0);
  CHECK(out.estimates.back().annotations[0] == 2.0);
  CHECK(std::isnan(out.estimates.back().annotations[1]));
  CHECK(out.estimates.back().annotations[2] == 0.0);
  test::start_run(f, 1, 1, &d);  // as the engine, at the next run
  f.on_measurement(cartesian(0, Vec3(1, 2, 3), 1), 0);
  CHECK(std::isnan(out.estimates.back().annotations[0]));
}

TEST_CASE("engine restores retuned process noise before next run") {
  auto c = test::make("filter.kalman", "{ q: 1 m2/s3 }");
  auto& f = dynamic_cast<Filter&>(*c);
  test::save_configured_noise(f);  // the engine, once the instance is built
  Diagnostics d;
  f.start_run({0, 1, &d});
  *f.noise().process.values = 50.0;
  test::start_run(f, 1, 1, &d);  // the engine, at the start of every run
  CHECK(*f.noise().process.values == 1.0);
}

// Two truth targets into one single-track filter: the track takes the first target's id (sinks
// score its estimates against that target), and the other target's measurements are said once
// per run and counted, never silently fused.
TEST_CASE("two targets into one filter are said and counted") {
  auto c = test::make("filter.kalman", "{}", "kf");
  auto& f = dynamic_cast<Filter&>(*c);
  test::Collector out;
  out.attach_to(f);
  Diagnostics d;
  f.start_run({0, 1, &d});
  for (int k = 0; k < 6; ++k) {
    Measurement a = cartesian(k, Vec3(100.0 * k, 0, 0), 1);
    a.origin = 3;
    f.on_measurement(a, 0);
    Measurement b = cartesian(k + 0.5, Vec3(5e4, 100.0 * k, 0), 1);
    b.origin = k < 4 ? 8 : kOriginUnknown;  // unknown origins are neither counted nor followed
    f.on_measurement(b, 0);
  }
  REQUIRE(!out.estimates.empty());
  for (const Estimate& e : out.estimates) CHECK(e.target == 3u);
  REQUIRE(d.warnings.size() == 1);
  CHECK_THAT(d.warnings[0].message, Catch::Contains("t=0.5") && Catch::Contains("truth target 8") &&
                                        Catch::Contains("first from target 3"));
  f.merge(*f.end_run());
  Summary s;
  f.finish(s, {});
  REQUIRE(s.find("other_target_measurements"));
  CHECK(s.find("other_target_measurements")->value == 4.0);
  // One target only: no such metric, and the estimates carry its id.
  auto single = test::make("filter.kalman");
  auto& g = dynamic_cast<Filter&>(*single);
  test::Collector out2;
  out2.attach_to(g);
  g.start_run({0, 1, &d});
  Measurement m = cartesian(0, Vec3::Zero(), 1);
  m.origin = 5;
  g.on_measurement(m, 0);
  g.merge(*g.end_run());
  Summary s2;
  g.finish(s2, {});
  CHECK(s2.find("other_target_measurements") == nullptr);
  CHECK(out2.estimates.back().target == 5u);
}

// A planar (x, y) sensor: with a diagonal R the axes are independent filters, so the x-y part of
// the track equals, bit for bit, that of a 3-D filter fed the same x and y (and any z); the planar
// track stays in z = 0 with zero z variance (no z process noise).
TEST_CASE("planar x-y measurements track in the plane z 0") {
  auto planar = test::make("filter.kalman", "{ motion: constant_velocity, q: 2 m2/s3 }");
  auto full = test::make("filter.kalman", "{ motion: constant_velocity, q: 2 m2/s3 }");
  test::Collector out_planar, out_full;
  out_planar.attach_to(*planar);
  out_full.attach_to(*full);
  Diagnostics d;
  planar->start_run({0, 1, &d});
  full->start_run({0, 1, &d});
  Rng rng(11);
  const double sigma = 4.0, T = 0.5;
  for (int k = 0; k < 40; ++k) {
    const double t = k * T;
    const Vec3 z(800 + 30 * t + sigma * rng.normal(), -100 - 12 * t + sigma * rng.normal(), 50 * rng.normal());
    Measurement m3 = cartesian(t, z, sigma);
    Measurement m2;
    m2.time = t;
    m2.frame = Frame::Planar;
    m2.value = z.head<2>();
    m2.covariance = MeasCov::Identity(2, 2) * sigma * sigma;
    planar->on_measurement(m2, 0);
    full->on_measurement(m3, 0);
  }
  REQUIRE(out_planar.estimates.size() == 40);
  for (size_t k = 1; k < 40; ++k) {
    const Estimate &p = out_planar.estimates[k], &f = out_full.estimates[k];
    REQUIRE(p.initialised);
    for (int i : {0, 1, 3, 4}) {  // x, y, vx, vy of the ENU block
      CHECK(p.enu(i) == f.enu(i));
      for (int j : {0, 1, 3, 4}) CHECK(p.enu_covariance(i, j) == f.enu_covariance(i, j));
    }
    CHECK(p.enu(2) == 0.0);
    CHECK(p.enu(5) == 0.0);
    CHECK(p.enu_covariance.row(2).norm() == 0.0);
    CHECK(p.enu_covariance.row(5).norm() == 0.0);
    if (k > 1) {
      CHECK(p.innovation.size() == 2);
      CHECK(p.innovation_covariance.rows() == 2);
    }
  }
  // The planar NIS has 2 degrees of freedom: its mean over the run is near 2, not 3.
  double nis = 0.0;
  for (size_t k = 2; k < 40; ++k) nis += out_planar.estimates[k].nis;
  CHECK(nis / 38.0 < 2.9);
}

// A detection of another frame, or of the wrong size, is refused with a message naming both.
TEST_CASE("planar measurement of the wrong size is refused") {
  auto kf = test::make("filter.kalman", "{ motion: constant_velocity, q: 2 m2/s3 }");
  Diagnostics d;
  kf->start_run({0, 1, &d});
  Measurement m;
  m.frame = Frame::Planar;
  m.value = Vec3(1, 2, 3);
  m.covariance = MeasCov::Identity(3, 3);
  CHECK_THROWS_WITH(kf->on_measurement(m, 0), Catch::Contains("planar (x-y) measurement") && Catch::Contains("expected 2"));
  Measurement polar;
  polar.frame = Frame::Polar;
  polar.value = Eigen::Vector2d(1000, 0.1);
  polar.covariance = MeasCov::Identity(2, 2);
  CHECK_THROWS_WITH(kf->on_measurement(polar, 0), Catch::Contains("takes cartesian/planar (x-y) measurements"));
}
