// Purpose: tests of sim.radar's noise options: draw order, SNR and Table 4 models, presets, shot noise, mode and lock schedules.
#include <trackflow/geometry.hpp>
#include <trackflow/rng.hpp>

#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

// A unit direction (compass azimuth 30 deg, elevation 10 deg) the geometry tests place targets along.
const Vec3 kDirection = spherical_to_enu(1.0, std::numbers::pi / 6, std::numbers::pi / 18, AzimuthConvention::NorthClockwise);

Truth truth_at(double t, const Vec3& p, const Vec3& v = Vec3::Zero()) {
  Truth x;
  x.time = t;
  x.position = p;
  x.velocity = v;
  return x;
}

// `n` truths at `range` along kDirection, `dt` apart from t = 0.
std::vector<Truth> still_target(int n, double range, double dt = 0.01) {
  std::vector<Truth> truths;
  truths.reserve(n);
  for (int k = 0; k < n; ++k) truths.push_back(truth_at(k * dt, range * kDirection));
  return truths;
}

std::vector<Measurement> measure(const std::string& yaml, const std::vector<Truth>& truths, std::uint64_t seed = 1) {
  auto radar = test::make("sim.radar", yaml);
  test::Collector out;
  out.attach_to(*radar);
  Diagnostics diag;
  radar->start_run({0, seed, &diag});
  for (const Truth& t : truths) radar->on_truth(t, 0);
  return out.measurements;
}

struct Moments {
  double mean = 0.0, sd = 0.0;
};
Moments moments(const std::vector<double>& x) {
  double s = 0.0;
  for (double v : x) s += v;
  const double mean = s / x.size();
  double ss = 0.0;
  for (double v : x) ss += (v - mean) * (v - mean);
  return {mean, std::sqrt(ss / (x.size() - 1))};
}

// Relative tolerance of a sample sd from n draws at 4 standard errors (se = 1 / sqrt(2n)).
double sd_tolerance(size_t n) { return 4.0 / std::sqrt(2.0 * static_cast<double>(n)); }

// The exact geometry of kDirection targets, as [r, az, el].
Vec3 exact(const Truth& t) { return enu_to_spherical(t.position, AzimuthConvention::NorthClockwise); }

std::string config_error(const std::string& yaml) {
  try {
    (void)test::make("sim.radar", yaml);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return {};
}

double db_to_linear(double db) { return std::pow(10.0, db / 10.0); }

}  // namespace

