// Purpose: tests of adapt.innovation_r attached to filter.kalman and filter.decoupled: convergence to the true R, the floor, a whole pipeline, incompatibility.
#include <trackflow/host/engine.hpp>
#include <trackflow/host/graph.hpp>
#include <trackflow/rng.hpp>

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include "plugin_fixture.hpp"

using namespace trackflow;

namespace {

// Measurement noise of a radar ~10 km away: range 3 m, cross-range 10 m and 6 m, diagonal in
// the line-of-sight frame of `los` (so filter.decoupled's approximation is exact for it).
Mat3 nominal_R(const Vec3& los) {
  Mat3 D;
  D.col(0) = los.normalized();
  D.col(1) = Vec3(-D(1, 0), D(0, 0), 0).normalized();
  D.col(2) = D.col(0).cross(D.col(1));
  return D * Vec3(9.0, 100.0, 36.0).asDiagonal() * D.transpose();
}

struct Attached {
  std::shared_ptr<Component> filter, adapter;
  Filter* f = nullptr;
  Adapter* a = nullptr;
  test::Collector out;
  Attached(const std::string& filter_type, const std::string& filter_params, const std::string& adapter_params) {
    filter = test::make(filter_type, filter_params, "kf");
    adapter = test::make("adapt.innovation_r", adapter_params, "adaptive");
    f = dynamic_cast<Filter*>(filter.get());
    a = dynamic_cast<Adapter*>(adapter.get());
    REQUIRE(f);
    REQUIRE(a);
    test::attach(*a, *f);
    out.attach_to(*filter);
  }
  void start_run(std::uint64_t run, Diagnostics& d) {
    filter->start_run({run, 1, &d});
    adapter->start_run({run, 1, &d});
    out.estimates.clear();
  }
  // R the filter used for the latest measurement (the adapter writes it in before_update).
  Mat3 filter_R() const { return f->noise().measurement.R->topLeftCorner<3, 3>(); }
};

// One run of a target with the continuous white acceleration (PSD q) the filters assume, so that
// with the true R the filter is consistent and the residual-based estimate is unbiased. The true
// measurement noise is k times the nominal R's square root; the measurements report the nominal.
void fly(Attached& s, std::uint64_t run, double k, int steps, std::vector<Mat3>* final_R = nullptr,
         std::vector<Mat3>* final_P = nullptr, const char* stream = "adapter") {
  const double q = 1.0, T = 0.1;
  Diagnostics d;
  s.start_run(run, d);
  Rng rng(derive_seed(42, run, stream));
  const Eigen::Matrix2d Qa =
      (Eigen::Matrix2d() << q * T * T * T / 3, q * T * T / 2, q * T * T / 2, q * T).finished();
  const Eigen::Matrix2d Lq = Qa.llt().matrixL();
  Vec3 p(6000, 8000, 500), v(-60, -80, 0);
  const Mat3 R = nominal_R(p);
  const Mat3 LR = R.llt().matrixL();
  for (int i = 0; i < steps; ++i) {
    Measurement m;
    m.time = i * T;
    m.frame = Frame::Cartesian;
    m.value = p + k * LR * Vec3(rng.normal(), rng.normal(), rng.normal());
    m.covariance = R;
    s.filter->on_measurement(m, 0);
    for (int a = 0; a < 3; ++a) {
      const Eigen::Vector2d w = Lq * Eigen::Vector2d(rng.normal(), rng.normal());
      p(a) += v(a) * T + w(0);
      v(a) += w(1);
    }
  }
  REQUIRE(d.warnings.empty());
  if (final_R) final_R->push_back(s.filter_R());
  if (final_P) final_P->push_back(s.out.estimates.back().enu_covariance.topLeftCorner<3, 3>());
}

struct Moments {
  Mat3 mean = Mat3::Zero(), sd = Mat3::Zero();
};
Moments moments(const std::vector<Mat3>& xs) {
  Moments m;
  for (const auto& x : xs) m.mean += x;
  m.mean /= static_cast<double>(xs.size());
  for (const auto& x : xs) m.sd += (x - m.mean).cwiseAbs2();
  m.sd = (m.sd / static_cast<double>(xs.size() - 1)).cwiseSqrt();
  return m;
}

}  // namespace

