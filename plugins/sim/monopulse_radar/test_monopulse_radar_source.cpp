// Purpose: tests of sim.monopulse_radar through the plugin: each effect alone against its closed form, misses, stream independence, determinism, refused parameters.
#include "monopulse_antenna.hpp"
#include "process_statistics.hpp"
#include "radar_equation.hpp"

#include <trackflow/error.hpp>
#include <trackflow/geometry.hpp>

#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

using namespace trackflow;

namespace {

const double kBeamwidth = 1.1 * std::numbers::pi / 180;
const Vec3 kDirection = spherical_to_enu(1.0, 0.7, 0.3, AzimuthConvention::NorthClockwise);  // az 0.7, el 0.3 rad

// `n` looks of a still target at `range` along kDirection, `dt` apart: angle errors (measured - true).
struct Looks {
  std::vector<double> az, el, snr_db;
  std::vector<bool> valid;
};
Looks look(const std::string& yaml, double range, int n, double dt, std::uint64_t seed = 1) {
  auto radar = test::make("sim.monopulse_radar", yaml);
  test::Collector out;
  out.attach_to(*radar);
  Diagnostics diag;
  radar->start_run({0, seed, &diag});
  Truth t;
  t.position = range * kDirection;
  for (int k = 0; k < n; ++k) {
    t.time = k * dt;
    radar->on_truth(t, 0);
  }
  Looks l;
  for (const auto& m : out.measurements) {
    l.az.push_back(wrap_angle(m.value(1) - 0.7));
    l.el.push_back(m.value(2) - 0.3);
    l.snr_db.push_back(m.snr_db);
    l.valid.push_back(m.valid);
  }
  return l;
}

std::string fixed(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

double mean_square(const std::vector<double>& x) {
  double s = 0;
  for (double v : x) s += v * v;
  return s / static_cast<double>(x.size());
}

}  // namespace

// Glint alone (linear antenna, constant RCS, no thermal): the angle is the linear glint over the range
// (eq 3-11), RMS 9.5 m / r per plane. 100 000 looks 10 s apart (independent: the DAR(1) renews with
// probability 1 - exp(-20 pi)). Per-plane fourth moment 1.5 E g^4 = 143 708 m^4: the standard error of
// r^2 <az^2> is sqrt((143 708 - 90.25^2) / n) = 1.16 m^2; bound 5 of them. At 10 and 40 km alike.
TEST_CASE("glint alone is 9.5 m over range") {
  const std::string yaml = "{ antenna: linear, rcs_model: constant, thermal: false }";
  const int n = 100000;
  const double se = std::sqrt((143708.0 - 90.25 * 90.25) / n);
  for (double r : {10e3, 40e3}) {
    const Looks l = look(yaml, r, n, 10.0);
    CHECK(std::abs(r * r * mean_square(l.az) - 90.25) < 5 * se);
    CHECK(std::abs(r * r * mean_square(l.el) - 90.25) < 5 * se);
  }
}

// Thermal alone (linear antenna, constant RCS, no glint): SNR from eq 4.1 and an angle sigma of
// beamwidth / (|k_m| sqrt(2 SNR)) in each axis. 20 000 looks: the variance's relative standard error is
// sqrt(2 / n) = 1 %; bound 5 of them.
TEST_CASE("thermal alone follows the radar equation") {
  const std::string yaml = "{ antenna: linear, rcs_model: constant, glint: false, integration_gain: 20 dB, detection_threshold: -200 dB }";
  const int n = 20000;
  for (double r : {60e3, 150e3}) {
    const Looks l = look(yaml, r, n, 0.05);
    sim::RadarEquation eq;
    eq.wavelength = 54.55e-3;
    eq.antenna_gain = std::pow(10.0, 4.1);
    eq.noise_figure = std::pow(10.0, 1.2);
    eq.integration_gain = 100;
    const double snr = eq.snr(std::pow(10.0, 0.56), r);
    CHECK(l.snr_db.front() == Approx(10 * std::log10(snr)).epsilon(1e-9));
    const double sigma = kBeamwidth / (std::abs(sim::FourHornMonopulse().slope()) * std::sqrt(2 * snr));
    CHECK(std::abs(mean_square(l.az) / (sigma * sigma) - 1) < 5 * std::sqrt(2.0 / n));
    CHECK(std::abs(mean_square(l.el) / (sigma * sigma) - 1) < 5 * std::sqrt(2.0 / n));
  }
}

// RCS alone shows in the SNR: Swerling II makes SNR / SNR_mean exponential (mean 1, P(x < 0.1) =
// 1 - e^-0.1); 40 000 independent looks, 5 standard errors. Below the 13 dB threshold at a 20 dB mean the
// look is missed: P = 1 - exp(-10^-0.7) = 0.181.
TEST_CASE("swerling2 snr is exponential and fades are missed") {
  const std::string yaml = "{ antenna: linear, glint: false, integration_gain: 30 dB, detection_threshold: 13 dB }";
  const int n = 40000;
  const double r = 10e3 * std::pow(10.0, (-6.6231 + 40 * std::log10(25.0) + 30 - 20) / 40);  // mean SNR 20 dB
  const Looks l = look(yaml, r, n, 10.0);
  sim::RadarEquation eq;
  eq.wavelength = 54.55e-3;
  eq.antenna_gain = std::pow(10.0, 4.1);
  eq.noise_figure = std::pow(10.0, 1.2);
  eq.integration_gain = 1000;
  const double mean_snr = eq.snr(std::pow(10.0, 0.56), r);
  double sum = 0, below = 0, missed = 0;
  for (int i = 0; i < n; ++i) {
    const double x = std::pow(10.0, l.snr_db[i] / 10) / mean_snr;
    sum += x;
    below += x < 0.1;
    missed += !l.valid[i];
  }
  CHECK(std::abs(sum / n - 1) < 5 / std::sqrt(static_cast<double>(n)));
  const double p = 1 - std::exp(-0.1);
  CHECK(std::abs(below / n - p) < 5 * std::sqrt(p * (1 - p) / n));
  const double q = 1 - std::exp(-std::pow(10.0, 13.0 / 10) / std::pow(10.0, 20.0 / 10));
  CHECK(10 * std::log10(mean_snr) == Approx(20).margin(0.01));
  CHECK(std::abs(missed / n - q) < 5 * std::sqrt(q * (1 - q) / n));
}

// Pointing 0.25 beamwidths off the target, the four-horn antenna reports the target's offset through its
// curved error signal: measured - true = pointing + beamwidth x reported(-0.25): the non-linear error of
// eq 2-1..2-12, -2.0e-3 beamwidths here. The linear antenna reports the truth exactly.
TEST_CASE("four horn error is non-linear off boresight") {
  const double delta = 0.25 * kBeamwidth;
  const std::string common = "rcs_model: constant, glint: false, thermal: false, sigma_range: 0 m, pointing_error_azimuth: " +
                             fixed(delta) + " rad, pointing_error_elevation: 0 rad";
  const Looks four = look("{ " + common + " }", 50e3, 3, 0.05);
  const Looks lin = look("{ antenna: linear, " + common + " }", 50e3, 3, 0.05);
  double u_az, u_el;
  sim::FourHornMonopulse().reported_offset(-0.25, 0.0, u_az, u_el);
  CHECK(four.az[0] == Approx(delta + kBeamwidth * u_az).margin(1e-12));
  CHECK(four.az[0] / kBeamwidth == Approx(-1.996e-3).margin(2e-6));
  CHECK(four.el[0] == Approx(0).margin(1e-12));
  CHECK(lin.az[0] == Approx(0).margin(1e-12));
}

// Each effect draws from its own stream: with the linear antenna (errors add), glint + thermal minus
// thermal alone is exactly glint alone, run by run.
TEST_CASE("effects draw from independent streams") {
  const std::string base = "antenna: linear, rcs_model: swerling2, integration_gain: 30 dB, detection_threshold: -200 dB";
  const Looks both = look("{ " + base + " }", 30e3, 200, 0.05, 8);
  const Looks thermal = look("{ " + base + ", glint: false }", 30e3, 200, 0.05, 8);
  const Looks glint = look("{ antenna: linear, rcs_model: swerling2, thermal: false }", 30e3, 200, 0.05, 8);
  for (int i = 0; i < 200; ++i) {
    CHECK(both.az[i] - thermal.az[i] == Approx(glint.az[i]).margin(1e-12));
    CHECK(both.el[i] - thermal.el[i] == Approx(glint.el[i]).margin(1e-12));
  }
}

TEST_CASE("same seed gives the same measurements") {
  const Looks a = look("{}", 30e3, 500, 0.05, 5), b = look("{}", 30e3, 500, 0.05, 5), c = look("{}", 30e3, 500, 0.05, 6);
  CHECK(a.az == b.az);
  CHECK(a.el == b.el);
  CHECK(a.az != c.az);
}

TEST_CASE("parameters of an effect that is off are refused") {
  CHECK_THROWS_AS(test::make("sim.monopulse_radar", "{ rcs_scan_period: 2 s }"), ConfigError);
  CHECK_THROWS_AS(test::make("sim.monopulse_radar", "{ glint: false, glint_bandwidth: 2 Hz }"), ConfigError);
  CHECK_THROWS_AS(test::make("sim.monopulse_radar", "{ thermal: false, wavelength: 3 cm }"), ConfigError);
  CHECK_THROWS_AS(test::make("sim.monopulse_radar", "{ antenna: linear, squint: 0.4 }"), ConfigError);
  CHECK_NOTHROW(test::make("sim.monopulse_radar", "{ rcs_model: swerling3, rcs_scan_period: 2 s }"));
}

// The summary's estimators on a hand-made series: variance about zero for the glint, lag-1 coefficients
// as written in process_statistics.hpp, computed here directly.
TEST_CASE("process statistics estimators") {
  sim::ProcessStatistics s;
  const double g[] = {1.0, -2.0, 0.5, 3.0}, x[] = {0.5, 1.5, 2.0, 0.2};
  for (int k = 0; k < 4; ++k) {
    ++s.looks;
    ++s.glint_n;
    s.g2 += g[k] * g[k];
    s.x += x[k];
    s.x2 += x[k] * x[k];
    if (k > 0) {
      ++s.pairs;
      s.time_steps += 0.05;
      s.g_lag += g[k] * g[k - 1];
      s.g_prev2 += g[k - 1] * g[k - 1];
      s.x_lag += x[k] * x[k - 1];
      s.x_prev += x[k - 1];
      s.x_cur_paired += x[k];
    }
  }
  CHECK(s.glint_variance() == Approx((1 + 4 + 0.25 + 9) / 4.0));
  CHECK(s.glint_lag1() == Approx((-2 - 1 + 1.5) / (1 + 4 + 0.25)));
  const double m = 4.2 / 4, var = (0.25 + 2.25 + 4 + 0.04) / 4 - m * m;
  CHECK(s.rcs_variance() == Approx(var));
  const double cov = ((0.5 - m) * (1.5 - m) + (1.5 - m) * (2.0 - m) + (2.0 - m) * (0.2 - m)) / 3;
  CHECK(s.rcs_lag1() == Approx(cov / var));
  CHECK(s.mean_step() == Approx(0.05));
  CHECK(sim::ProcessStatistics::correlation_time(std::exp(-1.0), 0.05) == Approx(0.05));
}
