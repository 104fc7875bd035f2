// Purpose: tracker.tomht — a track-oriented multiple hypothesis tracker: target trees of track hypotheses, the k best global hypotheses per scan (Murty per cluster), N-scan pruning, score-based (SPRT) confirmation and deletion; publishes the best global hypothesis as one TrackSet per scan.
#include "association/scan_check.hpp"
#include "association/assumed_sensor.hpp"
#include "association/gating.hpp"
#include "tomht_engine.hpp"

#include <trackflow/component.hpp>
#include <trackflow/error.hpp>
#include <trackflow/estimator.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/tracker.hpp>
#include <trackflow/units.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace trackflow {
namespace {

// Per run, summed over the ensemble.
struct TomhtRunResult final : RunResult {
  std::uint64_t scans = 0, looks = 0, scans_not_looked = 0, scans_skipped = 0, detections = 0, hypotheses = 0,
                leaves = 0, trees_started = 0, start_failed = 0, confirmed = 0, deleted = 0, pruned_leaves = 0,
                pruned_hypotheses = 0, updates_refused = 0, track_limit_refused = 0, confirmed_track_scans = 0,
                clusters_capped = 0;
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.scans, r.looks, r.scans_not_looked, r.scans_skipped, r.detections, r.hypotheses, r.leaves, r.trees_started,
      r.start_failed, r.confirmed, r.deleted, r.pruned_leaves, r.pruned_hypotheses, r.updates_refused,
      r.track_limit_refused, r.confirmed_track_scans, r.clusters_capped);
  }
};

class TomhtTracker final : public Component, public FieldListCodec<TomhtRunResult> {
 public:
  TomhtTracker(std::string node, tomht::Settings s, std::unique_ptr<Estimator> prototype)
      : node_(std::move(node)),
        max_cluster_trees_(s.max_cluster_trees),
        spec_(prototype->measurement_spec()),
        checker_(prototype->clone()),
        engine_(std::move(s), std::move(prototype), "tracker.tomht (node '" + node_ + "')") {}

  void start_run(const RunContext& ctx) override {
    diag_ = ctx.diagnostics;
    run_ = TomhtRunResult{};
    engine_.reset();
    has_time_ = false;
    warned_ = false;
    engine_.warnings().clear();
  }

  void on_scan(const Scan& s, int) override {
    if (has_time_ && s.time < last_time_) {
      ++run_.scans_skipped;
      if (diag_) diag_->skip(node_, "scan at t=" + std::to_string(s.time) + " s is older than the previous one");
      return;
    }
    has_time_ = true;
    last_time_ = s.time;
    ++run_.scans;
    if (!s.valid) {  // the sensor did not look: no information, nothing missed
      ++run_.scans_not_looked;
      engine_.republish(s.time);
      out.emit(TrackSet{s.time, engine_.published()});
      return;
    }
    check(s);
    ++run_.looks;
    run_.detections += s.detections.size();
    engine_.process(s);
    out.emit(TrackSet{s.time, engine_.published()});
    report_warnings();
  }

