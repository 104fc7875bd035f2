// Purpose: adapt.innovation_r — retunes a filter's Cartesian measurement noise R from its post-update residuals (paper 001 eq 28-32).
#include "difference_noise_factor.hpp"
#include "residual_r_estimator.hpp"

#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace trackflow {
namespace {

using adapt::ResidualREstimator;

enum class PostFitTerm { Add, Subtract };
enum class Covariance { FollowR, Keep };
enum class WarmupEstimate { SecondDifferences, Nominal };

// The end-of-run state of one run; the aggregating instance sums these in run order.
struct InnovationRRunResult final : RunResult {
  bool has_estimate = false;
  Vec3 sigma = Vec3::Zero();          // sqrt of R̂'s diagonal, ENU
  Vec3 nominal_sigma = Vec3::Zero();  // sqrt of the averaged nominal R's diagonal
  double noise_factor = 0.0;          // sqrt(tr(R̄_nom⁻¹ R̂) / 3) at the end of the run
  double factor_sum = 0.0;            // the same after every adapting update, summed
  std::uint64_t factor_count = 0;
  std::uint64_t updates = 0, floored = 0, rescales = 0;
  double variance_factor = 1.0;  // the covariance rescale applied over the run (covariance: follow_r)
  // Its codec under mpirun (run_result_codec.hpp): one list, written and read in this order.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.has_estimate, r.sigma, r.nominal_sigma, r.noise_factor, r.factor_sum, r.factor_count, r.updates, r.floored,
      r.rescales, r.variance_factor);
  }
};

// How much larger than the measurements' own R the estimate is: sqrt of the mean generalised
// eigenvalue, sqrt(tr(R̄_nom⁻¹ R̂) / 3); NaN if the averaged nominal R is not positive definite.
double noise_factor(const ResidualREstimator& e) {
  const Eigen::LLT<Mat3> llt(e.nominal_average());
  if (llt.info() != Eigen::Success) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(std::max(0.0, llt.solve(e.estimate()).trace() / 3.0));
}

class InnovationRAdapter final : public Adapter, public FieldListCodec<InnovationRRunResult> {
 public:
  InnovationRAdapter(adapt::EstimatorSettings s, bool follow_r, bool warmup_differences)
      : settings_(s), estimator_(s), follow_r_(follow_r), warmup_differences_(warmup_differences) {}

  NoiseNeeds needs() const override {
    NoiseNeeds n;
    n.measurement = MeasurementSpace::CartesianPosition;
    n.covariance = follow_r_;
    return n;
  }

  // The adapted R's standard deviations, per ENU axis (m), on every estimate.
  std::vector<std::string> annotation_names() const override { return {"sigma_x", "sigma_y", "sigma_z"}; }

  void start_run(const RunContext&) override {
    estimator_ = ResidualREstimator(settings_);
    updates_ = floored_ = run_factor_count_ = rescales_ = 0;
    run_factor_sum_ = 0.0;
    applied_variance_factor_ = 1.0;
    differences_.reset();
  }

  void before_update(const Measurement& m, Filter& f) override {
    // An invalid measurement is only coasted through (and may not even be converted).
    if (!m.valid || m.covariance.rows() < 3 || m.covariance.cols() < 3 || m.value.size() < 3) {
      differences_.gap();
      return;
    }
    const Mat3 nominal = m.covariance.topLeftCorner<3, 3>();
    if (!nominal.allFinite() || !m.value.head<3>().allFinite()) return;
    if (!estimator_.started()) estimator_.start(nominal);
    MeasCov* R = f.noise().measurement.R;
    if (!estimator_.adapting()) {
      // Warm-up: the residuals still carry the start-up state error. The measurements' own R,
      // scaled by the second-difference noise factor once it has enough samples (warmup_estimate:
      // second_differences), or as it is (nominal).
      if (!warmup_differences_) return;
      differences_.add(m.time, m.value.head<3>(), nominal);
      const double k2 = differences_.variance_factor();
      if (differences_.samples() < kMinDifferences || !std::isfinite(k2) || !(k2 > 0.0)) return;
      estimator_.set_warmup_scale(k2);
      if (R && R->rows() >= 3 && R->cols() >= 3) R->topLeftCorner<3, 3>() = k2 * nominal;
      if (follow_r_) follow(f, k2);
      return;
    }
    if (R) *R = estimator_.estimate();
    if (follow_r_) follow(f, noise_factor(estimator_) * noise_factor(estimator_));
  }