// the draws follow the documented order: [SNR jitter,] range, azimuth, elevation, range rate
TEST_CASE("the draws follow the documented order") {
  std::vector<Truth> truths;
  for (int k = 0; k < 30; ++k) truths.push_back(truth_at(0.1 * k, Vec3(4000 + 50 * k, -2500, 700), Vec3(500, 20, -3)));
  SECTION("constant model: four normals per look, nothing else") {
    const auto ms = measure("range_rate: true\nsigma_range: 7 m\nsigma_azimuth: 2 mrad\nsigma_elevation: 3 mrad\n"
                            "sigma_range_rate: 0.5 m/s\nbias_range: 4 m",
                            truths, 99);
    Rng rng(99);
    REQUIRE(ms.size() == truths.size());
    for (size_t k = 0; k < ms.size(); ++k) {
      const Vec3 rae = exact(truths[k]);
      const double rr = range_rate(truths[k].position, truths[k].velocity);
      const double n0 = rng.normal(), n1 = rng.normal(), n2 = rng.normal(), n3 = rng.normal();
      CHECK(ms[k].value(0) == Approx(rae(0) + 4 + 7 * n0).epsilon(1e-12));
      CHECK(ms[k].value(1) == Approx(wrap_angle(rae(1) + 2e-3 * n1)).epsilon(1e-12));
      CHECK(ms[k].value(2) == Approx(rae(2) + 3e-3 * n2).epsilon(1e-12));
      CHECK(ms[k].value(3) == Approx(rr + 0.5 * n3).epsilon(1e-12));
      CHECK_FALSE(ms[k].has_snr);
    }
  }
  SECTION("snr model: the SNR jitter is drawn first") {
    const auto ms = measure("noise_model: snr\nsnr_jitter: 3 dB\nsnr_law: beacon_r2\nsnr_reference: 40 dB\n"
                            "snr_reference_range: 5 km\nrange_resolution: 30 m\nbeamwidth_azimuth: 3 deg\n"
                            "beamwidth_elevation: 4 deg\nmonopulse_slope: 1.7",
                            truths, 5);
    Rng rng(5);
    const double bw_az = 3 * std::numbers::pi / 180, bw_el = 4 * std::numbers::pi / 180;
    for (size_t k = 0; k < ms.size(); ++k) {
      const Vec3 rae = exact(truths[k]);
      const double snr_db = 40 - 20 * std::log10(rae(0) / 5000) + 3 * rng.normal();
      const double root = std::sqrt(2 * db_to_linear(snr_db));
      const double n0 = rng.normal(), n1 = rng.normal(), n2 = rng.normal();
      REQUIRE(ms[k].has_snr);
      CHECK(ms[k].snr_db == Approx(snr_db).epsilon(1e-12));
      CHECK(ms[k].value(0) == Approx(rae(0) + 30 / root * n0).epsilon(1e-12));
      CHECK(ms[k].value(1) == Approx(rae(1) + bw_az / (1.7 * root) * n1).epsilon(1e-12));
      CHECK(ms[k].value(2) == Approx(rae(2) + bw_el / (1.7 * root) * n2).epsilon(1e-12));
    }
  }
}

// snr model: sigma from paper 001 eq 6-8 over an R^-4 or R^-2 link budget
TEST_CASE("snr model: sigma from paper 001 eq 6-8") {
  const double dr = 15.0, bw = 2 * std::numbers::pi / 180, km = 1.6;
  for (const char* law : {"radar_r4", "beacon_r2"}) {
    INFO(law);
    const int n_law = std::string(law) == "radar_r4" ? 4 : 2;
    std::vector<Truth> truths;
    const double ranges[] = {2e3, 10e3, 20e3, 80e3, 333e3};
    for (double r : ranges) truths.push_back(truth_at(0, r * kDirection));
    const auto ms = measure(std::string("noise_model: snr\nsnr_law: ") + law, truths);
    REQUIRE(ms.size() == 5);
    for (size_t i = 0; i < ms.size(); ++i) {
      const double snr_db = 30 - 10 * n_law * std::log10(ranges[i] / 10e3);  // defaults: 30 dB at 10 km
      const double snr = db_to_linear(snr_db);
      CHECK(ms[i].snr_db == Approx(snr_db).margin(1e-9));
      CHECK(ms[i].covariance(0, 0) == Approx(dr * dr / (2 * snr)).epsilon(1e-12));
      CHECK(ms[i].covariance(1, 1) == Approx(bw * bw / (km * km * 2 * snr)).epsilon(1e-12));
      CHECK(ms[i].covariance(2, 2) == Approx(bw * bw / (km * km * 2 * snr)).epsilon(1e-12));
    }
    // Doubling the range costs 12.04 dB for a skin echo and 6.02 dB for a beacon.
    CHECK(ms[1].snr_db - ms[2].snr_db == Approx(10 * n_law * std::log10(2.0)));
  }
  SECTION("the noise drawn has the reported sigma") {
    const auto truths = still_target(20000, 50e3);
    const auto ms = measure("noise_model: snr\nsnr_law: beacon_r2", truths, 3);
    const Vec3 rae = exact(truths[0]);
    std::vector<double> er, eaz, eel;
    for (const auto& m : ms) {
      er.push_back((m.value(0) - rae(0)) / std::sqrt(m.covariance(0, 0)));
      eaz.push_back(wrap_angle(m.value(1) - rae(1)) / std::sqrt(m.covariance(1, 1)));
      eel.push_back((m.value(2) - rae(2)) / std::sqrt(m.covariance(2, 2)));
    }
    for (const auto* e : {&er, &eaz, &eel}) {
      const Moments mo = moments(*e);
      CHECK(std::abs(mo.mean) < 4 / std::sqrt(20000.0));
      CHECK(mo.sd == Approx(1.0).epsilon(sd_tolerance(e->size())));
    }
  }
}

