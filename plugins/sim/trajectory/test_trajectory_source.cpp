// Purpose: tests of sim.trajectory: closed-form CV/CA, exact turns, velocity changes, sample times, record validation, process noise.
#include <catch2/catch.hpp>

#include "flight_plan.hpp"
#include "launch_profile.hpp"
#include "plugin_fixture.hpp"
#include "trajectory_test_support.hpp"

#include <trackflow/rng.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

using namespace trackflow;

namespace {

using test::config_error;
using test::fly;

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// Reference turn: RK4 on dp/dt = v, dv/dt = w z^ x v with a small step, independent of the plugin's closed form.
void integrate_turn(Vec3& p, Vec3& v, double w, double duration, int steps) {
  const double h = duration / steps;
  auto accel = [w](const Vec3& vel) { return Vec3(-w * vel.y(), w * vel.x(), 0.0); };
  for (int i = 0; i < steps; ++i) {
    const Vec3 k1p = v, k1v = accel(v);
    const Vec3 k2p = v + 0.5 * h * k1v, k2v = accel(v + 0.5 * h * k1v);
    const Vec3 k3p = v + 0.5 * h * k2v, k3v = accel(v + 0.5 * h * k2v);
    const Vec3 k4p = v + h * k3v, k4v = accel(v + h * k3v);
    p += h / 6 * (k1p + 2 * k2p + 2 * k3p + k4p);
    v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
  }
}

}  // namespace

// constant velocity then constant acceleration follow the closed form
TEST_CASE("CV then CA segments follow the closed form") {
  const auto truths = fly(R"(
    rate: 10 Hz
    initial_position: [100 m, -200 m, 50 m]
    initial_velocity: [10 m/s, 20 m/s, -1 m/s]
    target: 7
    segments:
      - {type: constant_velocity, duration: 5 s}
      - {type: constant_acceleration, duration: 4 s, acceleration: [1, -2, 0.5]}
  )");
  REQUIRE(truths.size() == 91);
  const Vec3 p0(100, -200, 50), v0(10, 20, -1), a(1, -2, 0.5);
  const Vec3 p5 = p0 + 5 * v0;
  for (const Truth& t : truths) {
    CHECK(t.target == 7u);
    Vec3 p, v, acc;
    if (t.time < 5.0) {
      p = p0 + t.time * v0, v = v0, acc = Vec3::Zero();
    } else {
      const double s = t.time - 5.0;
      p = p5 + s * v0 + 0.5 * s * s * a, v = v0 + s * a, acc = a;
    }
    CHECK((t.position - p).norm() < 1e-9);
    CHECK((t.velocity - v).norm() < 1e-12);
    CHECK((t.acceleration - acc).norm() == 0.0);
  }
  CHECK(truths.back().time == 9.0);
}

// a full circle returns to its start with constant speed and radius v / turn_rate
TEST_CASE("a full circle returns to its start") {
  // Paper 002 scenario 1: radius 1500 m at 200 m/s and 150 m altitude, so turn_rate = v / R.
  const double v = 200.0, R = 1500.0, w = v / R, period = 2 * std::numbers::pi / w;
  const int samples_per_circle = 1884;  // about 40 Hz; the rate is chosen so the last sample lands on the end
  const auto truths = fly("rate: " + num(samples_per_circle / period) + " Hz\n" +
                          "initial_position: [0, 0, 150 m]\ninitial_velocity: [200 m/s, 0, 0]\n"
                          "segments:\n  - {type: turn, turn_rate: " + num(w) + " rad/s, duration: " + num(period) + " s}\n");
  REQUIRE(truths.size() == samples_per_circle + 1);
  CHECK(truths.back().time == Approx(period).epsilon(1e-14));
  CHECK((truths.back().position - truths.front().position).norm() < 1e-6);
  // Counter-clockwise from an eastward start: the centre is to the left (north) of the start.
  const Vec3 centre(0.0, R, 150.0);
  double farthest = 0.0;
  for (const Truth& t : truths) {
    CHECK(t.velocity.norm() == Approx(v).epsilon(1e-12));
    CHECK((t.position - centre).norm() == Approx(R).epsilon(1e-10));
    CHECK(t.position.z() == 150.0);
    CHECK(t.acceleration.norm() == Approx(v * v / R).epsilon(1e-12));
    CHECK(t.acceleration.dot(centre - t.position) > 0.0);  // centripetal
    farthest = std::max(farthest, (t.position - truths.front().position).norm());
  }
  CHECK(farthest == Approx(2 * R).epsilon(1e-6));  // diameter
  // A quarter of the way round, a counter-clockwise turn heads north.
  const Truth& quarter = truths[samples_per_circle / 4];
  CHECK(quarter.velocity.y() > 0.99 * v);
}

