// Purpose: benchmark: the quickstart pipeline against the same computation as a plain loop; one 6-state CV Kalman step through filter.kalman, as plain fixed-size Eigen, and in OpenCV's cv::KalmanFilter side by side.
//
// Usage: trackflow-bench [--runs N] [--reps N] [--rounds R] [--only pipeline|kalman|stages] [--plugins DIR].
// Single thread.
// Every section alternates its contenders for R rounds (default 5) and keeps each one's best
// round, so other load on a shared machine affects them alike; rates are given per second of
// CPU time (this process on its core) and of wall time.
//   pipeline: quickstart through the engine and five plugins (N runs per round, default 400)
//     against the same simulation, conversion, CV Kalman filter and error/NEES bookkeeping
//     written as one plain loop over fixed-size Eigen (same SDK math headers).
//   stages (only when asked): the quickstart cut after each of its five nodes against the plain
//     loop stopped after the same work, to show what each stage costs in the framework.
//   kalman: 1000 pre-generated Cartesian position measurements, N passes per round (default 400):
//     filter.kalman through its plugin (virtual call, Estimate formed and read by a consumer),
//     a plain fixed-size Eigen textbook step, and cv::KalmanFilter (OpenCV, CV_64F) with the same
//     F, Q, H, R, initial state and covariance — once with a diagonal R (independent axes) and
//     once with a full R that changes every step (as converted measurements have). The final
//     states are compared as a check that the three compute the same filter. OpenCV is optional:
//     without it (Debian libopencv-video-dev) its rows are skipped with a message.
#include "bench_common.hpp"
#include "scoring/chi_square_band.hpp"
#include "scoring/nees.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/host/engine.hpp>
#include <trackflow/host/validate.hpp>
#include <trackflow/kalman.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/rng.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#ifdef TRACKFLOW_BENCH_OPENCV
#include <opencv2/video/tracking.hpp>
#endif

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

using namespace trackflow;
using namespace trackflow::bench;

