// Purpose: benchmark: quickstart pipeline vs the same computation as a plain loop, and the 6-state Kalman step.
//
// Usage: trackflow-bench [--runs N] [--steps N]. Single thread. Prints measurements/s of
//   (1) the quickstart pipeline through the engine and plugins,
//   (2) the same simulation, conversion, CV Kalman filter and error/NEES bookkeeping written
//       as one plain loop over fixed-size Eigen (same SDK math headers),
//   (3) one Kalman step through the filter.kalman plugin (virtual call, no consumers) and a
//       plain fixed-size Eigen step, on pre-generated measurements.
#include <trackflow/geometry.hpp>
#include <trackflow/host/engine.hpp>
#include <trackflow/host/validate.hpp>
#include <trackflow/kalman.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/rng.hpp>

#include <Eigen/Cholesky>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

using namespace trackflow;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// (2) The quickstart computation without the framework. Same parameters as pipelines/quickstart.yaml.
double plain_loop(int runs, double& checksum) {
  using M = ConstantVelocity;
  const double T = 0.1, q = 0.001, sr = 10.0, sa = 1e-3, se = 1e-3;
  const int steps = 601;
  const Vec3 p0(6000, 8000, 1000), v0(-150, 50, 0);
  M::Matrix F, Q;
  M::transition(T, F);
  M::block_diagonal(M::axis_noise_continuous(T, q), Q);
  Eigen::Matrix<double, 3, 6> H = Eigen::Matrix<double, 3, 6>::Zero();
  for (int a = 0; a < 3; ++a) H(a, M::position_index(a)) = 1;
  std::vector<double> sq_err(steps), nees(steps), meas_sq(steps);
  const auto t0 = Clock::now();
  for (int run = 0; run < runs; ++run) {
    Rng rng(derive_seed(1, run, "radar"));
    M::State x;
    M::Matrix P;
    Vec3 z1;
    Mat3 R1;
    for (int k = 0; k < steps; ++k) {
      const double t = k * T;
      const Vec3 p = p0 + v0 * t;
      const Vec3 s = enu_to_spherical(p, AzimuthConvention::NorthClockwise);
      const double r = s(0) + sr * rng.normal(), az = wrap_angle(s(1) + sa * rng.normal()), el = s(2) + se * rng.normal();
      const Vec3 z = spherical_to_enu(r, az, el, AzimuthConvention::NorthClockwise);
      const Mat3 J = spherical_to_enu_jacobian(r, az, el, AzimuthConvention::NorthClockwise);
      Mat3 R = J * Vec3(sr * sr, sa * sa, se * se).asDiagonal() * J.transpose();
      R = 0.5 * (R + R.transpose()).eval();
      meas_sq[k] += (z - p).squaredNorm();
      if (k == 0) {
        z1 = z;
        R1 = R;
        continue;
      }
      if (k == 1) {
        x.setZero();
        P.setZero();
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) {
            P(2 * a, 2 * b) = R(a, b);
            P(2 * a, 2 * b + 1) = P(2 * b + 1, 2 * a) = R(a, b) / T;
            P(2 * a + 1, 2 * b + 1) = (R(a, b) + R1(a, b)) / (T * T);
          }
        for (int a = 0; a < 3; ++a) {
          x(2 * a) = z(a);
          x(2 * a + 1) = (z(a) - z1(a)) / T;
        }
      } else {
        M::propagate(T, x);
        const M::Matrix FP = F * P;
        P.noalias() = FP * F.transpose();
        P += Q;
        const Vec3 nu = z - H * x;
        Mat3 S;
        double nis;
        joseph_update<6, 3>(x, P, nu, H, R, S, nis);
      }
      Vec6 e, enu;
      Mat6 C;
      const int idx[6] = {0, 2, 4, 1, 3, 5};
      for (int i = 0; i < 6; ++i) {
        enu(i) = x(idx[i]);
        for (int j = 0; j < 6; ++j) C(i, j) = P(idx[i], idx[j]);
      }
      e << enu.head<3>() - p, enu.tail<3>() - v0;
      sq_err[k] += e.head<3>().squaredNorm();
      nees[k] += e.dot(C.ldlt().solve(e));
    }
  }
  const double secs = seconds_since(t0);
  double sum = 0, ne = 0;
  for (int k = 1; k < steps; ++k) {
    sum += sq_err[k];
    ne += nees[k];
  }
  checksum = std::sqrt(sum / ((steps - 1.0) * runs)) + ne / ((steps - 1.0) * runs * 6);
  return static_cast<double>(runs) * steps / secs;
}

