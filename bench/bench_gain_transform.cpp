// Purpose: benchmark: per-step time of filter.ekf (Singer) vs filter.gain_transform on paper 002's circle, and the multiplication counts of each step.
//
// Usage: trackflow-bench-gain-transform [--reps N] [--trials N] [--plugins DIR]. Single thread; the
// contenders take turns for N trials (default 5) and each keeps its best, by CPU time (this process
// on its core) and by wall time, so other load on a shared machine affects them alike. On one
// pre-generated measurement
// sequence (paper 002 scenario 1: 40 Hz, 1500 m circle around the radar at 150 m altitude,
// 200 m/s, sigma_r 15 m, 3 mrad, one full turn = 1885 measurements), repeated N times:
//   (1) filter.ekf (motion: singer) and filter.gain_transform through their plugins (virtual call,
//       Estimate formed and read by one consumer), the ratio of their step times;
//   (2) the same two algorithms as plain loops without the plugin shell: the gain-transform core
//       and a lean EKF (structured prediction, H-sparse symmetric update), to separate the
//       algorithm from filter.ekf's dense Joseph-form implementation;
//   (3) multiplications per step, counted with a counting scalar (operation_counts.hpp).
#include "bench_common.hpp"
#include "operation_counts.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/host/config.hpp>
#include <trackflow/host/plugins.hpp>
#include <trackflow/host/validate.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/rng.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

using namespace trackflow;
using namespace trackflow::gain_transform;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kT = 0.025, kAlpha = 1.0, kSigmaM = 20.0;

std::vector<Measurement> circle_measurements() {
  const int steps = 1885;
  std::vector<Measurement> ms(steps);
  Rng rng(2);
  const double w = 200.0 / 1500.0, sig[3] = {15.0, 3e-3, 3e-3};
  for (int k = 0; k < steps; ++k) {
    auto& m = ms[k];
    m.time = k * kT;
    m.frame = Frame::Spherical;
    const Vec3 p(1500.0 * std::cos(w * m.time), 1500.0 * std::sin(w * m.time), 150.0);
    m.value = enu_to_spherical(p, AzimuthConvention::NorthClockwise);
    m.covariance = MeasCov::Zero(3, 3);
    for (int i = 0; i < 3; ++i) {
      m.value(i) += sig[i] * rng.normal();
      m.covariance(i, i) = sig[i] * sig[i];
    }
    m.value(1) = wrap_angle(m.value(1));
  }
  return ms;
}

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// A plugin and the consumer that reads each of its estimates (so the whole Estimate is formed).
struct PluginUnderTest {
  std::shared_ptr<Component> filter;
  trackflow::bench::Consumer consumer;
  Link link{};
};

std::unique_ptr<PluginUnderTest> plugin(const host::PluginRegistry& reg, const std::string& type,
                                        const std::string& params) {
  auto p = std::make_unique<PluginUnderTest>();
  p->filter = trackflow::bench::make(reg, type, params);
  p->link = {&p->consumer, 0, 0xFF};
  p->filter->out.connect(&p->link, 1);
  return p;
}

void passes(Component& f, const std::vector<Measurement>& ms, int reps) {
  Diagnostics d;
  for (int rep = 0; rep < reps; ++rep) {
    f.start_run({static_cast<std::uint64_t>(rep), 1, &d});
    for (const auto& m : ms) f.on_measurement(m, 0);
  }
}

SingerAxis<double> singer_axis() {
  const Eigen::Matrix3d F = SingerModel::axis_transition(kAlpha, kT);
  const Eigen::Matrix3d Q = (2.0 * kAlpha) * SingerModel::noise_per_psd(kAlpha, kT);
  return {F(0, 1), F(0, 2), F(1, 2), F(2, 2), {Q(0, 0), Q(0, 1), Q(0, 2), Q(1, 1), Q(1, 2), Q(2, 2)}};
}

// Common start for the plain loops: two-point state from the first two measurements, position
// variances of the converted measurements on the diagonal (enough for timing).
void two_point(const std::vector<Measurement>& ms, double x[9], double var[3]) {
  const Vec3 z0 = spherical_to_enu(ms[0].value(0), ms[0].value(1), ms[0].value(2), AzimuthConvention::NorthClockwise);
  const Vec3 z1 = spherical_to_enu(ms[1].value(0), ms[1].value(1), ms[1].value(2), AzimuthConvention::NorthClockwise);
  for (int a = 0; a < 3; ++a) {
    x[3 * a] = z1(a);
    x[3 * a + 1] = (z1(a) - z0(a)) / kT;
    x[3 * a + 2] = 0.0;
  }
  var[0] = 225.0;
  var[1] = var[2] = std::pow(1500 * 3e-3, 2);
}