  void after_update(const Measurement& m, const Estimate& e, Filter& f) override {
    if (estimator_.started())
      for (int i = 0; i < 3; ++i) annotate(f, i, std::sqrt(std::max(0.0, estimator_.estimate()(i, i))));
    if (!e.updated || !e.initialised || !m.valid || !estimator_.started() || m.value.size() < 3) return;
    const Vec3 residual = m.value.head<3>() - e.enu.head<3>();
    const Mat3 posterior = e.enu_covariance.topLeftCorner<3, 3>();
    const Mat3 nominal = m.covariance.topLeftCorner<3, 3>();
    if (!residual.allFinite() || !posterior.allFinite() || !nominal.allFinite()) return;
    ++updates_;
    if (estimator_.update(residual, posterior, nominal)) ++floored_;
    if (estimator_.adapting()) {
      const double k = noise_factor(estimator_);
      if (std::isfinite(k)) {
        run_factor_sum_ += k;
        ++run_factor_count_;
      }
    }
  }

  std::unique_ptr<RunResult> end_run() override {
    auto r = std::make_unique<InnovationRRunResult>();
    r->rescales = rescales_;
    r->updates = updates_;
    r->floored = floored_;
    if (estimator_.started()) {
      const Mat3& R = estimator_.estimate();
      const Mat3& N = estimator_.nominal_average();
      r->has_estimate = true;
      r->sigma = R.diagonal().cwiseMax(0.0).cwiseSqrt();
      r->nominal_sigma = N.diagonal().cwiseMax(0.0).cwiseSqrt();
      r->noise_factor = noise_factor(estimator_);
    }
    r->factor_sum = run_factor_sum_;
    r->variance_factor = applied_variance_factor_;
    r->factor_count = run_factor_count_;
    return r;
  }

  void merge(RunResult& result) override {
    const auto& r = static_cast<InnovationRRunResult&>(result);
    ++runs_;
    updates_total_ += r.updates;
    floored_total_ += r.floored;
    mean_factor_sum_ += r.factor_sum;
    mean_factor_count_ += r.factor_count;
    rescales_total_ += r.rescales;
    variance_factor_sum_ += r.variance_factor;
    if (!r.has_estimate) return;
    ++runs_with_estimate_;
    sigma_sum_ += r.sigma;
    nominal_sum_ += r.nominal_sigma;
    if (std::isfinite(r.noise_factor)) {
      factor_sum_ += r.noise_factor;
      ++factor_runs_;
    }
  }

  void finish(Summary& s, const FinishContext&) override {
    if (runs_with_estimate_ == 0) {
      s.notes.push_back("no measurement reached the adapter: R was never estimated");
      return;
    }
    const double n = static_cast<double>(runs_with_estimate_);
    const char* axis[3] = {"x", "y", "z"};
    for (int i = 0; i < 3; ++i) s.metric(std::string("sigma_") + axis[i], sigma_sum_(i) / n, "m");
    for (int i = 0; i < 3; ++i) s.metric(std::string("nominal_sigma_") + axis[i], nominal_sum_(i) / n, "m");
    if (factor_runs_ > 0) s.metric("noise_factor_estimate", factor_sum_ / static_cast<double>(factor_runs_));
    if (mean_factor_count_ > 0)
      s.metric("noise_factor_mean", mean_factor_sum_ / static_cast<double>(mean_factor_count_));
    s.metric("updates", static_cast<double>(updates_total_));
    if (follow_r_) {
      s.metric("covariance_rescales", static_cast<double>(rescales_total_));
      s.metric("covariance_factor_mean", variance_factor_sum_ / static_cast<double>(runs_));
    }
    s.metric("floor_fraction",
             updates_total_ ? static_cast<double>(floored_total_) / static_cast<double>(updates_total_) : 0.0);
    s.notes.push_back("final R-hat of each run (ENU sigmas), averaged over " + std::to_string(runs_with_estimate_) +
                      " runs; nominal_sigma_*: the measurements' own R averaged with the same window; "
                      "noise_factor_estimate = sqrt(tr(nominal^-1 R-hat)/3) at the end of each run, "
                      "noise_factor_mean: the same averaged over every adapting update of every run");
    if (runs_with_estimate_ < runs_)
      s.notes.push_back(std::to_string(runs_ - runs_with_estimate_) + " run(s) had no measurement: left out");
  }