// R-hat converges to k^2 R when the true noise is k times the nominal, on filter.kalman and filter.decoupled
TEST_CASE("R-hat converges to k^2 R on kalman and decoupled") {
  const int runs = 200, steps = 400, window = 20;
  for (const char* type : {"filter.kalman", "filter.decoupled"}) {
    for (double k : {1.0, 3.0}) {
      Attached s(type, "{ q: 1 m2/s3 }", "{ window: 20, warmup: 50 }");
      std::vector<Mat3> finals;
      for (int r = 0; r < runs; ++r) fly(s, r, k, steps, &finals);
      const Moments m = moments(finals);
      const Mat3 target = k * k * nominal_R(Vec3(6000, 8000, 500));
      INFO(type << " k=" << k << "\nmean R-hat\n" << m.mean << "\nk^2 R\n" << target << "\nsd\n" << m.sd);
      for (int i = 0; i < 3; ++i) {
        // The mean over independent runs is within 4 standard errors of k^2 R.
        CHECK(std::abs(m.mean(i, i) - target(i, i)) < 4.0 * m.sd(i, i) / std::sqrt(runs));
        // The spread is the moving average's: residual variances enter with weight 1/L, so
        // sd(R-hat_ii) ~ sqrt(2 / (2L - 1)) E[dz_i^2] <= 0.23 k^2 R_ii for L = 20 and independent
        // residuals (post-update residuals are somewhat correlated, hence the wide bracket).
        const double independent = std::sqrt(2.0 / (2.0 * window - 1.0)) * target(i, i);
        CHECK(m.sd(i, i) > 0.3 * independent);
        CHECK(m.sd(i, i) < 2.0 * independent);
      }
      // Off-diagonal terms (up to 0.6 of the variances here) are recovered too.
      CHECK((m.mean - target).norm() < 0.05 * target.norm());
    }
  }
}

// post_fit_term subtract (eq 28 as printed) converges below R by about twice the posterior variance
TEST_CASE("post_fit_term subtract converges below R") {
  // add tends to R; subtract to E[dz dz'] - H P+ H' = R - 2 H P+ H' (to first order in H P+ H' / R).
  const int runs = 100, steps = 400;
  Attached add("filter.kalman", "{ q: 1 m2/s3 }", "{}");
  Attached sub("filter.kalman", "{ q: 1 m2/s3 }", "{ post_fit_term: subtract }");
  std::vector<Mat3> fa, fs, pa, diff;
  for (int r = 0; r < runs; ++r) {
    fly(add, r, 2.0, steps, &fa, &pa);
    fly(sub, r, 2.0, steps, &fs);  // the same truth and noise: a paired comparison
    diff.push_back(fa.back() - fs.back());
  }
  const Moments md = moments(diff), mp = moments(pa);
  for (int i = 0; i < 3; ++i) {
    INFO("axis " << i << ": add - subtract " << md.mean(i, i) << " +- " << md.sd(i, i) / std::sqrt(runs)
                 << ", posterior variance " << mp.mean(i, i));
    CHECK(md.mean(i, i) > 4.0 * md.sd(i, i) / std::sqrt(runs));
    CHECK(md.mean(i, i) > 1.5 * mp.mean(i, i));
    CHECK(md.mean(i, i) < 2.5 * mp.mean(i, i));
  }
}

// the floor holds on the filter's R when residuals vanish
TEST_CASE("the floor holds on R when residuals vanish") {
  for (const char* term : {"add", "subtract"}) {
    INFO(term);
    Attached s("filter.decoupled", "{ q: 0.001 m2/s3 }",
               std::string("{ window: 5, warmup: 0, floor_ratio: 0.2, floor_sigma: 1 cm, post_fit_term: ") + term + " }");
    Diagnostics d;
    s.start_run(0, d);
    const Vec3 p0(6000, 8000, 500), v(-60, -80, 0);
    const Mat3 R = nominal_R(p0);
    int violations = 0;
    for (int i = 0; i < 3000; ++i) {
      Measurement m;
      m.time = 0.1 * i;
      m.frame = Frame::Cartesian;
      m.value = p0 + v * m.time;  // noise-free: residuals shrink to nothing
      m.covariance = R;
      s.filter->on_measurement(m, 0);
      const Mat3 used = s.filter_R();
      const Eigen::GeneralizedSelfAdjointEigenSolver<Mat3> ges(used, R);
      const Eigen::SelfAdjointEigenSolver<Mat3> es(used);
      violations += !(ges.eigenvalues().minCoeff() >= 0.04 * (1 - 1e-9)) ||
                    !(es.eigenvalues().minCoeff() >= 1e-4 * (1 - 1e-9)) || !s.out.estimates.back().enu.allFinite();
    }
    CHECK(violations == 0);
    CHECK(d.warnings.empty());
    // The floor is what holds R-hat up: it sits at floor_ratio^2 R in some direction.
    const Eigen::GeneralizedSelfAdjointEigenSolver<Mat3> ges(s.filter_R(), R);
    CHECK(ges.eigenvalues().minCoeff() == Approx(0.04).epsilon(1e-6));
  }
}