// a climbing turn keeps its vertical velocity and matches a fine numerical integration
TEST_CASE("a climbing turn matches numerical integration") {
  const auto truths = fly(R"(
    rate: 4 Hz
    initial_position: [1 km, 2 km, 300 m]
    initial_velocity: [-50 m/s, 120 m/s, 3 m/s]
    segments:
      - {type: turn, turn_rate: -6 deg/s, duration: 7.25 s}
  )");
  REQUIRE(truths.size() == 30);
  Vec3 p(1000, 2000, 300), vel(-50, 120, 3);
  integrate_turn(p, vel, -6 * std::numbers::pi / 180, 7.25, 20000);
  CHECK((truths.back().position - p).norm() < 1e-6);
  CHECK((truths.back().velocity - vel).norm() < 1e-8);
  for (const Truth& t : truths) CHECK(t.velocity.z() == 3.0);
}

// paper 002 scenario 2: a velocity change to 300 m/s with a 60 degree climb
TEST_CASE("paper 002 scenario 2 velocity change and climb") {
  const auto truths = fly(R"(
    rate: 40 Hz
    initial_position: [0, 0, 100 m]
    initial_velocity: [150 m/s, 0, 0]
    segments:
      - {type: constant_velocity, duration: 3 s}
      - {type: velocity_change, speed: 300 m/s, climb: 60 deg}
      - {type: constant_velocity, duration: 2 s}
  )");
  REQUIRE(truths.size() == 201);
  const double c60 = std::cos(std::numbers::pi / 3), s60 = std::sin(std::numbers::pi / 3);
  const Vec3 after(300 * c60, 0, 300 * s60);  // heading kept (east)
  const Truth& before = truths[119];
  const Truth& at = truths[120];
  CHECK(before.time < 3.0);
  REQUIRE(at.time == 3.0);
  CHECK((before.velocity - Vec3(150, 0, 0)).norm() < 1e-12);
  CHECK((at.velocity - after).norm() < 1e-9);  // the sample at the change already shows it
  CHECK(at.velocity.norm() == Approx(300));
  CHECK(std::atan2(at.velocity.z(), std::hypot(at.velocity.x(), at.velocity.y())) == Approx(std::numbers::pi / 3));
  CHECK((at.position - Vec3(450, 0, 100)).norm() < 1e-9);
  CHECK((truths.back().position - (Vec3(450, 0, 100) + 2 * after)).norm() < 1e-9);
}

// velocity_change: heading alone keeps speed and climb - a full vector replaces the velocity
TEST_CASE("velocity_change by heading or by full vector") {
  const auto truths = fly(R"(
    rate: 1 Hz
    initial_position: [0, 0, 0]
    initial_velocity: [30 m/s, 0, 40 m/s]
    segments:
      - {type: velocity_change, heading: 180 deg}
      - {type: constant_velocity, duration: 1 s}
      - {type: velocity_change, velocity: [1, 2, 3]}
  )");
  REQUIRE(truths.size() == 2);
  CHECK((truths[0].velocity - Vec3(0, -30, 40)).norm() < 1e-12);  // due south, same speed and climb
  CHECK((truths[1].position - Vec3(0, -30, 40)).norm() < 1e-12);
  CHECK((truths[1].velocity - Vec3(1, 2, 3)).norm() == 0.0);     // trailing change shows at the end
}

