// Purpose: tests of adapt.quality_switch on filter.ekf and a minimal hand-written filter: q and R written, grades at the thresholds, beacon/skin tables, invalid samples, a whole pipeline.
#include <trackflow/geometry.hpp>
#include <trackflow/host/engine.hpp>
#include <trackflow/host/graph.hpp>

#include <catch2/catch.hpp>

#include <cmath>

#include "plugin_fixture.hpp"

using namespace trackflow;

namespace {

// The grade the adapter published on an estimate for a channel (its annotations 0..2), -1: none yet.
int grade(const Estimate& e, int channel) {
  return channel < e.annotation_count && !std::isnan(e.annotations[channel]) ? static_cast<int>(e.annotations[channel]) : -1;
}

constexpr double kR0 = 100e3, kAz0 = 0.5, kEl0 = 0.2;

// Tables whose every entry differs, so that a read-back names the row it came from.
const char* const kAdapterParams = R"({
  window: 2, reference_range: 1 m, reference_azimuth: 1 mrad, reference_elevation: 1 mrad,
  beacon: [{grade: best,   q_range: 1 m2/s5, q_angle: 1e-12 rad2/s5, sigma_range: 1 m, sigma_angle: 10 urad},
           {grade: normal, q_range: 2 m2/s5, q_angle: 2e-12 rad2/s5, sigma_range: 2 m, sigma_angle: 20 urad},
           {grade: worst,  q_range: 3 m2/s5, q_angle: 3e-12 rad2/s5, sigma_range: 3 m, sigma_angle: 30 urad}],
  skin:   [{grade: best,   q_range: 4 m2/s5, q_angle: 4e-12 rad2/s5, sigma_range: 4 m, sigma_angle: 40 urad},
           {grade: normal, q_range: 5 m2/s5, q_angle: 5e-12 rad2/s5, sigma_range: 5 m, sigma_angle: 50 urad},
           {grade: worst,  q_range: 6 m2/s5, q_angle: 6e-12 rad2/s5, sigma_range: 6 m, sigma_angle: 60 urad}]})";

// The table's sigma and q for (table 0 beacon / 1 skin, grade).
double table_sigma_range(int table, int grade) { return 1.0 + 3 * table + grade; }
double table_sigma_angle(int table, int grade) { return 1e-5 * (1.0 + 3 * table + grade); }
double table_q_range(int table, int grade) { return 1.0 + 3 * table + grade; }
double table_q_angle(int table, int grade) { return 1e-12 * (1.0 + 3 * table + grade); }

Measurement meas(double t, double r, double az = kAz0, double el = kEl0, MeasMode mode = MeasMode::Beacon,
                 bool valid = true) {
  Measurement m;
  m.time = t;
  m.frame = Frame::Spherical;
  m.azimuth = AzimuthConvention::NorthClockwise;
  m.mode = mode;
  m.valid = valid;
  m.sensor_position = Vec3(100.0, -50.0, 10.0);
  m.value = MeasVec(3);
  m.value << r, az, el;
  m.covariance = MeasCov::Zero(3, 3);
  m.covariance.diagonal() << 0.25, 1e-10, 1e-10;
  return m;
}

struct Attached {
  std::shared_ptr<Component> filter, adapter;
  Filter* f = nullptr;
  Adapter* a = nullptr;
  test::Collector out;
  Diagnostics diag;
  Attached(const std::string& adapter_params = kAdapterParams,
           const std::string& filter_params = "{ motion: constant_acceleration, q_jerk: 7 m2/s5 }") {
    filter = test::make("filter.ekf", filter_params, "kf");
    adapter = test::make("adapt.quality_switch", adapter_params, "quality");
    f = dynamic_cast<Filter*>(filter.get());
    a = dynamic_cast<Adapter*>(adapter.get());
    REQUIRE(f);
    REQUIRE(a);
    test::attach(*a, *f);  // the typed contract checked, the configured noise saved, as the engine does
    out.attach_to(*filter);
    test::start_run(*filter, 0, 1, &diag);
    adapter->start_run({0, 1, &diag});
  }
  const Estimate& step(const Measurement& m) {
    filter->on_measurement(m, 0);
    REQUIRE(!out.estimates.empty());
    return out.estimates.back();
  }
  double R(int i) const { return (*f->noise().measurement.R)(i, i); }
  Summary summary() {
    auto r = adapter->end_run();
    adapter->merge(*r);
    Summary s;
    adapter->finish(s, {"quality", "", 1});
    return s;
  }
};