// (2a) The gain-transform core as a plain loop (what filter.gain_transform runs, without the
// Estimate and its ENU covariance).
double plain_gain_transform_us(const std::vector<Measurement>& ms, int reps, double& checksum) {
  const SingerAxis<double> model = singer_axis();
  const auto t0 = Clock::now();
  for (int rep = 0; rep < reps; ++rep) {
    double x[9], var[3];
    two_point(ms, x, var);
    AxisCov<double> B[3];
    for (int i = 0; i < 3; ++i) B[i] = {var[i], var[i] / kT, 0, 2 * var[i] / (kT * kT), 0, kSigmaM * kSigmaM};
    LosFrame<double> f;
    const double d1[3] = {x[0], x[3], x[6]};
    line_of_sight_frame(d1, AzimuthConvention::NorthClockwise, f);
    UpdateResult<double> out;
    const bool use[3] = {true, true, true};
    for (size_t k = 2; k < ms.size(); ++k) {
      predict_state(x, model);
      for (auto& b : B) predict_axis(b, model, kSigmaM * kSigmaM);
      LosFrame<double> next;
      const double d[3] = {x[0], x[3], x[6]};
      line_of_sight_frame(d, AzimuthConvention::NorthClockwise, next);
      reframe(B, f.u, next.u);
      f = next;
      const double R[3] = {ms[k].covariance(0, 0), ms[k].covariance(1, 1), ms[k].covariance(2, 2)};
      double rbar[3];
      measurement_variances(B, f, d[2], R, 3.0, rbar);
      const double nu[3] = {ms[k].value(0) - f.h[0], wrap_angle(ms[k].value(1) - f.h[1]), ms[k].value(2) - f.h[2]};
      decoupled_gain(B, f, rbar, use, out);
      correct_state(x, f, nu, use, out);
    }
    checksum += x[0];
  }
  return 1e6 * seconds_since(t0) / (static_cast<double>(reps) * (ms.size() - 2));
}

// (2b) A lean EKF as a plain loop: the replicas counted in operation_counts.hpp, in double.
double plain_lean_ekf_us(const std::vector<Measurement>& ms, int reps, double& checksum) {
  const SingerAxis<double> model = singer_axis();
  const auto t0 = Clock::now();
  for (int rep = 0; rep < reps; ++rep) {
    double x[9], var[3];
    two_point(ms, x, var);
    Eigen::Matrix<double, 9, 9> P = Eigen::Matrix<double, 9, 9>::Zero();
    for (int a = 0; a < 3; ++a) {
      P(3 * a, 3 * a) = var[a];
      P(3 * a, 3 * a + 1) = P(3 * a + 1, 3 * a) = var[a] / kT;
      P(3 * a + 1, 3 * a + 1) = 2 * var[a] / (kT * kT);
      P(3 * a + 2, 3 * a + 2) = kSigmaM * kSigmaM;
    }
    Eigen::Matrix<double, 9, 3> K;
    Eigen::Matrix3d S;
    for (size_t k = 2; k < ms.size(); ++k) {
      predict_state(x, model);
      replica::lean_predict_covariance(P, model, kSigmaM * kSigmaM);
      LosFrame<double> f;
      const double d[3] = {x[0], x[3], x[6]};
      line_of_sight_frame(d, AzimuthConvention::NorthClockwise, f);
      const Eigen::Matrix3d R = ms[k].covariance;
      replica::lean_ekf_gain(P, f.u, f.scale, R, K, S);
      const double nu[3] = {ms[k].value(0) - f.h[0], wrap_angle(ms[k].value(1) - f.h[1]), ms[k].value(2) - f.h[2]};
      for (int r = 0; r < 9; ++r) x[r] += K(r, 0) * nu[0] + K(r, 1) * nu[1] + K(r, 2) * nu[2];
    }
    checksum += x[0];
  }
  return 1e6 * seconds_since(t0) / (static_cast<double>(reps) * (ms.size() - 2));
}

void print_counts(const char* name, const StepCounts& c) {
  std::printf("  %-40s %6lld %6lld %6lld %6lld   %6lld   %6lld   %6lld\n", name, (long long)c.covariance_prediction.mul,
              (long long)c.linearisation.mul, (long long)c.gain_and_covariance_update.mul, (long long)c.state.mul,
              (long long)c.gain_computation().mul, (long long)c.filter().mul, (long long)c.publication.mul);
}

}  // namespace

template <class F>
double fastest(int trials, F&& f) {
  double best = 1e300;
  for (int i = 0; i < trials; ++i) best = std::min(best, f());
  return best;
}