TEST_CASE("a straight constant-speed descent (landing approach)") {
  const auto truths = fly(R"(
    rate: 20 Hz
    initial_position: [-5 km, 0, 262 m]
    initial_velocity: [0, 0, 0]
    segments:
      - {type: velocity_change, speed: 60 m/s, heading: 90 deg, climb: -3 deg}
      - {type: constant_velocity, duration: 80 s}
  )");
  REQUIRE(truths.size() == 1601);
  const double g = -3 * std::numbers::pi / 180;
  const Vec3 v(60 * std::cos(g), 0, 60 * std::sin(g));
  CHECK((truths.back().position - (Vec3(-5000, 0, 262) + 80 * v)).norm() < 1e-9);
  for (const Truth& t : truths) CHECK(t.velocity.norm() == Approx(60));
}

// landing approach (paper 001): straight constant-speed descent along the runway to a radar at touchdown
TEST_CASE("paper 001 landing approach to a touchdown radar") {
  // Runway along +x (heading 090), radar at the touchdown point (the origin); 3 deg glide slope from
  // 5 km out at 60 m/s. Existing segments express it: a velocity_change, then constant velocity until
  // the track reaches the radar.
  const double glide = 3 * std::numbers::pi / 180, speed = 60, out = 5000;
  const double height = out * std::tan(glide), duration = out / (speed * std::cos(glide));
  const auto truths = fly("rate: 10 Hz\ninitial_position: [" + num(-out) + ", 0, " + num(height) + "]\n"
                          "segments:\n  - {type: velocity_change, speed: 60 m/s, heading: 90 deg, climb: -3 deg}\n"
                          "  - {type: constant_velocity, duration: " + num(duration) + " s}\n");
  REQUIRE(truths.size() == static_cast<size_t>(std::floor(duration * 10)) + 1);
  const double start_range = out / std::cos(glide);
  for (const Truth& t : truths) {
    if (t.time == truths.back().time) break;
    const Vec3& p = t.position;
    INFO("t = " << t.time);
    CHECK(std::abs(p.y()) < 1e-9);                                             // on the centreline
    CHECK(std::atan2(p.z(), -p.x()) == Approx(glide).epsilon(1e-12));          // constant elevation seen from the radar
    CHECK(p.norm() == Approx(start_range - speed * t.time).margin(1e-8));       // range closes at the airspeed
    CHECK(t.velocity.dot(p) / p.norm() == Approx(-speed).epsilon(1e-12));      // range rate -60 m/s
  }
  // The last sample (at most one period before touchdown) is within one period's travel of the radar.
  CHECK(truths.back().position.norm() < speed * 0.1 + 1e-9);
}

// sample times are start_time + k / rate up to the end, inclusive
TEST_CASE("sample times are start_time + k / rate inclusive") {
  SECTION("10 Hz from 2 s over 3 s") {
    const auto truths = fly("rate: 10 Hz\nstart_time: 2 s\ninitial_position: [0, 0, 0]\n"
                            "segments: [{type: constant_velocity, duration: 3 s}]");
    REQUIRE(truths.size() == 31);
    for (size_t k = 0; k < truths.size(); ++k) CHECK(truths[k].time == 2.0 + static_cast<double>(k) / 10.0);
    CHECK(truths.back().time == 5.0);
  }
  SECTION("3 Hz over 1 s: the period is not a binary fraction") {
    const auto truths = fly("rate: 3 Hz\ninitial_position: [0, 0, 0]\nsegments: [{type: constant_velocity, duration: 1 s}]");
    REQUIRE(truths.size() == 4);
    CHECK(truths[1].time == 1.0 / 3.0);
    CHECK(truths[3].time == 1.0);
  }
  SECTION("boundaries summed with rounding (0.1 + 0.2 s) still put the change on the sample at 0.3 s") {
    const auto truths = fly(R"(
      rate: 40 Hz
      initial_position: [0, 0, 0]
      initial_velocity: [1, 0, 0]
      segments:
        - {type: constant_velocity, duration: 0.1 s}
        - {type: constant_velocity, duration: 0.2 s}
        - {type: velocity_change, velocity: [0, 5, 0]}
        - {type: constant_velocity, duration: 0.1 s}
    )");
    REQUIRE(truths.size() == 17);
    CHECK(truths[12].time == 0.3);
    CHECK(truths[11].velocity.x() == 1.0);
    CHECK(truths[12].velocity.y() == 5.0);
    CHECK(truths.back().time == 0.4);
  }
  SECTION("each run starts over") {
    auto gen = test::make("sim.trajectory", "initial_position: [0, 0, 0]\nsegments: [{type: constant_velocity, duration: 1 s}]");
    test::Collector out;
    out.attach_to(*gen);
    test::drain(*gen, 1, 0);
    test::drain(*gen, 2, 1);
    REQUIRE(out.truths.size() == 22);
    CHECK(out.truths[11].time == 0.0);
  }
}