// Independent expectation for filter_q: enu_axes — diag(J diag(q) J') with J differentiated numerically.
Vec3 expected_enu_q(const Vec3& rel, double q_range, double q_az, double q_el) {
  const Vec3 rae = enu_to_spherical(rel, AzimuthConvention::NorthClockwise);
  Mat3 J;
  const double h[3] = {1e-2, 1e-8, 1e-8};
  for (int k = 0; k < 3; ++k) {
    Vec3 a = rae, b = rae;
    a(k) += h[k];
    b(k) -= h[k];
    J.col(k) = (spherical_to_enu(a(0), a(1), a(2), AzimuthConvention::NorthClockwise) -
                spherical_to_enu(b(0), b(1), b(2), AzimuthConvention::NorthClockwise)) /
               (2 * h[k]);
  }
  return (J * Vec3(q_range, q_az, q_el).asDiagonal() * J.transpose()).diagonal();
}

}  // namespace

// the adapter writes the graded rows' R and q into filter.ekf (read back through noise())
TEST_CASE("adapter writes graded R and q into filter.ekf") {
  Attached s;
  // Range steps of 0.5 m (RMSE 0.5 <= 1 m: BEST), azimuth steps of 1.5 mrad (NORMAL), elevation
  // steps of 3 mrad (WORST).
  Estimate previous;
  for (int k = 0; k < 12; ++k) {
    const Estimate before = s.out.estimates.empty() ? Estimate{} : s.out.estimates.back();
    const Estimate& e = s.step(meas(0.025 * k, kR0 + 0.5 * k, kAz0 + 1.5e-3 * k, kEl0 + 3e-3 * k));
    if (k < 2) {
      for (int c = 0; c < 3; ++c) CHECK(grade(e, c) == -1);  // window of 2 differences not yet full
      continue;
    }
    CHECK(grade(e, 0) == 0);
    CHECK(grade(e, 1) == 1);
    CHECK(grade(e, 2) == 2);
    CHECK(s.R(0) == Approx(std::pow(table_sigma_range(0, 0), 2)));
    CHECK(s.R(1) == Approx(std::pow(table_sigma_angle(0, 1), 2)));
    CHECK(s.R(2) == Approx(std::pow(table_sigma_angle(0, 2), 2)));
    CHECK((*s.f->noise().measurement.R)(0, 1) == 0.0);
    // q was set before this update from the previous estimate's geometry.
    REQUIRE(before.initialised);
    const Vec3 expected = expected_enu_q(before.enu.head<3>() - Vec3(100.0, -50.0, 10.0), table_q_range(0, 0),
                                         table_q_angle(0, 1), table_q_angle(0, 2));
    const double* q = s.f->noise().process.values;
    for (int i = 0; i < 3; ++i) CHECK(q[i] == Approx(expected(i)).epsilon(1e-6));
  }
  const Summary sum = s.summary();
  REQUIRE(sum.find("best_fraction_range"));
  CHECK(sum.find("best_fraction_range")->value == 1.0);
  CHECK(sum.find("normal_fraction_azimuth")->value == 1.0);
  CHECK(sum.find("worst_fraction_elevation")->value == 1.0);
  CHECK(sum.find("mean_rmse_range")->value == Approx(0.5));
  CHECK(sum.find("ungraded_steps")->value == 2);
}