int main(int argc, char** argv) {
  int reps = 300, trials = 5;
  std::string plugin_dir = TRACKFLOW_BENCH_PLUGIN_DIR;  // --plugins: another build's, for before/after
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--plugins")) plugin_dir = argv[i + 1];
    if (!std::strcmp(argv[i], "--reps")) reps = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--trials")) trials = std::max(1, std::atoi(argv[i + 1]));
  }
  host::PluginRegistry reg;
  reg.load_directories({plugin_dir});
  const auto ms = circle_measurements();
  double checksum = 0;
  auto ekf_plugin = plugin(reg, "filter.ekf", "{ motion: singer, singer_alpha: 1 1/s, singer_sigma: 20 m/s2 }");
  auto gt_plugin = plugin(reg, "filter.gain_transform", "{ singer_alpha: 1 1/s, singer_sigma: 20 m/s2 }");
  // The two plugins take turns (and the two plain loops), each keeping its best trial, so other
  // load on a shared machine affects them alike.
  const double steps = static_cast<double>(reps) * ms.size(), plain_steps = static_cast<double>(reps) * (ms.size() - 2);
  trackflow::bench::Rate ekf_rate, gt_rate;
  passes(*ekf_plugin->filter, ms, reps / 10 + 1);
  passes(*gt_plugin->filter, ms, reps / 10 + 1);
  for (int t = 0; t < trials; ++t) {
    ekf_rate.add(steps, trackflow::bench::time_it([&] { passes(*ekf_plugin->filter, ms, reps); }));
    gt_rate.add(steps, trackflow::bench::time_it([&] { passes(*gt_plugin->filter, ms, reps); }));
  }
  plain_gain_transform_us(ms, reps / 10 + 1, checksum);  // warm-up
  plain_lean_ekf_us(ms, reps / 10 + 1, checksum);
  trackflow::bench::Rate plain_gt, plain_lean;
  for (int t = 0; t < trials; ++t) {
    plain_gt.add(plain_steps, trackflow::bench::time_it([&] { plain_gain_transform_us(ms, reps, checksum); }));
    plain_lean.add(plain_steps, trackflow::bench::time_it([&] { plain_lean_ekf_us(ms, reps, checksum); }));
  }
  checksum += ekf_plugin->consumer.sum + gt_plugin->consumer.sum;

  std::printf("paper 002 circle, %zu measurements x %d repetitions, best of %d alternating trials, 1 thread\n",
              ms.size(), reps, trials);
  std::printf("us per step                                     CPU time   wall time\n");
  std::printf("through the plugin (virtual call, Estimate formed and read by a consumer):\n");
  std::printf("  filter.ekf (singer, Joseph form)             %8.3f    %8.3f\n", 1e6 / ekf_rate.cpu, 1e6 / ekf_rate.wall);
  std::printf("  filter.gain_transform                        %8.3f    %8.3f\n", 1e6 / gt_rate.cpu, 1e6 / gt_rate.wall);
  std::printf("  speed-up ekf / gain_transform                %8.2f x  %8.2f x  (aim >= 1.5)\n", gt_rate.cpu / ekf_rate.cpu,
              gt_rate.wall / ekf_rate.wall);
  std::printf("plain loops (no plugin shell, no published covariance):\n");
  std::printf("  lean EKF (structured F, H-sparse update)     %8.3f    %8.3f\n", 1e6 / plain_lean.cpu, 1e6 / plain_lean.wall);
  std::printf("  gain-transform core                          %8.3f    %8.3f\n", 1e6 / plain_gt.cpu, 1e6 / plain_gt.wall);
  std::printf("  speed-up lean EKF / gain-transform core      %8.2f x  %8.2f x\n", plain_gt.cpu / plain_lean.cpu,
              plain_gt.wall / plain_lean.wall);
  std::printf("\nmultiplications per step (counting scalar; divisions and sqrt/atan2/hypot/exp not included):\n");
  std::printf("  %-40s %6s %6s %6s %6s   %6s   %6s   %6s\n", "", "P pred", "lin", "K+P up", "state", "GAIN", "FILTER",
              "publ.");
  const StepCounts ekf = count_filter_ekf_step(), lean = count_lean_ekf_step(), gt = count_gain_transform_step();
  print_counts("filter.ekf before issue 12 (dense)", ekf);
  print_counts("lean EKF", lean);
  print_counts("gain transform (filter.gain_transform)", gt);
  std::printf("  GAIN = P pred + lin + K+P up (paper 002's 'gain computation'); FILTER = GAIN + state\n");
  std::printf("  gain transform vs filter.ekf: gain %+.0f %%, filter %+.0f %%; vs lean EKF: gain %+.0f %%, filter %+.0f %%\n",
              100.0 * (double(gt.gain_computation().mul) / double(ekf.gain_computation().mul) - 1.0),
              100.0 * (double(gt.filter().mul) / double(ekf.filter().mul) - 1.0),
              100.0 * (double(gt.gain_computation().mul) / double(lean.gain_computation().mul) - 1.0),
              100.0 * (double(gt.filter().mul) / double(lean.filter().mul) - 1.0));
  std::printf("  paper 002: gain ~860 -> ~230 (-70 %%), whole filter -55 %%\n");
  std::printf("(checksum %.6g)\n", checksum);
  return 0;
}