TEST_CASE("inconsistent segments are refused naming the field") {
  const std::string head = "initial_position: [0, 0, 0]\ninitial_velocity: [10, 0, 0]\nsegments:\n";
  struct Case {
    const char* segment;
    const char* field;
  };
  const Case cases[] = {
      {"{type: constant_velocity}", "duration"},
      {"{type: constant_velocity, duration: 1 s, turn_rate: 1 deg/s}", "turn_rate"},
      {"{type: constant_acceleration, duration: 1 s}", "acceleration"},
      {"{type: turn, duration: 1 s}", "turn_rate"},
      {"{type: turn, duration: 1 s, turn_rate: 1 deg/s, speed: 3}", "speed"},
      {"{type: velocity_change, duration: 1 s, speed: 3}", "duration"},
      {"{type: velocity_change}", "velocity"},
      {"{type: velocity_change, velocity: [1, 2, 3], climb: 3 deg}", "climb"},
      {"{type: constant_velocity, duration: 0 s}", "duration"},
      {"{type: velocity_change, climb: 100 deg}", "climb"},
      {"{type: hover, duration: 1 s}", "type"},
  };
  for (const auto& c : cases) {
    INFO(c.segment);
    const std::string msg = config_error(head + "  - " + c.segment + "\n");
    CHECK_THAT(msg, Catch::Matchers::Contains(std::string("'") + c.field + "'"));
  }
  CHECK_THAT(config_error(head), Catch::Matchers::Contains("segments"));
  CHECK_THAT(config_error("initial_position: [0, 0, 0]\nsegments: []"), Catch::Matchers::Contains("segments"));
  CHECK_THAT(config_error("segments: [{type: constant_velocity, duration: 1 s}]"),
             Catch::Matchers::Contains("initial_position"));
  // The segment's number is in the message, so the analyst knows which entry.
  CHECK_THAT(config_error(head + "  - {type: constant_velocity, duration: 1 s}\n  - {type: turn, duration: 2 s}\n"),
             Catch::Matchers::Contains("segment 2"));
}

// keeping the direction of a zero or vertical velocity is refused - a vertical target is fine
TEST_CASE("keeping a zero or vertical direction is refused") {
  const std::string still = "initial_position: [0, 0, 0]\nsegments:\n";
  CHECK_THAT(config_error(still + "  - {type: velocity_change, speed: 100}\n"), Catch::Matchers::Contains("'climb'"));
  CHECK_THAT(config_error(still + "  - {type: velocity_change, speed: 100, climb: 10 deg}\n"),
             Catch::Matchers::Contains("'heading'"));
  const auto up = fly(still + "  - {type: velocity_change, speed: 100, climb: 90 deg}\n");
  REQUIRE(up.size() == 1);
  CHECK((up[0].velocity - Vec3(0, 0, 100)).norm() < 1e-9);
}

namespace {

// A manoeuvring flight: every segment kind, near the origin so that deviations of a few mm are
// not lost to rounding of the position.
// Flush left, so that a parameter can be appended to it.
const std::string kManoeuvres = R"(rate: 10 Hz
initial_position: [10 m, -20 m, 5 m]
initial_velocity: [30 m/s, 0, 1 m/s]
segments:
  - {type: constant_velocity, duration: 2 s}
  - {type: turn, turn_rate: 10 deg/s, duration: 3 s}
  - {type: constant_acceleration, acceleration: [-2, 1, 0], duration: 2 s}
  - {type: velocity_change, speed: 20 m/s, heading: 200 deg}
  - {type: constant_velocity, duration: 3 s}
)";
const std::string kLaunch = "rate: 2 Hz\nprofile: kslv1\npad_position: [0, 50 km, 0]\nlaunch_azimuth: 120 deg\n"
                            "earth: spherical\nprofile_duration: 60 s\n";