// grades at the thresholds: RMSE = M is BEST, = 2M is NORMAL, just above 2M is WORST
TEST_CASE("grades exactly at the M and 2M thresholds") {
  Attached s;
  // Window 2, M = 1 m. Range differences chosen so that the RMS of the last two is exact.
  const double r[] = {0, 1, 2,        // d = 1, 1: RMSE 1 = M                 -> BEST (k = 2)
                      4,              // d = 1, 2: 1.58                      -> NORMAL
                      6,              // d = 2, 2: RMSE 2 = 2M               -> NORMAL
                      8.0000001,      // d = 2, 2.0000001: just above 2M     -> WORST
                      10.5,           // d = 2.0000001, 2.4999999            -> WORST
                      11.0,           // d = 2.4999999, 0.5: 1.80            -> NORMAL
                      11.5,           // d = 0.5, 0.5                        -> BEST
                      12.75,          // d = 0.5, 1.25: 0.95                 -> BEST
                      14.0};          // d = 1.25, 1.25                      -> NORMAL
  const int expected[] = {-1, -1, 0, 1, 1, 2, 2, 1, 0, 0, 1};
  for (int k = 0; k < 11; ++k) {
    const Estimate& e = s.step(meas(0.025 * k, kR0 + r[k]));
    INFO("k = " << k);
    CHECK(grade(e, 0) == expected[k]);
    if (expected[k] >= 0) CHECK(s.R(0) == Approx(std::pow(table_sigma_range(0, expected[k]), 2)));
  }
}

// the table follows the measurement's mode; unknown_mode picks the table for neither
TEST_CASE("table follows the measurement mode") {
  for (const char* unknown : {"beacon", "skin"}) {
    Attached s(std::string(kAdapterParams).substr(0, std::string(kAdapterParams).size() - 1) + ", unknown_mode: " +
               unknown + " }");
    const MeasMode modes[] = {MeasMode::Beacon, MeasMode::Beacon, MeasMode::Beacon, MeasMode::Skin, MeasMode::Skin,
                              MeasMode::Unknown, MeasMode::Beacon};
    int skin_steps = 0;
    for (int k = 0; k < 7; ++k) {
      const Estimate& e = s.step(meas(0.025 * k, kR0 + 0.5 * k, kAz0, kEl0, modes[k]));  // all BEST once graded
      const int table = modes[k] == MeasMode::Skin || (modes[k] == MeasMode::Unknown && std::string(unknown) == "skin");
      skin_steps += table;
      const int range_grade = grade(e, 0) >= 0 ? grade(e, 0) : 1;  // initial_grade normal
      INFO("k = " << k << ", unknown_mode " << unknown);
      CHECK(s.R(0) == Approx(std::pow(table_sigma_range(table, range_grade), 2)));
      CHECK(s.R(1) == Approx(std::pow(table_sigma_angle(table, grade(e, 1) >= 0 ? grade(e, 1) : 1), 2)));
    }
    const Summary sum = s.summary();
    CHECK(sum.find("skin_table_steps")->value == skin_steps);
    CHECK(sum.find("beacon_table_steps")->value == 7 - skin_steps);
    // Both tables were in force: the grades are also split by table. With window 2 the steps from
    // k = 2 on are graded, all BEST here; the beacon (or skin) fraction sums to 1 per channel.
    REQUIRE(sum.find("beacon_best_fraction_range"));
    REQUIRE(sum.find("skin_best_fraction_elevation"));
    CHECK(sum.find("beacon_best_fraction_range")->value == 1.0);
    CHECK(sum.find("skin_best_fraction_azimuth")->value == 1.0);
    CHECK(sum.find("skin_worst_fraction_range")->value == 0.0);
  }
}