// snr jitter: SNR varies per measurement with the given dB sigma, and the covariance follows it
TEST_CASE("snr jitter varies SNR and the covariance follows") {
  const int n = 20000;
  const auto truths = still_target(n, 30e3);
  const auto ms = measure("noise_model: snr\nsnr_jitter: 3 dB\nrange_resolution: 20 m", truths, 11);
  const double link = 30 - 40 * std::log10(3.0);
  std::vector<double> snr, normalised;
  const Vec3 rae = exact(truths[0]);
  for (const auto& m : ms) {
    snr.push_back(m.snr_db);
    CHECK(m.covariance(0, 0) == Approx(400 / (2 * db_to_linear(m.snr_db))).epsilon(1e-12));
    normalised.push_back((m.value(0) - rae(0)) / std::sqrt(m.covariance(0, 0)));
  }
  const Moments s = moments(snr);
  CHECK(std::abs(s.mean - link) < 4 * 3 / std::sqrt(static_cast<double>(n)));
  CHECK(s.sd == Approx(3.0).epsilon(sd_tolerance(n)));
  // The covariance is the sigma actually used: errors over their own sigma are standard normal.
  const Moments e = moments(normalised);
  CHECK(e.sd == Approx(1.0).epsilon(sd_tolerance(n)));
}

// table4 model: paper 000 Table 4 at its rows, held outside, log-log in between
TEST_CASE("table4 model: paper 000 Table 4 interpolation") {
  struct Row {
    double range, snr, sr, sa;
  };
  const Row rows[] = {{158.48e3, 45, 0.3, 50e-6}, {1000e3, 29, 1.9, 320e-6}, {1500e3, 25.47, 3.0, 500e-6}, {2000e3, 22.97, 4.3, 630e-6}};
  std::vector<Truth> truths;
  for (const Row& r : rows) truths.push_back(truth_at(0, r.range * kDirection));
  truths.push_back(truth_at(0, 20e3 * kDirection));    // inside the first row's span
  truths.push_back(truth_at(0, 3000e3 * kDirection));  // beyond the table
  for (int i = 0; i < 3; ++i) truths.push_back(truth_at(0, std::sqrt(rows[i].range * rows[i + 1].range) * kDirection));
  const auto ms = measure("noise_model: table4\nrange_rate: true\nsigma_range_rate: 0.2 m/s", truths);
  REQUIRE(ms.size() == 9);
  auto check = [](const Measurement& m, double snr, double sr, double sa) {
    CHECK(m.has_snr);
    CHECK(m.snr_db == Approx(snr).epsilon(1e-9));
    CHECK(m.covariance(0, 0) == Approx(sr * sr).epsilon(1e-9));
    CHECK(m.covariance(1, 1) == Approx(sa * sa).epsilon(1e-9));
    CHECK(m.covariance(2, 2) == Approx(sa * sa).epsilon(1e-9));
    CHECK(m.covariance(3, 3) == Approx(0.04).epsilon(1e-12));
  };
  for (int i = 0; i < 4; ++i) check(ms[i], rows[i].snr, rows[i].sr, rows[i].sa);
  check(ms[4], 45, 0.3, 50e-6);
  check(ms[5], 22.97, 4.3, 630e-6);
  // At the geometric mean of two rows' ranges: S/N halfway in dB, sigma the geometric mean.
  for (int i = 0; i < 3; ++i)
    check(ms[6 + i], 0.5 * (rows[i].snr + rows[i + 1].snr), std::sqrt(rows[i].sr * rows[i + 1].sr),
          std::sqrt(rows[i].sa * rows[i + 1].sa));
  // The table's S/N is an R^-2 law (a beacon link): 20 dB per decade from 45 dB at 158.48 km.
  for (int i = 0; i < 4; ++i) CHECK(ms[i].snr_db == Approx(45 - 20 * std::log10(rows[i].range / 158.48e3)).margin(0.03));
}