std::vector<Measurement> cv_measurements(int n) {
  std::vector<Measurement> ms(n);
  Rng rng(5);
  for (int k = 0; k < n; ++k) {
    auto& m = ms[k];
    m.time = 0.1 * k;
    m.frame = Frame::Cartesian;
    m.value = Vec3(1000 + 10 * m.time + 5 * rng.normal(), 2000 + 5 * rng.normal(), 300 + 5 * rng.normal());
    m.covariance = MeasCov::Identity(3, 3) * 25.0;
  }
  return ms;
}

// (3b) The plain fixed-size Eigen Kalman step the brief quotes (~0.3 us on this box).
double plain_kalman_steps(const std::vector<Measurement>& ms, int reps, double& checksum) {
  using M = ConstantVelocity;
  M::Matrix F, Q;
  M::transition(0.1, F);
  M::block_diagonal(M::axis_noise_continuous(0.1, 1.0), Q);
  Eigen::Matrix<double, 3, 6> H = Eigen::Matrix<double, 3, 6>::Zero();
  for (int a = 0; a < 3; ++a) H(a, M::position_index(a)) = 1;
  const auto t0 = Clock::now();
  checksum = 0;
  for (int rep = 0; rep < reps; ++rep) {
    M::State x = M::State::Zero();
    M::Matrix P = M::Matrix::Identity() * 1e4;
    for (const auto& m : ms) {
      x = F * x;
      P = F * P * F.transpose() + Q;
      const Mat3 R = m.covariance;
      const Mat3 S = H * P * H.transpose() + R;
      const Eigen::Matrix<double, 6, 3> K = P * H.transpose() * S.llt().solve(Mat3::Identity());
      x += K * (Vec3(m.value) - H * x);
      const M::Matrix IKH = M::Matrix::Identity() - K * H;
      P = IKH * P * IKH.transpose() + K * R * K.transpose();
    }
    checksum += x(0);
  }
  return static_cast<double>(reps) * ms.size() / seconds_since(t0);
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 2000, reps = 2000;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--runs")) runs = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--reps")) reps = std::atoi(argv[i + 1]);
  }
  host::PluginRegistry reg;
  reg.load_directories({TRACKFLOW_BENCH_PLUGIN_DIR});
  auto cfg = host::parse_pipeline(host::load_yaml_file(TRACKFLOW_BENCH_PIPELINE), TRACKFLOW_BENCH_PIPELINE);
  const host::Graph g = host::build_graph(cfg, reg);
  host::RunOptions opt;
  opt.runs = runs;
  opt.threads = 1;
  opt.output_dir = "/tmp/trackflow-bench-out";

  // Warm-up of both, then measure.
  double checksum = 0;
  { auto w = opt; w.runs = 20; host::run_graph(g, reg, w); plain_loop(20, checksum); }
  const host::Outcome out = host::run_graph(g, reg, opt);
  const double pipeline_rate = out.source_items / out.seconds;
  const double loop_rate = plain_loop(runs, checksum);

  const auto ms = cv_measurements(1000);
  const auto* kt = reg.find("filter.kalman");
  host::Value pv = host::load_yaml_string("{ q: 1 m2/s3 }", "bench");
  Params kp = host::validate_params(kt->decl.params, pv, "kf", {});
  auto kf = reg.create(*kt, kp);
  Diagnostics d;
  double plugin_rate = 0;
  for (int pass = 0; pass < 2; ++pass) {  // first pass warms up
    const auto t0 = Clock::now();
    for (int rep = 0; rep < reps; ++rep) {
      kf->start_run({static_cast<std::uint64_t>(rep), 1, &d});
      for (const auto& m : ms) kf->on_measurement(m, 0);
    }
    plugin_rate = static_cast<double>(reps) * ms.size() / seconds_since(t0);
  }
  double ck2 = 0;
  plain_kalman_steps(ms, reps / 10, ck2);
  const double plain_rate = plain_kalman_steps(ms, reps, ck2);

  std::printf("quickstart pipeline (engine + 5 plugins, %d runs x 601 steps, 1 thread): %10.0f measurements/s\n", runs,
              pipeline_rate);
  std::printf("same computation as a plain loop                                : %10.0f measurements/s\n", loop_rate);
  std::printf("  pipeline / plain loop                                         : %10.2f\n", pipeline_rate / loop_rate);
  std::printf("filter.kalman CV 6-state step through the plugin (virtual call) : %10.0f steps/s (%.3f us)\n",
              plugin_rate, 1e6 / plugin_rate);
  std::printf("plain fixed-size Eigen CV Kalman step (textbook, Joseph)        : %10.0f steps/s (%.3f us)\n",
              plain_rate, 1e6 / plain_rate);
  std::printf("  plugin / plain Eigen                                          : %10.2f\n", plugin_rate / plain_rate);
  std::printf("(checksums %.6g %.6g)\n", checksum, ck2);
  return 0;
}