namespace {

// The quickstart computation without the framework. Same parameters as pipelines/quickstart.yaml
// and the same outputs as its summary: per time step the sums sink.metrics keeps (squared error
// and error per ENU component, NEES and position NEES, NIS, the measurement's squared error),
// reduced at the end to position/velocity RMSE (total and per axis), mean error per axis, the
// largest per-step position RMS, ANEES (and the fraction of steps in the chi-square band),
// ANEES of the position, ANIS, measurement RMSE and the RMSE ratio. The filter is filter.kalman's
// step written with the same SDK math (structured F P F', Joseph update from P H'). Returns the
// number of measurements processed; adds a checksum of the outputs.
//
// Stage (for --only stages) stops the loop after the same work as the quickstart cut after its
// first Stage nodes: 1 the truth, 2 the radar's noisy spherical measurement, 3 its conversion
// (position and J R J'), 4 the Kalman step, 5 the scoring and the summary (the whole loop). What
// a shorter loop would leave unused goes into the checksum, so the compiler cannot drop it.
template <int Stage = 5>
double plain_loop(int runs, double& checksum) {
  using M = ConstantVelocity;
  const double T = 0.1, q = 0.0, sr = 10.0, sa = 1e-3, se = 1e-3;
  const int steps = 601;
  const Vec3 p0(6000, 8000, 1000), v0(-150, 50, 0);
  M::Matrix Q;
  M::block_diagonal(M::axis_noise_continuous(T, q), Q);
  struct Step {
    double sq[6] = {}, sum[6] = {}, nees = 0, nees_position = 0, nis = 0, meas_sq = 0;
    int estimates = 0, nis_count = 0;
  };
  std::vector<Step> step(steps);
  for (int run = 0; run < runs; ++run) {
    Rng rng(derive_seed(1, run, "radar"));
    M::State x;
    M::Matrix P;
    Vec3 z1;
    Mat3 R1;
    for (int k = 0; k < steps; ++k) {
      Step& st = step[k];
      const double t = k * T;
      const Vec3 p = p0 + v0 * t;
      if constexpr (Stage == 1) {
        st.meas_sq += p(0);
        continue;
      }
      const Vec3 s = enu_to_spherical(p, AzimuthConvention::NorthClockwise);
      const double r = s(0) + sr * rng.normal(), az = wrap_angle(s(1) + sa * rng.normal()), el = s(2) + se * rng.normal();
      if constexpr (Stage == 2) {
        st.meas_sq += r + az + el;
        continue;
      }
      const Vec3 z = spherical_to_enu(r, az, el, AzimuthConvention::NorthClockwise);
      const Mat3 J = spherical_to_enu_jacobian(r, az, el, AzimuthConvention::NorthClockwise);
      Mat3 R = J * Vec3(sr * sr, sa * sa, se * se).asDiagonal() * J.transpose();
      R = 0.5 * (R + R.transpose()).eval();
      if constexpr (Stage == 3) {
        st.meas_sq += z.sum() + R.sum();
        continue;
      }
      // sink.metrics scores measurements from the first estimate's time on (step 1).
      if (k > 0) st.meas_sq += (z - p).squaredNorm();
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
        M::propagate_covariance(T, P);
        P += Q;
        Vec3 nu;
        Eigen::Matrix<double, 6, 3> PHt;
        Mat3 S;
        for (int a = 0; a < 3; ++a) {
          nu(a) = z(a) - x(M::position_index(a));
          PHt.col(a) = P.col(M::position_index(a));
        }
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) S(a, b) = PHt(M::position_index(a), b) + R(a, b);
        double nis = 0;
        if (joseph_update_cross<6, 3>(x, P, nu, PHt, S, nis)) {
          st.nis += nis;
          ++st.nis_count;
        }
      }
      if constexpr (Stage == 4) {
        st.meas_sq += x(0) + P(0, 0);
        continue;
      }
      // Error against the truth; NEES and position NEES as sink.metrics computes them (nees.hpp).
      const int idx[6] = {0, 2, 4, 1, 3, 5};
      Vec6 e;
      Mat6 C;
      for (int i = 0; i < 6; ++i) {
        e(i) = x(idx[i]) - (i < 3 ? p(i) : v0(i - 3));
        for (int j = 0; j < 6; ++j) C(i, j) = P(idx[i], idx[j]);
      }
      ++st.estimates;
      for (int i = 0; i < 6; ++i) {
        st.sq[i] += e(i) * e(i);
        st.sum[i] += e(i);
      }
      double terms[6];
      if (metrics::nees_terms(C, e, terms)) {
        st.nees_position += terms[0] + terms[1] + terms[2];
        st.nees += terms[0] + terms[1] + terms[2] + terms[3] + terms[4] + terms[5];
      }
    }
  }
  if constexpr (Stage < 5) {
    for (const Step& st : step) checksum += st.meas_sq * 1e-300;
    return static_cast<double>(runs) * steps;
  }
  // The summary's reductions.
  double sq[6] = {}, sum[6] = {}, n = 0, max_rms = 0, anees = 0, anees_position = 0, anis = 0, meas_sq = 0;
  int nees_steps = 0, in_band = 0, nis_steps = 0;
  const metrics::Band band = metrics::chi_square_band(6.0 * runs, 0.95);
  for (const Step& st : step) {
    meas_sq += st.meas_sq;
    if (st.estimates == 0) continue;
    for (int i = 0; i < 6; ++i) {
      sq[i] += st.sq[i];
      sum[i] += st.sum[i];
    }
    n += st.estimates;
    max_rms = std::max(max_rms, std::sqrt((st.sq[0] + st.sq[1] + st.sq[2]) / st.estimates));
    const double a = st.nees / (6.0 * st.estimates);
    anees += a;
    anees_position += st.nees_position / (3.0 * st.estimates);
    in_band += a >= band.lo && a <= band.hi;
    ++nees_steps;
    if (st.nis_count) {
      anis += st.nis / (3.0 * st.nis_count);
      ++nis_steps;
    }
  }
  const double position_rmse = std::sqrt((sq[0] + sq[1] + sq[2]) / n);
  const double measurement_rmse = std::sqrt(meas_sq / (static_cast<double>(runs) * (steps - 1)));
  const double outputs[] = {position_rmse,
                            std::sqrt((sq[3] + sq[4] + sq[5]) / n),
                            std::sqrt(sq[0] / n), std::sqrt(sq[1] / n), std::sqrt(sq[2] / n),
                            std::sqrt(sq[3] / n), std::sqrt(sq[4] / n), std::sqrt(sq[5] / n),
                            sum[0] / n, sum[1] / n, sum[2] / n, max_rms,
                            anees / nees_steps, anees_position / nees_steps,
                            static_cast<double>(in_band) / nees_steps, anis / nis_steps,
                            measurement_rmse, position_rmse / measurement_rmse};
  for (double v : outputs) checksum += v;
  return static_cast<double>(runs) * steps;
}