// an invalid sample: the filter coasts, the grade is held, no difference is taken across it
TEST_CASE("invalid sample coasts and holds the grade") {
  Attached s;
  // BEST with 0.5 m steps, then an unlocked sample, then the track resumes 50 m further on.
  for (int k = 0; k < 6; ++k) s.step(meas(0.025 * k, kR0 + 0.5 * k));
  const Estimate last_valid = s.out.estimates.back();
  REQUIRE(grade(last_valid, 0) == 0);
  const Estimate& coast = s.step(meas(0.15, 0.0, 0.0, 0.0, MeasMode::Beacon, /*valid=*/false));
  CHECK(coast.initialised);
  CHECK_FALSE(coast.updated);
  CHECK(coast.time == 0.15);
  CHECK(coast.enu.allFinite());
  CHECK((coast.enu.head<3>() - last_valid.enu.head<3>()).norm() > 0.0);  // predicted forward, not frozen
  CHECK(grade(coast, 0) == 0);                                          // held
  // After the gap: 50 m on, then 0.5 m steps. Bridging the gap would give a 50 m difference
  // (WORST) as soon as the window of two is full; restarting it keeps BEST held, then BEST.
  const int expected[] = {0, 0, 0, 0};
  for (int k = 0; k < 4; ++k) {
    const Estimate& e = s.step(meas(0.175 + 0.025 * k, kR0 + 53.0 + 0.5 * k));
    INFO("k = " << k);
    CHECK(e.updated);
    CHECK(grade(e, 0) == expected[k]);
  }
  const Summary sum = s.summary();
  CHECK(sum.find("invalid_steps")->value == 1);
  CHECK(sum.find("window_resets")->value == 1);
  CHECK(sum.find("worst_fraction_range")->value == 0.0);
  // Graded: 4 before the gap (k = 2..5), 2 after (the window of 2 refills over 3 samples).
  CHECK(sum.find("mean_rmse_range")->value == Approx(0.5));
}

// a run that starts unlocked gets the filter's own q back, not the previous run's
TEST_CASE("unlocked run start restores the filter's own q") {
  Attached s;
  for (int k = 0; k < 5; ++k) s.step(meas(0.025 * k, kR0 + 0.5 * k));
  REQUIRE(s.f->noise().process.values[0] != 7.0);  // adapted
  test::start_run(*s.filter, 1, 1, &s.diag);  // as the engine, at the start of every run
  s.adapter->start_run({1, 1, &s.diag});
  s.step(meas(0.0, 0.0, 0.0, 0.0, MeasMode::Beacon, /*valid=*/false));
  for (int i = 0; i < 3; ++i) CHECK(s.f->noise().process.values[i] == 7.0);  // q_jerk of the filter
  s.step(meas(0.025, kR0));
  CHECK(s.f->noise().process.values[0] != 7.0);  // geometry known: the table's again
}

TEST_CASE("line-of-sight q gets channel PSDs scaled") {
  struct StubFilter : Filter {
    MeasCov R = MeasCov::Identity(3, 3);
    double q[3] = {-1, -1, -1};
    NoiseHandles noise() override {
      return {{&R, MeasurementSpace::Spherical}, {q, 3, NoiseKind::SpectralDensity, dim::jerk_psd, NoiseAxes::LineOfSight}};
    }
    void step(const Measurement& m, Estimate& e) {
      before_update(m);
      publish(m, e);
    }
  };
  auto adapter = test::make("adapt.quality_switch");
  auto* a = dynamic_cast<Adapter*>(adapter.get());
  StubFilter f;
  test::attach(*a, f);
  test::Collector out;
  out.attach_to(f);
  Diagnostics d;
  adapter->start_run({0, 1, &d});
  Estimate e;
  e.initialised = true;
  e.enu.setZero();
  const Vec3 sensor(0, 0, 0);
  const Vec3 rel = spherical_to_enu(150e3, 1.0, 0.3, AzimuthConvention::NorthClockwise);
  e.enu.head<3>() = rel;
  // Default tables (Table 13), initial grade normal; beacon normal: q_r 300 cm2/s5, q_angle 0.01 urad2/s5.
  Measurement m = meas(0.0, 150e3, 1.0, 0.3);
  m.sensor_position = sensor;
  f.step(m, e);  // the first step has only the measurement's geometry, which is the same here
  m.time = 0.025;
  f.step(m, e);
  CHECK(f.q[0] == Approx(300e-4));
  CHECK(f.q[1] == Approx(std::pow(150e3 * std::cos(0.3), 2) * 0.01e-12));
  CHECK(f.q[2] == Approx(150e3 * 150e3 * 0.01e-12));
  CHECK(f.R(0, 0) == Approx(0.5 * 0.5));
  CHECK(f.R(1, 1) == Approx(50e-6 * 50e-6));
  CHECK(grade(out.estimates.back(), 0) == -1);
}