 private:
  // covariance: follow_r. The filter's P was built with the R it used (the measurements' own during
  // the warm-up); when R-hat says the noise is k^2 times larger, the true error covariance is
  // about k^2 times P too (P0 and the measurement-dominated part of P scale with R). P is rescaled
  // by the change of k^2 = tr(R_nom^-1 R-hat)/3 since the last step, so over a run it has followed
  // R-hat's growth once; the filter's own updates then settle it. Without this the gains
  // collapse when R-hat grows while P still claims the small start-up error.
  void follow(Filter& f, double variance_factor) {
    if (!std::isfinite(variance_factor) || !(variance_factor > 0.0)) return;
    const double step = variance_factor / applied_variance_factor_;
    if (std::abs(step - 1.0) < 1e-12) return;
    f.scale_covariance(step);
    applied_variance_factor_ = variance_factor;
    ++rescales_;
  }

  adapt::EstimatorSettings settings_;
  ResidualREstimator estimator_;
  bool follow_r_ = true;
  bool warmup_differences_ = true;
  adapt::DifferenceNoiseFactor differences_;
  // Second differences before their noise factor is used: the estimate of k² from n of them has
  // a relative spread of about sqrt(2 / (3 n)) (0.37 at 5).
  static constexpr int kMinDifferences = 1;
  double applied_variance_factor_ = 1.0;
  std::uint64_t rescales_ = 0, rescales_total_ = 0;
  double variance_factor_sum_ = 0.0;
  std::uint64_t updates_ = 0, floored_ = 0, run_factor_count_ = 0;
  double run_factor_sum_ = 0.0;
  // Aggregating instance.
  std::uint64_t runs_ = 0, runs_with_estimate_ = 0, factor_runs_ = 0, updates_total_ = 0, floored_total_ = 0;
  Vec3 sigma_sum_ = Vec3::Zero(), nominal_sum_ = Vec3::Zero();
  double factor_sum_ = 0.0, mean_factor_sum_ = 0.0;
  std::uint64_t mean_factor_count_ = 0;
};