// The profile without the plugin's sampling loop: the piece in force at t, evaluated in closed form.
sim::Kinematics profile_at(const std::vector<sim::MotionPiece>& pieces, double t) {
  size_t i = 0;
  while (i + 1 < pieces.size() && pieces[i + 1].start <= t + 1e-9) ++i;
  return sim::evaluate(pieces[i], t);
}

// The set-up of the process-noise moment tests: a straight CV flight sampled every T, R runs with
// the per-axis intensities q (the "[4, 1, 0.25]" the tests append to `base`), compared with the
// noise-free `profile` over its K steps.
struct NoiseExperiment {
  Vec3 q = Vec3(4.0, 1.0, 0.25);
  double T = 0.1;
  int R = 400;
  std::string base = "rate: 10 Hz\ninitial_position: [1 m, 2 m, 3 m]\ninitial_velocity: [5 m/s, -5 m/s, 0]\n"
                     "segments: [{type: constant_velocity, duration: 10 s}]\n";
  std::vector<Truth> profile = fly(base);
  int K = static_cast<int>(profile.size()) - 1;
};

// The moment estimate S of the covariance E from n independent vectors, entry by entry within 5 sd,
// Var S_ij = (E_ii E_jj + E_ij²) / n (Isserlis).
template <int D>
void check_covariance(const Eigen::Matrix<double, D, D>& S, const Eigen::Matrix<double, D, D>& E, double n) {
  for (int i = 0; i < D; ++i)
    for (int j = i; j < D; ++j) {
      const double sd = std::sqrt((E(i, i) * E(j, j) + E(i, j) * E(i, j)) / n);
      INFO("entry " << i << " " << j << ": " << S(i, j) << " expected " << E(i, j) << " sd " << sd);
      CHECK(std::abs(S(i, j) - E(i, j)) < 5 * sd);
    }
}

}  // namespace

TEST_CASE("process noise off: output is the deterministic profile") {
  struct Case {
    const std::string* yaml;
    bool launch;
  };
  for (const Case c : {Case{&kManoeuvres, false}, Case{&kLaunch, true}}) {
    const Params p = test::params_for("sim.trajectory", *c.yaml);
    const auto pieces = c.launch ? sim::build_launch_plan(p) : sim::build_flight_plan(p);
    for (const char* off : {"", "process_noise_q: 0 m2/s3\n", "process_noise_q_enu: [0, 0, 0]\n", "process_noise_q_jerk: 0 m2/s5\n",
                            "process_noise_q_jerk_enu: [0, 0, 0]\n"}) {
      INFO(*c.yaml << off);
      for (std::uint64_t seed : {1u, 99u}) {
        const auto truths = fly(*c.yaml + off, seed, seed);
        REQUIRE(truths.size() > 10);
        for (const Truth& t : truths) {
          const sim::Kinematics k = profile_at(pieces, t.time);
          // Bitwise: an exact comparison, not a tolerance.
          CHECK((t.position.array() == k.position.array()).all());
          CHECK((t.velocity.array() == k.velocity.array()).all());
          CHECK((t.acceleration.array() == k.acceleration.array()).all());
        }
      }
    }
  }
}