// The Kalman step benchmark's problem: CV target, 10 Hz, explicit initial state, q = 1 m2/s3.
constexpr double kT = 0.1, kQ = 1.0;
const double kX0[6] = {1000, 10, 2000, 0, 300, 0};  // [x vx y vy z vz]
constexpr double kSigmaP0 = 50.0, kSigmaV0 = 20.0;

// 1000 measurements of a CV target; `full_R`: each with its own correlated R (a rotated diagonal,
// like a converted radar measurement's), else R = 25 m2 I.
std::vector<Measurement> cv_measurements(int n, bool full_R) {
  std::vector<Measurement> ms(n);
  Rng rng(5);
  for (int k = 0; k < n; ++k) {
    auto& m = ms[k];
    m.time = kT * k;
    m.frame = Frame::Cartesian;
    Mat3 R = Mat3::Identity() * 25.0;
    if (full_R) {
      const double a = 0.3 + 0.001 * k, b = 0.2;
      const Mat3 U = (Eigen::AngleAxisd(a, Vec3::UnitZ()) * Eigen::AngleAxisd(b, Vec3::UnitX())).toRotationMatrix();
      R = U * Vec3(25.0, 400.0, 100.0).asDiagonal() * U.transpose();
      R = (0.5 * (R + R.transpose())).eval();
    }
    const Eigen::LLT<Mat3> llt(R);
    const Vec3 w(rng.normal(), rng.normal(), rng.normal());
    m.value = Vec3(Vec3(1000 + 10 * m.time, 2000, 300) + llt.matrixL() * w);
    m.covariance = R;
  }
  return ms;
}

using CvModel = ConstantVelocity;

void model_matrices(CvModel::Matrix& F, CvModel::Matrix& Q, Eigen::Matrix<double, 3, 6>& H, CvModel::State& x0,
                    CvModel::Matrix& P0) {
  CvModel::transition(kT, F);
  CvModel::block_diagonal(CvModel::axis_noise_continuous(kT, kQ), Q);
  H.setZero();
  for (int a = 0; a < 3; ++a) H(a, CvModel::position_index(a)) = 1;
  for (int i = 0; i < 6; ++i) x0(i) = kX0[i];
  P0.setZero();
  for (int a = 0; a < 3; ++a) {
    P0(2 * a, 2 * a) = kSigmaP0 * kSigmaP0;
    P0(2 * a + 1, 2 * a + 1) = kSigmaV0 * kSigmaV0;
  }
}

// filter.kalman through its plugin, `reps` passes.
void plugin_passes(Component& kf, const std::vector<Measurement>& ms, int reps) {
  Diagnostics d;
  for (int rep = 0; rep < reps; ++rep) {
    kf.start_run({static_cast<std::uint64_t>(rep), 1, &d});
    for (const auto& m : ms) kf.on_measurement(m, 0);
  }
}

CvModel::State plugin_final_state(Component& kf, Consumer& c, const std::vector<Measurement>& ms) {
  struct Last final : Component {
    StateVec x;
    void on_estimate(const Estimate& e, int) override { x = e.state; }
  } last;
  const Link links[2] = {{&c, 0, 0xFF}, {&last, 0, 0xFF}};
  kf.out.connect(links, 2);
  Diagnostics d;
  kf.start_run({0, 1, &d});
  for (const auto& m : ms) kf.on_measurement(m, 0);
  kf.out.connect(links, 1);
  return last.x.head<6>();
}