// noise presets and noise_factor multiply every sigma, in every model
TEST_CASE("noise presets and noise_factor scale every sigma") {
  const auto truths = still_target(20000, 8e3);
  const std::string base = "range_rate: true\nsigma_range: 4 m\nsigma_azimuth: 1 mrad\nsigma_elevation: 2 mrad\nsigma_range_rate: 0.3 m/s\n";
  struct Case {
    const char* yaml;
    double factor;
  };
  for (const Case& c : {Case{"noise_preset: none", 1}, Case{"noise_preset: normal", 1}, Case{"noise_preset: best", 0.5},
                        Case{"noise_preset: worst", 2}, Case{"noise_factor: 5", 5}, Case{"noise_factor: 5\nnoise_preset: worst", 10}}) {
    INFO(c.yaml);
    const auto ms = measure(base + c.yaml, {truths.begin(), truths.begin() + 3});
    const Eigen::Vector4d expected = Eigen::Vector4d(4, 1e-3, 2e-3, 0.3).array().square() * c.factor * c.factor;
    CHECK(ms[0].covariance.diagonal().isApprox(expected, 1e-12));
  }
  SECTION("the drawn noise is scaled as the covariance says") {
    const auto ms = measure(base + "noise_factor: 5\nnoise_preset: worst", truths, 8);
    const Vec3 rae = exact(truths[0]);
    std::vector<double> er, eel, err;
    for (const auto& m : ms) {
      er.push_back(m.value(0) - rae(0));
      eel.push_back(m.value(2) - rae(2));
      err.push_back(m.value(3));
    }
    CHECK(moments(er).sd == Approx(40).epsilon(sd_tolerance(er.size())));
    CHECK(moments(eel).sd == Approx(20e-3).epsilon(sd_tolerance(eel.size())));
    CHECK(moments(err).sd == Approx(3).epsilon(sd_tolerance(err.size())));
  }
  SECTION("reported_noise: nominal draws the degraded noise but reports the nominal covariance") {
    const auto ms = measure(base + "noise_factor: 5\nreported_noise: nominal", truths, 8);
    const Vec3 rae = exact(truths[0]);
    std::vector<double> er;
    for (const auto& m : ms) er.push_back(m.value(0) - rae(0));
    CHECK(moments(er).sd == Approx(20).epsilon(sd_tolerance(er.size())));
    const Eigen::Vector4d nominal = Eigen::Vector4d(4, 1e-3, 2e-3, 0.3).array().square();
    CHECK(ms[0].covariance.diagonal().isApprox(nominal, 1e-12));
  }
  SECTION("snr and table4 sigmas are scaled too") {
    const auto plain = measure("noise_model: snr", {truths[0]});
    const auto worse = measure("noise_model: snr\nnoise_preset: best\nnoise_factor: 3", {truths[0]});
    CHECK(worse[0].covariance(0, 0) == Approx(2.25 * plain[0].covariance(0, 0)));
    CHECK(worse[0].snr_db == plain[0].snr_db);  // the factors scale sigma, not the reported SNR
    const auto t4 = measure("noise_model: table4\nnoise_preset: worst", {truths[0]});
    CHECK(t4[0].covariance(0, 0) == Approx(4 * 0.09));
  }
}