  std::unique_ptr<RunResult> end_run() override {
    const tomht::Counters& c = engine_.counters();
    run_.hypotheses = c.hypotheses;
    run_.leaves = c.leaves;
    run_.trees_started = c.trees_started;
    run_.start_failed = c.start_failed;
    run_.confirmed = c.confirmed;
    run_.deleted = c.deleted;
    run_.pruned_leaves = c.pruned_leaves;
    run_.pruned_hypotheses = c.pruned_hypotheses;
    run_.updates_refused = c.updates_refused;
    run_.track_limit_refused = c.track_limit_refused;
    run_.confirmed_track_scans = c.confirmed_track_scans;
    run_.clusters_capped = c.clusters_capped;
    return std::make_unique<TomhtRunResult>(run_);
  }
  void merge(RunResult& result) override {
    const auto& r = static_cast<const TomhtRunResult&>(result);
    ++runs_;
    TomhtRunResult::fields(total_, [&](auto&... t) {
      TomhtRunResult::fields(r, [&](const auto&... x) { ((t += x), ...); });
    });
  }
  void finish(Summary& s, const FinishContext&) override {
    const double runs = runs_ ? static_cast<double>(runs_) : 1.0;
    const double looks = total_.looks ? static_cast<double>(total_.looks) : 1.0;
    s.metric("scans", static_cast<double>(total_.scans));
    s.metric("hypotheses_per_scan", static_cast<double>(total_.hypotheses) / looks);
    s.metric("leaves_per_scan", static_cast<double>(total_.leaves) / looks);
    s.metric("trees_started_per_run", static_cast<double>(total_.trees_started) / runs);
    s.metric("tracks_confirmed_per_run", static_cast<double>(total_.confirmed) / runs);
    s.metric("tracks_deleted_per_run", static_cast<double>(total_.deleted) / runs);
    s.metric("confirmed_tracks_per_scan",
             total_.scans ? static_cast<double>(total_.confirmed_track_scans) / static_cast<double>(total_.scans) : 0.0);
    s.metric("pruned_leaves", static_cast<double>(total_.pruned_leaves));
    s.metric("pruned_hypotheses", static_cast<double>(total_.pruned_hypotheses));
    if (total_.clusters_capped) {
      s.metric("clusters_capped", static_cast<double>(total_.clusters_capped));
      s.notes.push_back(std::to_string(total_.clusters_capped) + " cluster ranking(s) of more than max_cluster_trees (" +
                        std::to_string(max_cluster_trees_) + ") trees gave their best assignment only");
    }
    if (total_.updates_refused) s.metric("updates_refused", static_cast<double>(total_.updates_refused));
    if (total_.start_failed) s.metric("starts_failed", static_cast<double>(total_.start_failed));
    if (total_.scans_not_looked) s.metric("scans_not_looked", static_cast<double>(total_.scans_not_looked));
    if (total_.scans_skipped) s.metric("scans_skipped", static_cast<double>(total_.scans_skipped));
    if (total_.track_limit_refused) {
      s.metric("starts_refused_at_max_tracks", static_cast<double>(total_.track_limit_refused));
      s.notes.push_back(std::to_string(total_.track_limit_refused) +
                        " tree start(s) refused: max_tracks trees were alive");
    }
  }

 private:
  void check(const Scan& s) { association::check_scan(s, *checker_, m_, "tracker.tomht (node '" + node_ + "')"); }

  void report_warnings() {
    std::vector<std::string>& w = engine_.warnings();
    if (!w.empty() && !warned_ && diag_)
      diag_->warn(node_, w.front() + (w.size() > 1 ? " (further warnings of this run not shown)" : ""));
    warned_ = warned_ || !w.empty();
    w.clear();
  }

  std::string node_;
  int max_cluster_trees_ = 0;
  MeasurementSpec spec_;
  std::unique_ptr<Estimator> checker_;  // the estimator's own checks of a scan's detections
  tomht::Engine engine_;
  Diagnostics* diag_ = nullptr;
  TomhtRunResult run_, total_;
  std::uint64_t runs_ = 0;
  Measurement m_;
  double last_time_ = 0.0;
  bool has_time_ = false, warned_ = false;
};