TEST_CASE("process noise increments have the CV model covariance") {
  // Per axis the deviation d = truth - profile obeys d' = F d + w with F = [[1, T], [0, 1]] and
  // w ~ N(0, q Q1), Q1 = [[T³/3, T²/2], [T²/2, T]]. Over R runs and K steps the N = R K vectors
  // w (6 components: p and v of east, north, up) are independent with mean zero, so the moment
  // estimate S_ij = Σ w_i w_j / N is unbiased with Var S_ij = (Σ_ii Σ_jj + Σ_ij²) / N (Isserlis:
  // E[w_i² w_j²] = Σ_ii Σ_jj + 2 Σ_ij²). S is a mean of N iid terms, so nearly normal at N = 40000;
  // |S_ij - Σ_ij| < 5 sd has a false-alarm chance below 1e-6 per entry (the seed is fixed, so the
  // test is deterministic; the bound is what makes a wrong factor such as T² or T³/2 fail:
  // those are off by 25 % or more, against 5 sd = 5 √(2/N) = 3.5 % on a diagonal entry).
  const NoiseExperiment experiment;
  const auto& [q, T, R, base, profile, K] = experiment;
  REQUIRE(K == 100);
  Eigen::Matrix<double, 6, 6> sum = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 6> end_sum = Eigen::Matrix<double, 6, 6>::Zero();
  auto deviation = [&](const Truth& noisy, const Truth& clean) {
    Eigen::Matrix<double, 6, 1> d;
    for (int a = 0; a < 3; ++a) {
      d(2 * a) = noisy.position[a] - clean.position[a];
      d(2 * a + 1) = noisy.velocity[a] - clean.velocity[a];
    }
    return d;
  };
  double worst_accel = 0.0;
  for (int r = 0; r < R; ++r) {
    const auto truths = fly(base + "process_noise_q_enu: [4, 1, 0.25]\n", derive_seed(11, r, "truth"), r);
    REQUIRE(truths.size() == profile.size());
    CHECK(deviation(truths[0], profile[0]).norm() == 0.0);  // the run starts on the profile
    for (int k = 0; k < K; ++k) {
      const auto d0 = deviation(truths[k], profile[k]), d1 = deviation(truths[k + 1], profile[k + 1]);
      Eigen::Matrix<double, 6, 1> w;  // d1 - F d0
      for (int a = 0; a < 3; ++a) {
        w(2 * a) = d1(2 * a) - d0(2 * a) - T * d0(2 * a + 1);
        w(2 * a + 1) = d1(2 * a + 1) - d0(2 * a + 1);
      }
      sum += w * w.transpose();
      // The reported acceleration is the profile's (zero) plus the step's mean white acceleration.
      for (int a = 0; a < 3; ++a)
        worst_accel = std::max(worst_accel, std::abs(truths[k + 1].acceleration[a] - w(2 * a + 1) / T));
    }
    const auto d = deviation(truths.back(), profile.back());
    end_sum += d * d.transpose();
  }
  CHECK(worst_accel < 1e-9);
  // Expected covariances: of one increment (period T) and of the deviation at the end (t = K T,
  // the same model integrated from zero: q [[t³/3, t²/2], [t²/2, t]]).
  auto model = [&](double t) {
    Eigen::Matrix<double, 6, 6> m = Eigen::Matrix<double, 6, 6>::Zero();
    for (int a = 0; a < 3; ++a) {
      m(2 * a, 2 * a) = q[a] * t * t * t / 3;
      m(2 * a, 2 * a + 1) = m(2 * a + 1, 2 * a) = q[a] * t * t / 2;
      m(2 * a + 1, 2 * a + 1) = q[a] * t;
    }
    return m;
  };
  const double N = static_cast<double>(R) * K;
  check_covariance<6>(sum / N, model(T), N);
  check_covariance<6>(end_sum / R, model(K * T), R);  // R = 400: 5 sd is 35 % on a diagonal entry
}