// shot noise: bursts of shot_length samples every shot_period multiply sigma, the covariance stays nominal
TEST_CASE("shot noise bursts scale sigma but not covariance") {
  const int n = 400;
  std::vector<Truth> truths;
  for (int k = 0; k < n; ++k) truths.push_back(truth_at(0.025 * k, Vec3(3000 + 10 * k, 9000, 1200), Vec3(400, 0, 0)));
  const std::string base = "range_rate: true\nsigma_range: 10 m\nsigma_azimuth: 1 mrad\nsigma_elevation: 1 mrad\n";
  const auto clean = measure(base, truths, 21);
  const auto shot = measure(base + "shot_noise: true\nshot_length: 3\nshot_period: 50\nshot_offset: 7\nshot_magnitude: 1e6", truths, 21);
  REQUIRE(shot.size() == clean.size());
  int bursts = 0;
  for (int k = 0; k < n; ++k) {
    INFO("sample " << k);
    const bool in_burst = k >= 7 && (k - 7) % 50 < 3;
    const Measurement &s = shot[k], &c = clean[k];
    CHECK(s.value.allFinite());
    CHECK((s.value(1) > -std::numbers::pi && s.value(1) <= std::numbers::pi));
    CHECK(s.covariance == c.covariance);  // nominal: the radar does not know about the burst
    if (!in_burst) {
      CHECK(s.value == c.value);  // the same draws: outside bursts nothing changes
      continue;
    }
    ++bursts;
    const Vec3 rae = exact(truths[k]);
    const double rr = range_rate(truths[k].position, truths[k].velocity);
    // Same standard normal, sigma x 1e6 (azimuth is wrapped, so compared on the other channels).
    CHECK((s.value(0) - rae(0)) == Approx(1e6 * (c.value(0) - rae(0))).epsilon(1e-6));
    CHECK((s.value(2) - rae(2)) == Approx(1e6 * (c.value(2) - rae(2))).epsilon(1e-6));
    CHECK((s.value(3) - rr) == Approx(1e6 * (c.value(3) - rr)).epsilon(1e-6));
  }
  CHECK(bursts == 8 * 3);

  SECTION("paper defaults: 10 samples every 4000, the first burst one period in") {
    const auto far = still_target(12001, 100e3);
    const auto a = measure("", far, 4);
    const auto b = measure("shot_noise: true", far, 4);
    std::vector<int> changed;
    for (size_t k = 0; k < a.size(); ++k)
      if (a[k].value != b[k].value) changed.push_back(static_cast<int>(k));
    std::vector<int> expected;
    for (int start : {4000, 8000, 12000})
      for (int j = 0; j < 10 && start + j <= 12000; ++j) expected.push_back(start + j);
    CHECK(changed == expected);
  }
  SECTION("the sample count restarts each run") {
    auto radar = test::make("sim.radar", base + "shot_noise: true\nshot_length: 2\nshot_period: 5\nshot_offset: 0");
    test::Collector out;
    out.attach_to(*radar);
    Diagnostics diag;
    for (std::uint64_t run = 0; run < 2; ++run) {
      radar->start_run({run, 3, &diag});
      for (int k = 0; k < 4; ++k) radar->on_truth(truths[k], 0);
    }
    REQUIRE(out.measurements.size() == 8);
    for (int k = 0; k < 4; ++k) CHECK(out.measurements[k].value == out.measurements[k + 4].value);
  }
}