const char* const kDoc =
    "Paper 001 eq 28-32 (Kim & Hwang 2013). After each update: residual dz = z - H x+ (post-update, from the "
    "filter's published ENU position), single-step estimate R_s = dz dz' + H P+ H' (H P+ H' the published ENU "
    "position covariance; for filter.decoupled that is eq 28's H D2 Pbar+ D2' H'), moving average "
    "R_k = R_{k-1} + (R_s - R_{k-1}) / L (eq 31), symmetrised (eq 32), then floored. Before each update R_k is "
    "written into the filter's R (Filter::noise().measurement_noise), so it is used from the next step on "
    "(eq 25). The first `warmup` residuals are not used (they hold the initial-state error, which the average "
    "would take for noise); meanwhile R is the measurements' own R times the noise factor squared of their second "
    "differences z_k - 2 z_k-1 + z_k-2 (covariance R_k + 4 R_k-1 + R_k-2 for any constant-velocity motion; "
    "warmup_estimate: second_differences, not in the paper) or the measurements' own R as it is (nominal). Sign: for the optimal gain E[dz dz'] = R S^-1 R = R - H P+ H', so '+' is unbiased and positive "
    "definite; eq 28 prints '-' (post_fit_term: subtract reproduces it; it is biased low). Floor: R >= "
    "floor_ratio^2 times the measurement's own R (generalised eigenvalues raised), then every eigenvalue >= "
    "floor_sigma^2. Starts from the first measurement's covariance. Needs a filter exposing R in measurement space "
    "cartesian_position (filter.kalman, filter.decoupled). covariance: follow_r (default; not in the paper) also "
    "rescales the filter's state covariance P by the change of the noise factor squared at every adapting step, so "
    "that P, built with the nominal R during the warm-up, follows R-hat as it grows (this removes the ADKF start-up "
    "transient; docs/papers/001-rbs-landing.md). Publishes R-hat's sigmas per ENU axis as annotations sigma_x, "
    "sigma_y, sigma_z. Reports the final R-hat sigmas averaged over runs.";

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "adapt.innovation_r";
  d.kind = ComponentKind::Adapter;
  // Its channels are three position values (2-D measurements are refused when the pipeline is built).
  d.accepts_frames = mask(Frame::Cartesian) | mask(Frame::Spherical);
  d.summary = "Adaptive measurement noise R from post-update residuals with a moving-average window (paper 001)";
  d.doc = kDoc;
  d.accepts = 0;
  d.min_inputs = 0;
  d.max_inputs = 0;
  d.produces = 0;
  d.params = {
      ParamSpec::integer("window", "moving-average window L of eq 31, in measurements (the paper does not state its L)").def("20").at_least(1).at_most(1000000),
      ParamSpec::real("floor_ratio", dim::none,
                      "R-hat is kept >= floor_ratio^2 x the measurement's own R (0: no relative floor)")
          .def("0.1")
          .at_least(0)
          .at_most(1),
      ParamSpec::real("floor_sigma", dim::length, "every eigenvalue of R-hat is kept >= floor_sigma^2").def("1 mm").positive(),
      ParamSpec::choice<PostFitTerm>("post_fit_term", {{PostFitTerm::Add, "add"}, {PostFitTerm::Subtract, "subtract"}},
                        "R_s = dz dz' + H P+ H' (add: unbiased) or - H P+ H' (subtract: eq 28 as printed)")
          .def("add"),
      ParamSpec::integer("warmup", "updates after initialisation whose residuals are not used (0: from the first, as the paper)")
          .def("50")
          .at_least(0)
          .at_most(1000000),
      ParamSpec::choice<Covariance>("covariance", {{Covariance::FollowR, "follow_r"}, {Covariance::Keep, "keep"}},
                                    "rescale the filter's state covariance P as R-hat grows or shrinks (follow_r: by the "
                                    "change of the noise factor squared; not in the paper) or leave P alone (keep)")
          .def("follow_r"),
      ParamSpec::choice<WarmupEstimate>("warmup_estimate",
                                        {{WarmupEstimate::SecondDifferences, "second_differences"},
                                         {WarmupEstimate::Nominal, "nominal"}},
                                        "R during the warm-up: the measurements' own R times the noise factor squared "
                                        "from their second differences (no filter state involved; not in the paper), "
                                        "or the measurements' own R as it is (nominal)")
          .def("second_differences"),
  };
  d.create = [](const Params& p) {
    adapt::EstimatorSettings s;
    s.window = static_cast<int>(p.integer("window"));
    s.floor_ratio = p.real("floor_ratio");
    s.floor_sigma = p.real("floor_sigma");
    s.add_posterior = p.choice<PostFitTerm>("post_fit_term") == PostFitTerm::Add;
    s.warmup = static_cast<int>(p.integer("warmup"));
    return std::make_unique<InnovationRAdapter>(s, p.choice<Covariance>("covariance") == Covariance::FollowR,
                                                p.choice<WarmupEstimate>("warmup_estimate") ==
                                                    WarmupEstimate::SecondDifferences);
  };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("adapt.innovation_r", trackflow::register_components)