// The textbook step in plain fixed-size Eigen (dense F P F', Joseph update).
CvModel::State plain_passes(const std::vector<Measurement>& ms, int reps, double& checksum) {
  CvModel::Matrix F, Q, P0;
  Eigen::Matrix<double, 3, 6> H;
  CvModel::State x0;
  model_matrices(F, Q, H, x0, P0);
  CvModel::State x;
  for (int rep = 0; rep < reps; ++rep) {
    x = x0;
    CvModel::Matrix P = P0;
    bool first = true;
    for (const auto& m : ms) {
      if (!first) {
        x = F * x;
        P = F * P * F.transpose() + Q;
      }
      first = false;
      const Mat3 R = m.covariance;
      const Mat3 S = H * P * H.transpose() + R;
      const Eigen::Matrix<double, 6, 3> K = P * H.transpose() * S.llt().solve(Mat3::Identity());
      x += K * (Vec3(m.value) - H * x);
      const CvModel::Matrix IKH = CvModel::Matrix::Identity() - K * H;
      P = IKH * P * IKH.transpose() + K * R * K.transpose();
    }
    checksum += x(0);
  }
  return x;
}

#ifdef TRACKFLOW_BENCH_OPENCV
// The same filter in cv::KalmanFilter (its predict() and correct(): F P F' + Q, then the
// textbook gain and P - K H P). R is copied in at every step (it changes with full_R).
CvModel::State opencv_passes(const std::vector<Measurement>& ms, int reps, double& checksum) {
  CvModel::Matrix F, Q, P0;
  Eigen::Matrix<double, 3, 6> H;
  CvModel::State x0;
  model_matrices(F, Q, H, x0, P0);
  cv::KalmanFilter kf(6, 3, 0, CV_64F);
  auto to_cv = [](const auto& A, cv::Mat& out) {
    for (int i = 0; i < A.rows(); ++i)
      for (int j = 0; j < A.cols(); ++j) out.at<double>(i, j) = A(i, j);
  };
  to_cv(F, kf.transitionMatrix);
  to_cv(Q, kf.processNoiseCov);
  to_cv(H, kf.measurementMatrix);
  for (int rep = 0; rep < reps; ++rep) {
    to_cv(x0, kf.statePre);  // correct() starts from the predicted ("pre") state
    to_cv(P0, kf.errorCovPre);
    bool first = true;
    for (const auto& m : ms) {
      if (!first) kf.predict();
      first = false;
      double* r = kf.measurementNoiseCov.ptr<double>();
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r[3 * i + j] = m.covariance(i, j);
      const cv::Mat z(3, 1, CV_64F, const_cast<double*>(m.value.data()));
      kf.correct(z);
    }
    checksum += kf.statePost.at<double>(0);
  }
  CvModel::State x;
  for (int i = 0; i < 6; ++i) x(i) = kf.statePost.at<double>(i);
  return x;
}
#endif

double relative_difference(const CvModel::State& a, const CvModel::State& b) {
  return (a - b).norm() / std::max(a.norm(), 1e-300);
}

void row(const std::string& name, const Rate& r) {
  std::printf("%-52s %12.0f %8.3f %12.0f %8.3f\n", name.c_str(), r.cpu, 1e6 / r.cpu, r.wall, 1e6 / r.wall);
}