// mode schedule: mode and sigma overrides per window, default_mode outside
TEST_CASE("mode schedule overrides mode and sigma per window") {
  const int n = 5000;
  const auto truths = still_target(n, 20e3);  // t = 0 .. 49.99 s
  const auto ms = measure(R"(
    sigma_range: 10 m
    default_mode: skin
    noise_preset: worst
    mode_schedule:
      - {start: 30 s, end: 40 s, mode: skin, sigma_azimuth: 4 mrad}
      - {start: 10 s, end: 20 s, mode: beacon, sigma_range: 0.5 m}
  )", truths, 17);
  REQUIRE(ms.size() == static_cast<size_t>(n));
  const Vec3 rae = exact(truths[0]);
  std::vector<double> beacon_err, skin_az_err;
  for (const auto& m : ms) {
    INFO("t = " << m.time);
    const bool beacon = m.time >= 10 && m.time < 20, overridden = m.time >= 30 && m.time < 40;
    CHECK(m.mode == (beacon ? MeasMode::Beacon : MeasMode::Skin));
    // Overrides replace the model's sigma, then the preset (x2) scales them like every sigma.
    CHECK(m.covariance(0, 0) == Approx(beacon ? 1.0 : 400.0));
    CHECK(m.covariance(1, 1) == Approx(overridden ? 64e-6 : 4e-6));
    CHECK(m.covariance(2, 2) == Approx(4e-6));
    if (beacon) beacon_err.push_back(m.value(0) - rae(0));
    if (overridden) skin_az_err.push_back(wrap_angle(m.value(1) - rae(1)));
  }
  REQUIRE(beacon_err.size() >= 999);
  REQUIRE(beacon_err.size() <= 1001);
  CHECK(moments(beacon_err).sd == Approx(1.0).epsilon(sd_tolerance(beacon_err.size())));
  CHECK(moments(skin_az_err).sd == Approx(8e-3).epsilon(sd_tolerance(skin_az_err.size())));

  SECTION("without a schedule the mode stays unknown, as before") {
    const auto plain = measure("{}", {truths[0]});
    CHECK(plain[0].mode == MeasMode::Unknown);
  }
}

// invalid schedule: measurements in its windows are flagged invalid, finite, with the same draws
TEST_CASE("invalid schedule flags measurements in its windows") {
  std::vector<Truth> truths;
  for (int k = 0; k <= 100; ++k) truths.push_back(truth_at(0.1 * k, Vec3(1000 + 50 * k, 2000, 300), Vec3(500, 0, 0)));
  const auto plain = measure("range_rate: true", truths, 6);
  const auto ms = measure("range_rate: true\ninvalid_schedule: [{start: 2 s, end: 3.5 s}, {start: 9 s, end: 100 s}]", truths, 6);
  REQUIRE(ms.size() == truths.size());
  int invalid = 0;
  for (size_t k = 0; k < ms.size(); ++k) {
    const double t = truths[k].time;
    const bool unlocked = (t >= 2 && t < 3.5) || t >= 9;
    INFO("t = " << t);
    CHECK(ms[k].valid == !unlocked);
    CHECK(ms[k].value.allFinite());
    CHECK(ms[k].value == plain[k].value);
    CHECK(ms[k].covariance == plain[k].covariance);
    invalid += unlocked;
  }
  CHECK(invalid == 15 + 11);
}

// all options on: same seed, same output; another seed, another
TEST_CASE("all options on: output is determined by the seed") {
  std::vector<Truth> truths;
  for (int k = 0; k < 300; ++k) truths.push_back(truth_at(0.025 * k, Vec3(20e3 + 100 * k, 5e3, 2e3), Vec3(4000, 0, 50)));
  const std::string yaml = R"(
    noise_model: snr
    snr_jitter: 3 dB
    snr_law: beacon_r2
    range_rate: true
    noise_factor: 2
    noise_preset: best
    shot_noise: true
    shot_length: 4
    shot_period: 60
    mode_schedule: [{start: 1 s, end: 4 s, mode: beacon, sigma_range: 1 m}]
    default_mode: skin
    invalid_schedule: [{start: 5 s, end: 6 s}]
  )";
  const auto a = measure(yaml, truths, 1234), b = measure(yaml, truths, 1234), c = measure(yaml, truths, 1235);
  REQUIRE(a.size() == truths.size());
  int differing = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    CHECK(a[k].value == b[k].value);
    CHECK(a[k].covariance == b[k].covariance);
    CHECK(a[k].snr_db == b[k].snr_db);
    CHECK(a[k].mode == b[k].mode);
    CHECK(a[k].valid == b[k].valid);
    CHECK(a[k].value.allFinite());
    differing += a[k].snr_db != c[k].snr_db;
  }
  CHECK(differing == static_cast<int>(a.size()));
}