std::unique_ptr<Component> create(const Params& p) {
  const NestedComponent& estimator_entry = p.component("estimator");
  std::unique_ptr<Estimator> estimator = estimator_entry.create_estimator();
  if (!estimator->starts_from_one_point())
    throw ConfigError("tracker.tomht starts every tree from one detection, which " + estimator_entry.type +
                          " cannot (it offers no Estimator::initiate_one_point): take filter.kalman, filter.ekf or "
                          "filter.ukf",
                      estimator_entry.type_where, p.node());
  tomht::Settings s;
  s.gate_probability = p.real("gate_probability");
  s.sensor = association::AssumedSensor(p, "tracker.tomht (node '" + p.node() + "')");
  s.velocity_sigma = p.real("max_speed") / 2.0;
  s.n_scan = static_cast<int>(p.integer("n_scan"));
  s.max_hypotheses = static_cast<int>(p.integer("max_hypotheses"));
  s.max_leaves_per_tree = static_cast<int>(p.integer("max_leaves_per_tree"));
  s.false_track_probability = p.real("false_track_probability");
  s.true_track_loss_probability = p.real("true_track_loss_probability");
  if (s.false_track_probability + s.true_track_loss_probability >= 1.0)
    throw p.error("true_track_loss_probability", "false_track_probability + true_track_loss_probability must be below 1");
  s.score_drop = p.real("score_drop");
  s.max_misses = static_cast<int>(p.integer("max_misses"));
  s.max_tracks = static_cast<int>(p.integer("max_tracks"));
  s.start_score = p.real("start_score");
  s.max_cluster_trees = static_cast<int>(p.integer("max_cluster_trees"));
  return std::make_unique<TomhtTracker>(p.node(), std::move(s), std::move(estimator));
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "tracker.tomht";
  d.kind = ComponentKind::Tracker;
  d.summary = "Track-oriented multiple hypothesis tracker: target trees, k best global hypotheses (Murty), N-scan "
              "pruning, score-based confirmation and deletion; the best global hypothesis as one TrackSet per scan";
  d.doc =
      "Track-oriented MHT (Blackman 2004, IEEE AES Magazine 19(1):5-18; Kurien 1990; Cox & Hingorani 1996, IEEE "
      "PAMI 18(2):138-150). Every detection starts a target tree (one-point start, velocity sigma max_speed / 2); a "
      "tree's leaves are its track hypotheses, each with its own estimator and log-likelihood-ratio score L (start "
      "start_score; a hit adds ln(P_D/beta_FA) + ln N(nu; 0, S), a miss ln(1 - P_D P_G)). Per scan every leaf gets a "
      "miss child and a child per detection in its chi-square gate; from each global hypothesis (a set of compatible "
      "leaves, at most one per tree, each detection once; a detection no tree of it takes starts its own tree) the "
      "best children come from Murty's k best assignments per cluster of trees sharing detections, and the best "
      "max_hypotheses of all are kept. N-scan pruning keeps only the hypotheses that agree with the best one n_scan "
      "scans back; leaves no hypothesis uses are dropped, at most max_leaves_per_tree per tree. A tree is confirmed "
      "when its leaf in the best hypothesis reaches ln((1 - beta)/alpha) (Wald's SPRT, as init.score); a leaf ends "
      "after max_misses consecutive misses, a fall of score_drop below its peak, or, never confirmed, at "
      "ln(beta/(1 - alpha)); a tree whose best-hypothesis leaf ends is deleted. Published: the best hypothesis's "
      "trees (id: the tree's, stable and never reused; score: L), a tree gone for good once as deleted. P_D and the "
      "clutter density are the parameters when given, else the scan's. See docs/multi-target.md.";
  d.accepts = mask(ItemKind::Scan);
  d.produces = mask(ItemKind::Tracks);
  d.params = {
      ParamSpec::component("estimator", {ComponentKind::Filter},
                           "each track hypothesis's estimator, e.g. { type: filter.kalman, q: 1 m2/s3 } (it must "
                           "start from one point)")
          .req(),
      association::gate_probability_param(),
      association::AssumedSensor::detection_probability_param(),
      association::AssumedSensor::clutter_density_param(),
      ParamSpec::real("max_speed", dim::velocity, "the fastest a target moves: a new tree's velocity sigma is half of it")
          .req()
          .positive(),
      ParamSpec::integer("n_scan", "N-scan pruning depth: decisions older than this many scans are fixed")
          .def("3")
          .at_least(0)
          .at_most(tomht::kWindow - 1),
      ParamSpec::integer("max_hypotheses", "global hypotheses kept per scan").def("100").at_least(1).at_most(100000),
      ParamSpec::integer("max_leaves_per_tree", "track hypotheses kept per target tree").def("20").at_least(1).at_most(10000),
      ParamSpec::real("false_track_probability", Dimension{},
                      "alpha: probability of confirming a false track (confirmation at L >= ln((1-beta)/alpha))")
          .def("1e-6")
          .positive()
          .at_most(0.5),
      ParamSpec::real("true_track_loss_probability", Dimension{},
                      "beta: probability of losing a true track (a never confirmed leaf ends at L <= ln(beta/(1-alpha)))")
          .def("0.1")
          .positive()
          .at_most(0.5),
      ParamSpec::real("score_drop", Dimension{}, "a leaf ends when its score falls this far below its peak")
          .def("6.5")
          .positive(),
      ParamSpec::integer("max_misses", "a leaf ends after this many consecutive misses").def("3").at_least(1),
      ParamSpec::integer("max_tracks", "at most this many target trees alive; further starts are refused and counted")
          .def("10000")
          .at_least(1),
      ParamSpec::real("start_score", Dimension{}, "L0 of a new tree, e.g. ln(beta_NT/beta_FA) (0: the reference)")
          .def("0"),
      ParamSpec::integer("max_cluster_trees",
                         "a cluster of more target trees than this gets its best assignment only (no ranking), counted: "
                         "Murty's ranking grows as the cube of the cluster")
          .def("30")
          .at_least(1)
          .at_most(1000),
  };
  d.create = create;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("tracker.tomht", trackflow::register_components)