void kalman_section(const host::PluginRegistry& reg, int reps, int rounds) {
  std::printf("6-state CV Kalman step, 1000 measurements x %d passes, best of %d alternating rounds, 1 thread\n", reps,
              rounds);
  std::printf("%-52s %12s %8s %12s %8s\n", "", "steps/CPU-s", "us", "steps/wall-s", "us");
  char params[400];
  std::snprintf(params, sizeof params,
                "{ q: %g m2/s3, init: explicit, initial_position: [%g, %g, %g], initial_velocity: [%g, %g, %g], "
                "initial_sigma_position: %g m, initial_sigma_velocity: %g m/s }",
                kQ, kX0[0], kX0[2], kX0[4], kX0[1], kX0[3], kX0[5], kSigmaP0, kSigmaV0);
  for (const bool full_R : {false, true}) {
    const auto ms = cv_measurements(1000, full_R);
    auto kf = make(reg, "filter.kalman", params);
    Consumer consumer;
    const Link link{&consumer, 0, 0xFF};
    kf->out.connect(&link, 1);
    const double steps = static_cast<double>(reps) * ms.size();
    Rate tf, plain, ocv;
    double ck = 0;
    CvModel::State x_plain, x_ocv;
    plugin_passes(*kf, ms, reps / 10 + 1);  // warm-up
    for (int round = 0; round < rounds; ++round) {
      tf.add(steps, time_it([&] { plugin_passes(*kf, ms, reps); }));
      plain.add(steps, time_it([&] { x_plain = plain_passes(ms, reps, ck); }));
#ifdef TRACKFLOW_BENCH_OPENCV
      ocv.add(steps, time_it([&] { x_ocv = opencv_passes(ms, reps, ck); }));
#endif
    }
    const CvModel::State x_tf = plugin_final_state(*kf, consumer, ms);
    std::printf("%s:\n", full_R ? "full R, a different one every step (converted measurements)" : "diagonal R = 25 m2 I");
    row("  filter.kalman through the plugin", tf);
    row("  plain fixed-size Eigen, textbook dense step", plain);
#ifdef TRACKFLOW_BENCH_OPENCV
    row("  OpenCV " CV_VERSION " cv::KalmanFilter (CV_64F)", ocv);
    std::printf("  %-50s %12.2f %8s %12.2f\n", "speed ratio filter.kalman / OpenCV", tf.cpu / ocv.cpu, "",
                tf.wall / ocv.wall);
    std::printf("  final states: plugin vs OpenCV %.1e, plugin vs plain %.1e (relative)\n",
                relative_difference(x_tf, x_ocv), relative_difference(x_tf, x_plain));
#else
    (void)ocv;
    (void)x_ocv;
    std::printf("  OpenCV cv::KalmanFilter: skipped (the OpenCV video module was not found when this was built: "
                "install libopencv-video-dev and re-run cmake)\n");
    std::printf("  final state: plugin vs plain %.1e (relative)\n", relative_difference(x_tf, x_plain));
#endif
    std::printf("  %-50s %12.2f %8s %12.2f\n", "speed ratio filter.kalman / plain Eigen", tf.cpu / plain.cpu, "",
                tf.wall / plain.wall);
  }
}

void pipeline_section(const host::PluginRegistry& reg, int runs, int rounds) {
  auto cfg = host::parse_pipeline(host::load_yaml_file(TRACKFLOW_BENCH_PIPELINE), TRACKFLOW_BENCH_PIPELINE);
  const host::Graph g = host::build_graph(cfg, reg);
  host::RunOptions opt;
  opt.runs = static_cast<std::uint64_t>(runs);
  opt.threads = 1;
  opt.output_dir = "/tmp/trackflow-bench-out";
  double checksum = 0;
  {
    auto w = opt;
    w.runs = 20;
    host::run_graph(g, reg, w);
    plain_loop(20, checksum);
  }
  Rate pipeline, loop;
  for (int round = 0; round < rounds; ++round) {
    double items = 0;
    const Clocks c = time_it([&] { items = static_cast<double>(host::run_graph(g, reg, opt).source_items); });
    pipeline.add(items, c);
    double n = 0;
    const Clocks l = time_it([&] { n = plain_loop(runs, checksum); });
    loop.add(n, l);
  }
  std::printf("quickstart, %d runs x 601 steps per round, best of %d alternating rounds, 1 thread\n", runs, rounds);
  std::printf("%-52s %12s %12s\n", "", "meas/CPU-s", "meas/wall-s");
  std::printf("%-52s %12.0f %12.0f\n", "quickstart pipeline (engine + 5 plugins)", pipeline.cpu, pipeline.wall);
  std::printf("%-52s %12.0f %12.0f\n", "same computation as a plain loop", loop.cpu, loop.wall);
  std::printf("%-52s %12.2f %12.2f   (aim >= 0.9)\n", "  pipeline / plain loop", pipeline.cpu / loop.cpu,
              pipeline.wall / loop.wall);
  std::printf("(checksum %.6g)\n", checksum);
}