// the snr model stays finite at the radar and far beyond any sensible range
TEST_CASE("snr model stays finite at zero and huge range") {
  const std::vector<Truth> truths = {truth_at(0, Vec3::Zero(), Vec3(10, 0, 0)), truth_at(1, 1e-9 * kDirection),
                                     truth_at(2, 1e12 * kDirection), truth_at(3, 1e300 * kDirection)};
  for (const char* extra : {"", "\nshot_noise: true\nshot_offset: 0\nshot_length: 4\nshot_period: 4"}) {
    const auto ms = measure(std::string("noise_model: snr\nrange_rate: true\nsnr_jitter: 30 dB") + extra, truths);
    REQUIRE(ms.size() == truths.size());
    for (const auto& m : ms) {
      CHECK(m.value.allFinite());
      CHECK(m.covariance.allFinite());
      CHECK(m.covariance.diagonal().minCoeff() > 0.0);
      CHECK(std::isfinite(m.snr_db));
      CHECK(m.snr_db >= -200.0);
      CHECK(m.snr_db <= 300.0);
    }
  }
}

// noise options that conflict or do not apply are refused, naming the parameter
TEST_CASE("conflicting noise options are refused") {
  struct Case {
    const char* yaml;
    const char* name;
  };
  const Case cases[] = {
      {"noise_model: snr\nsigma_range: 3 m", "sigma_range"},
      {"noise_model: table4\nsigma_azimuth: 3 mrad", "sigma_azimuth"},
      {"range_resolution: 10 m", "range_resolution"},
      {"noise_model: table4\nsnr_jitter: 3 dB", "snr_jitter"},
      {"shot_period: 100", "shot_period"},
      {"shot_noise: true\nshot_length: 11\nshot_period: 10", "shot_length"},
      {"shot_noise: true\nshot_period: 0", "shot_period"},
      {"noise_model: snr\nsnr_jitter: -1 dB", "snr_jitter"},
      {"noise_model: snr\nsnr_reference: 3 m", "snr_reference"},
      {"noise_preset: terrible", "noise_preset"},
      {"noise_factor: -1", "noise_factor"},
      {"mode_schedule: [{start: 1 s, end: 2 s}]", "mode"},
      {"mode_schedule: [{start: 1 s, end: 2 s, mode: radar}]", "mode"},
      {"mode_schedule: [{start: 1 s, end: 2 s, mode: skin, sigma_range: -1 m}]", "sigma_range"},
      {"invalid_schedule: [{start: 1 s, end: 1 s}]", "end"},
      {"invalid_schedule: [{start: 1 s}]", "end"},
  };
  for (const auto& c : cases) {
    INFO(c.yaml);
    CHECK_THAT(config_error(c.yaml), Catch::Matchers::Contains(std::string("'") + c.name + "'"));
  }
  const std::string overlap =
      config_error("mode_schedule:\n  - {start: 0 s, end: 10 s, mode: skin}\n  - {start: 20 s, end: 30 s, mode: beacon}\n"
                   "  - {start: 9 s, end: 12 s, mode: beacon}\n");
  CHECK_THAT(overlap, Catch::Matchers::Contains("entry 3") && Catch::Matchers::Contains("overlaps entry 1"));
  // Adjacent windows ([0, 10) then [10, 20)) do not overlap.
  CHECK(config_error("invalid_schedule: [{start: 0 s, end: 10 s}, {start: 10 s, end: 20 s}]").empty());
}