// incompatible filters and bad tables are refused with the reason
TEST_CASE("incompatible filters and bad tables are refused") {
  auto adapter = test::make("adapt.quality_switch");
  auto* a = dynamic_cast<Adapter*>(adapter.get());
  auto kalman = test::make("filter.kalman");
  CHECK_THAT(noise_mismatch(a->needs(), dynamic_cast<Filter*>(kalman.get())->noise(), dynamic_cast<Filter*>(kalman.get())->has_covariance_access()),
             Catch::Contains("'cartesian_position'") && Catch::Contains("spherical"));
  struct NoQ : Filter {
    MeasCov R = MeasCov::Identity(3, 3);
    NoiseHandles noise() override { return {{&R, MeasurementSpace::Spherical}, {}}; }
  } no_q;
  CHECK_THAT(noise_mismatch(a->needs(), no_q.noise(), no_q.has_covariance_access()), Catch::Contains("process noise"));
  auto ekf = test::make("filter.ekf", "{ motion: constant_acceleration }");
  CHECK(noise_mismatch(a->needs(), dynamic_cast<Filter*>(ekf.get())->noise(), dynamic_cast<Filter*>(ekf.get())->has_covariance_access()).empty());

  const std::string row = "{grade: best, q_range: 1 m2/s5, q_angle: 1e-12 rad2/s5}";
  CHECK_THROWS_WITH(test::make("adapt.quality_switch", "{ beacon: [" + row + ", " + row + "] }"),
                    Catch::Contains("'best' appears twice"));
  CHECK_THROWS_WITH(test::make("adapt.quality_switch", "{ skin: [" + row + "] }"),
                    Catch::Contains("no row for grade 'normal'"));
  CHECK_THROWS_WITH(test::make("adapt.quality_switch", "{ grade_limits: [2, 1] }"), Catch::Contains("increasing"));
  CHECK_THROWS_WITH(test::make("adapt.quality_switch",
                               "{ beacon: [{grade: best, q_range: 1 m2/s5, q_angle: 1 urad2}] }"),
                    Catch::Contains("q_angle"));
}