TEST_CASE("white jerk increments have the CA model covariance") {
  // Per axis d = truth - profile = [p, v, a] obeys d' = F d + w, F = [[1, T, T²/2], [0, 1, T],
  // [0, 0, 1]], w ~ N(0, q Q1), Q1 = [[T⁵/20, T⁴/8, T³/6], [T⁴/8, T³/3, T²/2], [T³/6, T²/2, T]]
  // (paper 000 eq 3.19). Moment estimates of the 9-vector w against q Q1 within 5 sd, as in the
  // white-acceleration test above (a wrong factor, e.g. T⁵/6 or T⁴/2, is off by far more).
  const NoiseExperiment experiment;
  const auto& [q, T, R, base, profile, K] = experiment;
  REQUIRE(K == 100);
  using Mat9 = Eigen::Matrix<double, 9, 9>;
  using Vec9 = Eigen::Matrix<double, 9, 1>;
  Mat9 sum = Mat9::Zero(), end_sum = Mat9::Zero();
  auto deviation = [&](const Truth& noisy, const Truth& clean) {
    Vec9 d;
    for (int a = 0; a < 3; ++a) {
      d(3 * a) = noisy.position[a] - clean.position[a];
      d(3 * a + 1) = noisy.velocity[a] - clean.velocity[a];
      d(3 * a + 2) = noisy.acceleration[a] - clean.acceleration[a];
    }
    return d;
  };
  for (int r = 0; r < R; ++r) {
    const auto truths = fly(base + "process_noise_q_jerk_enu: [4, 1, 0.25]\n", derive_seed(11, r, "truth"), r);
    REQUIRE(truths.size() == profile.size());
    CHECK(deviation(truths[0], profile[0]).norm() == 0.0);
    for (int k = 0; k < K; ++k) {
      const Vec9 d0 = deviation(truths[k], profile[k]), d1 = deviation(truths[k + 1], profile[k + 1]);
      Vec9 w;
      for (int a = 0; a < 3; ++a) {
        const int i = 3 * a;
        w(i) = d1(i) - d0(i) - T * d0(i + 1) - 0.5 * T * T * d0(i + 2);
        w(i + 1) = d1(i + 1) - d0(i + 1) - T * d0(i + 2);
        w(i + 2) = d1(i + 2) - d0(i + 2);
      }
      sum += w * w.transpose();
    }
    const Vec9 d = deviation(truths.back(), profile.back());
    end_sum += d * d.transpose();
  }
  // The covariance after time t from zero: q [[t⁵/20, t⁴/8, t³/6], [t⁴/8, t³/3, t²/2], [t³/6, t²/2, t]].
  auto model = [&](double t) {
    Mat9 m = Mat9::Zero();
    const double c[3][3] = {{std::pow(t, 5) / 20, std::pow(t, 4) / 8, std::pow(t, 3) / 6},
                            {std::pow(t, 4) / 8, std::pow(t, 3) / 3, t * t / 2},
                            {std::pow(t, 3) / 6, t * t / 2, t}};
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m(3 * a + i, 3 * a + j) = q[a] * c[i][j];
    return m;
  };
  const double N = static_cast<double>(R) * K;
  check_covariance<9>(sum / N, model(T), N);
  check_covariance<9>(end_sum / R, model(K * T), R);
}

TEST_CASE("process noise: same seed same path - new run new path") {
  const std::string yaml = kManoeuvres + "process_noise_q: 2 m2/s3\n";
  auto gen = test::make("sim.trajectory", yaml, "truth");
  auto run = [&](std::uint64_t r) {
    test::Collector out;
    out.attach_to(*gen);
    test::drain(*gen, derive_seed(42, r, "truth"), r);
    return out.truths;
  };
  const auto a = run(0), b = run(1), again = run(0);
  const auto fresh = fly(yaml, derive_seed(42, 0, "truth"), 0);
  const Params p = test::params_for("sim.trajectory", kManoeuvres);
  const auto pieces = sim::build_flight_plan(p);
  REQUIRE(a.size() == b.size());
  REQUIRE(a.size() == again.size());
  REQUIRE(a.size() == fresh.size());
  size_t differ = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    CHECK((a[k].position.array() == again[k].position.array()).all());  // start_run starts the stream over
    CHECK((a[k].velocity.array() == fresh[k].velocity.array()).all());  // and depends on nothing but the seed
    CHECK((a[k].acceleration.array() == fresh[k].acceleration.array()).all());
    if ((a[k].position - b[k].position).norm() > 1e-6) ++differ;
    if (k > 0) CHECK((a[k].position - profile_at(pieces, a[k].time).position).norm() > 0.0);
  }
  CHECK(differ == a.size() - 1);  // every sample but the first, which is on the profile in both
  CHECK((a[0].position - b[0].position).norm() == 0.0);
}