TEST_CASE("incompatibility names what is missing") {
  struct NoR : Filter {};
  struct SphericalR : Filter {
    MeasCov R = MeasCov::Identity(3, 3);
    NoiseHandles noise() override {
      NoiseHandles h;
      h.measurement.R = &R;
      h.measurement.space = MeasurementSpace::Spherical;
      return h;
    }
  };
  auto adapter = test::make("adapt.innovation_r");
  auto* a = dynamic_cast<Adapter*>(adapter.get());
  REQUIRE(a);
  NoR no_r;
  SphericalR spherical;
  CHECK_THAT(noise_mismatch(a->needs(), no_r.noise(), no_r.has_covariance_access()), Catch::Contains("exposes no measurement noise"));
  CHECK_THAT(noise_mismatch(a->needs(), spherical.noise(), spherical.has_covariance_access()), Catch::Contains("'spherical'") && Catch::Contains("cartesian_position"));
  for (const char* type : {"filter.kalman", "filter.decoupled"}) {
    auto f = test::make(type);
    CHECK(noise_mismatch(a->needs(), dynamic_cast<Filter*>(f.get())->noise(), dynamic_cast<Filter*>(f.get())->has_covariance_access()).empty());
  }
  CHECK_THROWS_WITH(test::make("adapt.innovation_r", "{ window: 0 }"), Catch::Contains("window"));
}

// in a pipeline the adapter drives filter.kalman and filter.decoupled, deterministically for any thread count
TEST_CASE("pipeline with kalman and decoupled is deterministic") {
  const std::string yaml = R"(
pipeline: { name: adapter_pipeline, seed: 3, runs: 12 }
nodes:
  - id: truth
    type: sim.trajectory
    params:
      rate: 10 Hz
      initial_position: [6 km, 8 km, 1 km]
      initial_velocity: [-150 m/s, 50 m/s, 0 m/s]
      segments: [{ type: constant_velocity, duration: 40 s }]
  - id: radar
    type: sim.radar
    input: truth
    params: { sigma_range: 10 m, sigma_azimuth: 1 mrad, sigma_elevation: 1 mrad }
  - id: cm
    type: convert.classical
    input: radar
  - { id: kf, type: filter.kalman, input: cm, params: { q: 0.1 m2/s3 } }
  - { id: dkf, type: filter.decoupled, input: cm, params: { q: 0.1 m2/s3 } }
  - { id: adapt_kf, type: adapt.innovation_r, attach_to: kf }
  - { id: adapt_dkf, type: adapt.innovation_r, attach_to: dkf, params: { window: 30 } }
  - { id: score_kf, type: sink.metrics, inputs: [kf, truth] }
  - { id: score_dkf, type: sink.metrics, inputs: [dkf, truth] }
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
  for (const char* id : {"adapt_kf", "adapt_dkf"}) {
    INFO(id);
    const Summary& s = one.find(id)->summary;
    const Metric* factor = s.find("noise_factor_mean");
    REQUIRE(factor);
    // The radar reports its true noise, so the estimate stays near the nominal.
    CHECK(factor->value == Approx(1.0).epsilon(0.15));
    REQUIRE(s.find("updates"));
    CHECK(s.find("updates")->value == Approx(12 * 399).margin(1));
    const Summary& s2 = two.find(id)->summary;
    REQUIRE(s.metrics.size() == s2.metrics.size());
    for (size_t i = 0; i < s.metrics.size(); ++i) CHECK(s.metrics[i].value == s2.metrics[i].value);
  }
  // A filter without a Cartesian R is refused when the pipeline is built.
  const std::string bad = yaml + "  - { id: adapt_sink, type: adapt.innovation_r, attach_to: score_kf }\n";
  host::PipelineConfig bad_cfg = host::parse_pipeline(host::load_yaml_string(bad, "bad.yaml"), "bad.yaml");
  CHECK_THROWS_AS(host::build_graph(bad_cfg, test::registry()), ConfigError);
}