// in a pipeline: skin and unlocked windows are counted, results do not depend on the thread count
TEST_CASE("pipeline counts windows independent of threads") {
  const std::string yaml = R"(
pipeline: { name: quality_pipeline, seed: 5, runs: 6 }
nodes:
  - id: truth
    type: sim.trajectory
    params:
      rate: 40 Hz
      initial_position: [60 km, 120 km, 5 km]
      initial_velocity: [-150 m/s, 50 m/s, 0 m/s]
      segments: [{ type: constant_velocity, duration: 30 s }]
  - id: radar
    type: sim.radar
    input: truth
    params:
      noise_model: table4
      default_mode: beacon
      mode_schedule: [{ start: 10 s, end: 15 s, mode: skin, sigma_range: 3 m, sigma_azimuth: 150 urad, sigma_elevation: 150 urad }]
      invalid_schedule: [{ start: 20 s, end: 21 s }]
  - { id: kf, type: filter.ekf, input: radar, params: { motion: constant_acceleration, q_jerk: 1 m2/s5 } }
  - id: quality
    type: adapt.quality_switch
    attach_to: kf
    params: { detrend: true, reference_range: 0.6 m, reference_azimuth: 100 urad, reference_elevation: 100 urad }
  - { id: score, type: sink.metrics, inputs: [kf, truth] }
)";
  host::PipelineConfig cfg = host::parse_pipeline(host::load_yaml_string(yaml, "test.yaml"), "test.yaml");
  const host::Graph g = host::build_graph(cfg, test::registry());
  auto run = [&](unsigned threads) {
    host::RunOptions opt;
    opt.runs = cfg.runs;
    opt.seed = cfg.seed;
    opt.threads = threads;
    return host::run_graph(g, test::registry(), opt);
  };
  const host::Outcome one = run(1), two = run(2);
  const Summary& s = one.find("quality")->summary;
  // 40 Hz: samples 400..599 are skin (t in [10, 15)), 800..839 unlocked (t in [20, 21)).
  CHECK(s.find("steps")->value == 6 * 1201);
  CHECK(s.find("skin_table_steps")->value == 6 * 200);
  CHECK(s.find("invalid_steps")->value == 6 * 40);
  CHECK(s.find("window_resets")->value == 6);
  // Beacon noise is Table 4's 0.3 m: detrended RMSE ~ sqrt(2) 0.3 = 0.42 m, mostly below M = 0.6 m;
  // in the skin window (3 m: 4.2 m) it is WORST.
  CHECK(s.find("worst_fraction_range")->value > 0.9 * 200.0 / 1201.0);
  CHECK(s.find("best_fraction_range")->value > 0.6);
  const Summary& s2 = two.find("quality")->summary;
  REQUIRE(s.metrics.size() == s2.metrics.size());
  for (size_t i = 0; i < s.metrics.size(); ++i) CHECK(s.metrics[i].value == s2.metrics[i].value);
  const Summary& score = one.find("score")->summary;
  REQUIRE(score.find("position_rmse"));
  CHECK(std::isfinite(score.find("position_rmse")->value));
  CHECK(score.find("position_rmse")->value == two.find("score")->summary.find("position_rmse")->value);
}

// the per-table fractions separate the grades of beacon and skin stretches (paper 000 §IV.3)
TEST_CASE("grades are reported per table") {
  Attached s;
  // Beacon: 0.5 m steps (BEST, RMS 0.5 <= M = 1 m); skin: alternating +-1.5 m (RMS 3 m > 2M: WORST).
  int k = 0;
  for (; k < 8; ++k) s.step(meas(0.025 * k, kR0 + 0.5 * k));
  for (int j = 0; j < 8; ++j, ++k) s.step(meas(0.025 * k, kR0 + (j % 2 ? 1.5 : -1.5), kAz0, kEl0, MeasMode::Skin));
  const Summary sum = s.summary();
  // Beacon: graded from its 3rd sample (window 2): 6 BEST. Skin: the first skin step's window holds
  // a beacon difference and the jump (RMS > 2M), then alternating: all 8 WORST.
  CHECK(sum.find("beacon_best_fraction_range")->value == 1.0);
  CHECK(sum.find("skin_worst_fraction_range")->value == 1.0);
  CHECK(sum.find("skin_best_fraction_range")->value == 0.0);
  CHECK(sum.find("best_fraction_range")->value == Approx(6.0 / 14.0));
  // Only one table in force: no per-table split (the overall fractions say it all).
  Attached one;
  for (int j = 0; j < 5; ++j) one.step(meas(0.025 * j, kR0 + 0.5 * j));
  const Summary only = one.summary();
  CHECK(only.find("best_fraction_range"));
  CHECK_FALSE(only.find("beacon_best_fraction_range"));
}