TEST_CASE("process noise parameters are checked") {
  const std::string head = "initial_position: [0, 0, 0]\nsegments: [{type: constant_velocity, duration: 1 s}]\n";
  CHECK_THAT(config_error(head + "process_noise_q: 1\nprocess_noise_q_enu: [1, 1, 1]\n"),
             Catch::Matchers::Contains("'process_noise_q_enu'"));
  CHECK_THAT(config_error(head + "process_noise_q: -1\n"), Catch::Matchers::Contains("process_noise_q"));
  CHECK_THAT(config_error(head + "process_noise_q_enu: [1, -1, 1]\n"), Catch::Matchers::Contains("process_noise_q_enu"));
  CHECK_THAT(config_error(head + "process_noise_q_enu: [1, 1]\n"), Catch::Matchers::Contains("process_noise_q_enu"));
  CHECK(config_error(head + "process_noise_q: 1 m2/s3\n").empty());
  CHECK(config_error(head + "process_noise_q_jerk: 1 m2/s5\n").empty());
  CHECK_THAT(config_error(head + "process_noise_q_jerk: 1 m2/s3\n"), Catch::Matchers::Contains("process_noise_q_jerk"));
  CHECK_THAT(config_error(head + "process_noise_q_jerk: 1\nprocess_noise_q_jerk_enu: [1, 1, 1]\n"),
             Catch::Matchers::Contains("'process_noise_q_jerk_enu'"));
  CHECK_THAT(config_error(head + "process_noise_q: 1\nprocess_noise_q_jerk: 1\n"), Catch::Matchers::Contains("not both"));
  CHECK_THAT(config_error(head + "process_noise_q_enu: [1, 1, 1]\nprocess_noise_q_jerk_enu: [1, 1, 1]\n"),
             Catch::Matchers::Contains("not both"));
}

// A jettisoned body starts on its parent's sample grid at the separation, with the parent's state
// plus the separation velocity, then falls freely (closed form) until it is back on the ground.
TEST_CASE("a jettisoned body falls from its parent's state") {
  const std::string flight = R"(
    rate: 10 Hz
    initial_position: [0 m, 0 m, 1000 m]
    initial_velocity: [100 m/s, 0 m/s, 50 m/s]
    segments:
      - {type: constant_velocity, duration: 100 s}
)";
  const auto parent = fly(flight);
  const auto stage = fly(flight + "    target: 1\n    jettison_time: 10.05 s\n    jettison_velocity: [0, -2 m/s, 0]\n");
  REQUIRE(!stage.empty());
  CHECK(stage.front().time == Approx(10.1));  // first sample of the grid at or after the separation
  CHECK(stage.front().target == 1);
  // Both on one grid: the stage's k-th sample is the parent's (101 + k)-th.
  REQUIRE(parent[101].time == stage.front().time);
  const Vec3 p0(100 * 10.05, 0.0, 1000 + 50 * 10.05), v0(100, -2, 50);
  for (const Truth& t : stage) {
    const double tau = t.time - 10.05;
    const Vec3 expected = p0 + v0 * tau + 0.5 * Vec3(0, 0, -9.80665) * tau * tau;
    CHECK((t.position - expected).norm() < 1e-6);
    CHECK(t.acceleration.z() == Approx(-9.80665));
  }
  // Impact at the start's height (1000 m): z0 + vz tau - g tau^2/2 = 1000.
  const double h = p0.z() - 1000.0, g = 9.80665, tau = (50.0 + std::sqrt(50.0 * 50.0 + 2 * g * h)) / g;
  CHECK(stage.back().time <= 10.05 + tau + 1e-9);
  CHECK(stage.back().time > 10.05 + tau - 0.1);
  CHECK(stage.back().position.z() >= 1000.0 - 1e-6);
  // Refusals: outside the flight, a curved earth, the fall's parameters without a jettison.
  CHECK_THAT(config_error(flight + "    jettison_time: 200 s\n"), Catch::Contains("within the flight"));
  CHECK_THAT(config_error(flight + "    gravity: 9 m/s2\n"), Catch::Contains("give jettison_time"));
}