// The quickstart cut after each of its nodes, against the plain loop stopped after the same work:
// what each stage adds, through the framework and as plain code. The difference of the two
// columns is the framework's cost of that stage (its item, its checks, its call).
void stages_section(const host::PluginRegistry& reg, int runs, int rounds) {
  auto full = host::parse_pipeline(host::load_yaml_file(TRACKFLOW_BENCH_PIPELINE), TRACKFLOW_BENCH_PIPELINE);
  full.expects.clear();
  constexpr int kStages = 5;
  std::vector<host::Graph> graphs;
  for (int k = 1; k <= kStages; ++k) {
    auto cut = full;
    cut.nodes.resize(static_cast<size_t>(k));
    graphs.push_back(host::build_graph(cut, reg));
  }
  host::RunOptions opt;
  opt.runs = static_cast<std::uint64_t>(runs);
  opt.threads = 1;
  opt.output_dir = "/tmp/trackflow-bench-out";
  double checksum = 0;
  using Loop = double (*)(int, double&);
  const Loop loops[kStages] = {&plain_loop<1>, &plain_loop<2>, &plain_loop<3>, &plain_loop<4>, &plain_loop<5>};
  Rate pipeline[kStages], loop[kStages];
  for (int round = 0; round < rounds; ++round)
    for (int k = 0; k < kStages; ++k) {
      // Per truth sample (each becomes one measurement further on).
      double items = 0, n = 0;
      const Clocks c = time_it([&] { items = static_cast<double>(host::run_graph(graphs[k], reg, opt).source_items); });
      pipeline[k].add(items, c);
      const Clocks l = time_it([&] { n = loops[k](runs, checksum); });
      loop[k].add(n, l);
    }
  const char* names[kStages] = {"sim.trajectory", "+ sim.radar", "+ convert.classical", "+ filter.kalman",
                                "+ sink.metrics (the quickstart)"};
  std::printf("quickstart cut after each node, %d runs x 601 steps, best of %d rounds, 1 thread; ns per measurement (CPU)\n",
              runs, rounds);
  std::printf("%-34s %10s %10s %10s   %s\n", "pipeline up to", "pipeline", "plain", "difference", "stage: pipeline  plain  framework");
  double prev_p = 0, prev_l = 0;
  for (int k = 0; k < kStages; ++k) {
    const double p = 1e9 / pipeline[k].cpu, l = 1e9 / loop[k].cpu;
    std::printf("%-34s %10.1f %10.1f %10.1f   %13.1f %6.1f %10.1f\n", names[k], p, l, p - l, p - prev_p, l - prev_l,
                (p - prev_p) - (l - prev_l));
    prev_p = p;
    prev_l = l;
  }
  std::printf("the 0.9 aim: the whole pipeline within %.1f ns of the plain loop (now %.1f)\n",
              1e9 / loop[kStages - 1].cpu / 0.9 - 1e9 / loop[kStages - 1].cpu,
              1e9 / pipeline[kStages - 1].cpu - 1e9 / loop[kStages - 1].cpu);
  std::printf("(checksum %.6g)\n", checksum);
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 400, reps = 400, rounds = 5;
  std::string only, plugin_dir = TRACKFLOW_BENCH_PLUGIN_DIR;  // --plugins: another build's, for before/after
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--plugins")) plugin_dir = argv[i + 1];
    if (!std::strcmp(argv[i], "--runs")) runs = std::max(1, std::atoi(argv[i + 1]));
    if (!std::strcmp(argv[i], "--reps")) reps = std::max(1, std::atoi(argv[i + 1]));
    if (!std::strcmp(argv[i], "--rounds")) rounds = std::max(1, std::atoi(argv[i + 1]));
    if (!std::strcmp(argv[i], "--only")) only = argv[i + 1];
  }
  host::PluginRegistry reg;
  reg.load_directories({plugin_dir});
  if (only.empty() || only == "pipeline") pipeline_section(reg, runs, rounds);
  if (only == "stages") stages_section(reg, runs, rounds);
  if (only.empty()) std::printf("\n");
  if (only.empty() || only == "kalman") kalman_section(reg, reps, rounds);
  return 0;
}
