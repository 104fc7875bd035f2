// Purpose: the track-oriented MHT itself — target trees of track hypotheses (leaves), their expansion per scan, the k best global hypotheses by Murty per cluster, N-scan pruning and leaf bounds, score-based confirmation and deletion — independent of the component that feeds it scans and publishes its TrackSets.
#pragma once

#include "assignment/k_best_assignment.hpp"
#include "association/assumed_sensor.hpp"
#include "association/gated_pairs.hpp"
#include "memory/grow.hpp"
#include "ranked_sums.hpp"

#include <trackflow/estimator.hpp>
#include <trackflow/scan.hpp>
#include <trackflow/tracker.hpp>
#include <trackflow/tracks.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace trackflow::tomht {

// The deepest N-scan window a leaf can remember (n_scan at most this minus one).
inline constexpr int kWindow = 32;

struct Settings {
  double gate_probability = 0.99;
  association::AssumedSensor sensor;
  double velocity_sigma = 5.0;  // one-point start's velocity prior per axis (max_speed / 2)
  int n_scan = 3;
  int max_hypotheses = 100;
  int max_leaves_per_tree = 20;
  double false_track_probability = 1e-6;     // alpha
  double true_track_loss_probability = 0.1;  // beta
  double score_drop = 6.5;
  int max_misses = 3;
  int max_tracks = 10000;
  double start_score = 0.0;  // L0 of a new tree (its first detection)
  // A cluster of more trees than this is given its best assignment only (GNN within it), counted:
  // Murty's ranking costs O(k n^3 m) on an n-row cluster, and dense clutter chains new trees into
  // clusters of hundreds of rows (200 clutter detections per km2 per scan: 2 s per scan unbounded).
  int max_cluster_trees = 30;
};

// What the engine counts (summed by the component into its run result).
struct Counters {
  std::uint64_t scans = 0, hypotheses = 0, leaves = 0, trees_started = 0, start_failed = 0, confirmed = 0,
                deleted = 0, pruned_leaves = 0, pruned_hypotheses = 0, updates_refused = 0, track_limit_refused = 0,
                confirmed_track_scans = 0, clusters_capped = 0;
};

// Track-oriented MHT (Blackman 2004, "Multiple hypothesis tracking for multiple target tracking",
// IEEE AES Magazine 19(1):5-18, doi:10.1109/MAES.2004.1263228, the track-oriented form; Kurien 1990, "Issues in the design of
// practical multitarget tracking algorithms", in Bar-Shalom (ed.), Multitarget-Multisensor Tracking:
// Advanced Applications, ch. 3; the k best global hypotheses by Murty's ranked assignment as in Cox &
// Hingorani 1996, "An efficient implementation of Reid's MHT algorithm and its evaluation for the
// purpose of visual tracking", IEEE PAMI 18(2):138-150).
//
// A target tree is one potential target, started by one detection. Its leaves are the track
// hypotheses still alive: each an estimator (a clone per branch), its score L — the log-likelihood
// ratio of "target" against "false alarms" (Blackman 2004, the track score; Blackman & Popoli
// 1999 sec. 6.2; tracker.hpp track_score):
//   L_root = L0 (start_score),  hit with z: dL = ln(P_D / beta_FA) + ln N(nu; 0, S),
//   miss: dL = ln(1 - P_D P_G)
// — and the detection it used in each of the last n_scan + 1 scans (-1: a miss).
//
// Per scan k:
//  1. Expansion: every live leaf is predicted, gated (chi-square gate P_G) and gets a miss child and
//     one child per gated detection (the estimator updated with it). Every detection starts a new
//     tree (one-point start, velocity sigma max_speed / 2).
//  2. Global hypotheses (D. B. Reid, "An algorithm for tracking multiple targets",
//     IEEE Trans. Automatic Control 24(6):843-854, 1979; Cox & Hingorani 1996): a global hypothesis is a set of
//     leaves, at most one per tree, each detection used once; a detection no existing tree of the
//     hypothesis takes is the start of its own new tree in that hypothesis. Its score is the sum of
//     its leaves' scores (a tree it dropped keeps its share: the hypothesis score is the sum of all
//     increments along its history). From each current hypothesis h, the children are the
//     assignments of this scan's detections to h's trees: rows = h's trees, columns = detections
//     plus one private miss column per row, cost c_ij = -(dL_ij - L0_j) (L0_j: what leaving j free
//     to start a tree would score) and c_i,miss = -dL_miss, so that
//         score(child) = score(h) + sum_j L0_j - sum of the chosen costs.
//     The problem splits into clusters of rows sharing gated detections; each cluster's k best
//     assignments come from KBestAssignment (Murty 1968, Miller, Stone & Cox 1997) — once per scan
//     for the same leaves (parents share most clusters), and lazily: the first parent's to
//     max_hypotheses, the others' to their best (the skip test), then twice as deep on demand,
//     resuming the search (KBestAssignment::resume) — and the k best joint ones from RankedSums.
//     The children of all hypotheses compete for max_hypotheses places (best score first; ties
//     by parent rank, then by rank within the parent: deterministic). A parent whose best
//     possible child cannot enter is skipped (tested first by each row's cheapest option, then by
//     its clusters' best answers).
//  3. Track management on the best hypothesis: its tree is confirmed when the leaf's L reaches
//     T_c = ln((1 - beta) / alpha) (Wald's SPRT on the score, Blackman 2004; as init.score).
//     A leaf is dead — it gets no children and its hypotheses drop the tree — after max_misses
//     consecutive misses, when L fell score_drop below its branch's peak, or while never confirmed
//     when L <= T_d = ln(beta / (1 - alpha)). When the best hypothesis's leaf of a tree is dead, the
//     tree is deleted (from every hypothesis) and published once as deleted.
//  4. N-scan pruning (Blackman 2004, track-oriented hypothesis management): the decisions of
//     scan k - N are fixed as the best hypothesis has them: a hypothesis survives only when every
//     leaf agrees with the best one's leaf of its tree at scan k - N (a tree born after k - N
//     agrees; an older tree the best hypothesis lacks does not). Previous prunings made all
//     leaves of a tree agree before k - N, so comparing the one scan suffices.
//  5. Leaves no surviving hypothesis uses are dropped; a tree keeps at most max_leaves_per_tree
//     (the best hypothesis's first, then by score), the hypotheses using the others dropped too.
//     A tree without leaves is gone (published once as deleted if it was ever published).
//
// Output: the best hypothesis's trees as tracks (id = tree id, assigned at its first publication,
// never reused; score = L of the leaf).
class Engine {
 public:
  struct Leaf {
    std::unique_ptr<Estimator> estimator;
    int tree = 0;  // into trees_
    double score = 0.0, peak = 0.0;
    int hits = 0, misses = 0;
    int depth = 0;  // scans since the tree's root
    bool dead = false;
    std::array<int, kWindow> recent{};  // recent[d]: detection used at scan k - d (-1: miss), d <= depth
    double last_time = 0.0;
    bool updated = false;  // this scan's update, its innovation (published)
    double nis = 0.0;
    MeasVec innovation;
    MeasCov innovation_covariance;
    // This scan's expansion: the miss child and the hit options [first_hit, first_hit + hit_count) of hits_.
    int miss_child = -1, first_hit = 0, hit_count = 0;
    bool can_predict = false;
    PredictedMeasurement predicted;
  };
  struct Tree {
    std::uint64_t id = 0;  // 0 until first published
    int birth_scan = 0;
    std::uint32_t origin = kOriginUnknown;
    TrackStatus status = TrackStatus::Tentative;
    bool deleted = false;  // deleted by track management this scan
    int in_best = -1;      // its leaf in the best hypothesis, or -1
    int used = 0;          // leaves used by surviving hypotheses
    TrackEstimate last;    // as last published
  };
  struct Hypothesis {
    double score = 0.0;
    int first = 0, count = 0;  // into hyp_leaves_: leaf indices, by tree
  };

  Engine(Settings s, std::unique_ptr<Estimator> prototype, std::string who)
      : s_(std::move(s)),
        prototype_(std::move(prototype)),
        who_(std::move(who)),
        confirm_(std::log((1.0 - s_.true_track_loss_probability) / s_.false_track_probability)),
        fail_(std::log(s_.true_track_loss_probability / (1.0 - s_.false_track_probability))),
        gated_(s_.gate_probability) {
    context_.who = who_ + " track";
    context_.estimate = &scratch_;
    context_.warnings = &warnings_;
    reset();
  }

  void reset() {
    for (Leaf& l : leaves_)
      if (l.estimator) spare_.push_back(std::move(l.estimator));
    leaves_.clear();
    trees_.clear();
    hyps_.assign(1, Hypothesis{});  // the empty hypothesis: no target yet
    hyp_leaves_.clear();
    next_id_ = 1;
    scan_ = 0;
    set_.clear();
    counters_ = Counters{};
  }

  double confirm_threshold() const { return confirm_; }
  double fail_threshold() const { return fail_; }

  // One look (valid, checked, in time order). Publishes into published().
  void process(const Scan& s) {
    ++scan_;
    ++counters_.scans;
    const double pd = s_.sensor.detection_probability(s);
    const double lambda = s_.sensor.clutter_density(s);
    miss_dL_ = track_score::miss(pd, s_.gate_probability);
    expand(s, pd, lambda);
    start_trees(s);
    form_hypotheses(s);
    manage();
    prune_n_scan();
    bound_leaves();
    publish(s.time);
    compact();
    counters_.hypotheses += hyps_.size();
    counters_.leaves += leaves_.size();
    // Spare estimators (for new trees' roots) bounded: the pruned branches would pile up otherwise.
    const std::size_t spares = leaves_.size() + s.detections.size() + 64;
    if (spare_.size() > spares) spare_.resize(spares);
  }

  // A look that did not happen: the same tracks at time t.
  void republish(double t) {
    for (TrackEstimate& e : set_) e.estimate.time = t;
    std::size_t kept = 0;
    for (std::size_t i = 0; i < set_.size(); ++i)
      if (set_[i].status != TrackStatus::Deleted) set_[kept++] = set_[i];
    set_.resize(kept);
  }

  std::span<const TrackEstimate> published() const { return set_; }
  const Counters& counters() const { return counters_; }
  std::vector<std::string>& warnings() { return warnings_; }

  // Inspection (tests): the hypotheses best first, their leaves, the leaves' trees.
  int hypotheses() const { return static_cast<int>(hyps_.size()); }
  double hypothesis_score(int h) const { return hyps_[static_cast<std::size_t>(h)].score; }
  std::span<const int> hypothesis_leaves(int h) const {
    const Hypothesis& x = hyps_[static_cast<std::size_t>(h)];
    return std::span<const int>(hyp_leaves_).subspan(static_cast<std::size_t>(x.first), static_cast<std::size_t>(x.count));
  }
  std::span<const Leaf> leaves() const { return leaves_; }
  std::span<const Tree> trees() const { return trees_; }
  int scan_index() const { return scan_; }

 private:
  struct HitOption {
    int detection = 0, child = 0;
    double dL = 0.0;
  };
  struct CacheEntry {
    std::uint64_t hash = 0;
    int key_first = 0, key_count = 0;  // cache_keys_: the cluster's leaves
    int child_first = 0;               // answer_child_: answers x rows children
    int cost_first = 0, answers = 0;   // answer_costs_
    int requested = 0;                 // the k of the last ranking
    bool complete = false;             // no more answers than these
  };
  struct Candidate {
    double score = 0.0;
    int parent = 0, seq = 0, first = 0, count = 0;
  };
  // The estimator reports here (one context for all leaves: only one runs at a time).
  struct Context final : TrackContext {
    std::vector<std::string>* warnings = nullptr;
    void warn(const std::string& message) override {
      if (warnings) warnings->push_back(who + ": " + message);
    }
    void count(int) override {}
    void annotate(int, double) override {}
  };

  int dimension(const SensorFrame& f, const Detection& d) const {
    const int positions = position_values(f.frame);
    switch (prototype_->measurement_spec().range_rate) {
      case RangeRateUse::Use: return positions + 1;
      case RangeRateUse::Auto: return d.has_range_rate ? positions + 1 : positions;
      case RangeRateUse::Ignore: break;
    }
    return positions;
  }

  void bind(Estimator& e, double time) {
    context_.time = time;
    scratch_.updated = false;
    e.bind(context_);
  }

  // A copy of a leaf's estimator for its child: a spare made into the copy in place
  // (Estimator::copy_from), so a steady population allocates nothing; a clone when no spare is
  // left or the estimator cannot copy in place.
  std::unique_ptr<Estimator> copy_of(const Estimator& parent) {
    if (!spare_.empty()) {
      std::unique_ptr<Estimator> e = std::move(spare_.back());
      spare_.pop_back();
      if (e->copy_from(parent)) return e;
      spare_.push_back(std::move(e));
    }
    return parent.clone();
  }

  std::unique_ptr<Estimator> fresh() {
    if (spare_.empty()) return prototype_->clone();
    std::unique_ptr<Estimator> e = std::move(spare_.back());
    spare_.pop_back();
    return e;
  }

  // Whether a leaf's branch ends here (track management, step 3 above).
  bool dies(const Leaf& l) const {
    return l.misses >= s_.max_misses || l.peak - l.score >= s_.score_drop || (l.peak < confirm_ && l.score <= fail_) ||
           !std::isfinite(l.score);
  }

  static void shift(const Leaf& parent, Leaf& child, int detection) {
    child.recent[0] = detection;
    for (int d = 1; d < kWindow; ++d) child.recent[static_cast<std::size_t>(d)] = parent.recent[static_cast<std::size_t>(d - 1)];
  }

  // Step 1: every live leaf predicted, gated, and its children made (into next_).
  void expand(const Scan& s, double pd, double lambda) {
    next_.clear();
    hits_.clear();
    views_.clear();
    for (Leaf& l : leaves_) {
      l.can_predict = false;
      l.miss_child = -1;
      l.hit_count = 0;
      if (!l.dead) {
        bind(*l.estimator, s.time);
        const double T = s.time - l.last_time;
        if (T > 0.0) l.estimator->predict(T);
        l.last_time = s.time;
        if (!s.detections.empty()) {
          const Detection& d = s.detections.front();
          MeasCov& R = l.estimator->measurement_noise();
          R = d.covariance.topLeftCorner(dimension(s.sensor, d), dimension(s.sensor, d));
          l.can_predict = l.estimator->predict_measurement(s.sensor, R, l.predicted);
        }
      }
      TrackView v;
      v.estimator = l.estimator.get();
      v.predicted = l.can_predict ? &l.predicted : nullptr;
      views_.push_back(v);
    }
    const std::span<const association::GatedPair> pairs = gated_.find(views_, s);
    std::size_t p = 0;
    const double log_pd = std::log(pd), log_lambda = std::log(lambda);
    for (std::size_t i = 0; i < leaves_.size(); ++i) {
      Leaf& l = leaves_[i];
      if (l.dead) {
        while (p < pairs.size() && pairs[p].track == static_cast<int>(i)) ++p;
        continue;
      }
      l.first_hit = static_cast<int>(hits_.size());
      for (; p < pairs.size() && pairs[p].track == static_cast<int>(i); ++p) {
        const association::GatedPair& g = pairs[p];
        const Detection& d = s.detections[static_cast<std::size_t>(g.detection)];
        std::unique_ptr<Estimator> e = copy_of(*l.estimator);
        bind(*e, s.time);
        const int dim = dimension(s.sensor, d);
        e->measurement_noise() = d.covariance.topLeftCorner(dim, dim);
        to_measurement(s, d, m_);
        if (!e->update(m_, dim)) {
          ++counters_.updates_refused;
          spare_.push_back(std::move(e));
          continue;
        }
        // ln(P_D / beta_FA) + ln N(nu; 0, S): track_score::hit with the gate's NIS and log det S.
        const double dL = log_pd - log_lambda + g.log_likelihood;
        next_.emplace_back();
        Leaf& c = next_.back();
        c.estimator = std::move(e);
        c.tree = l.tree;
        c.score = l.score + dL;
        c.peak = std::max(l.peak, c.score);
        c.hits = l.hits + 1;
        c.misses = 0;
        c.depth = l.depth + 1;
        shift(l, c, g.detection);
        c.last_time = s.time;
        c.updated = scratch_.updated;
        c.nis = scratch_.nis;
        c.innovation = scratch_.innovation;
        c.innovation_covariance = scratch_.innovation_covariance;
        c.dead = dies(c);
        hits_.push_back({g.detection, static_cast<int>(next_.size()) - 1, dL});
      }
      l.hit_count = static_cast<int>(hits_.size()) - l.first_hit;
      // The miss child takes the parent's (predicted) estimator: the parent is not kept.
      next_.emplace_back();
      Leaf& c = next_.back();
      c.estimator = std::move(l.estimator);
      c.tree = l.tree;
      c.score = l.score + miss_dL_;
      c.peak = l.peak;
      c.hits = l.hits;
      c.misses = l.misses + 1;
      c.depth = l.depth + 1;
      shift(l, c, -1);
      c.last_time = s.time;
      c.dead = dies(c);
      l.miss_child = static_cast<int>(next_.size()) - 1;
    }
  }

  // Step 1 (cont.): a new tree per detection, its root leaf in next_ (tree_of_detection_).
  void start_trees(const Scan& s) {
    const int m = static_cast<int>(s.detections.size());
    memory::assign_grown(tree_of_detection_, static_cast<std::size_t>(m), -1);
    memory::assign_grown(root_of_detection_, static_cast<std::size_t>(m), -1);
    for (int j = 0; j < m; ++j) {
      if (static_cast<int>(trees_.size()) >= s_.max_tracks) {
        ++counters_.track_limit_refused;
        continue;
      }
      const Detection& d = s.detections[static_cast<std::size_t>(j)];
      std::unique_ptr<Estimator> e = fresh();
      bind(*e, s.time);
      e->reset();
      const int dim = dimension(s.sensor, d);
      e->measurement_noise() = d.covariance.topLeftCorner(dim, dim);
      to_measurement(s, d, m_);
      if (!e->initiate_one_point(m_, dim, s_.velocity_sigma)) {
        ++counters_.start_failed;
        spare_.push_back(std::move(e));
        continue;
      }
      trees_.emplace_back();
      Tree& t = trees_.back();
      t.birth_scan = scan_;
      t.origin = d.origin;
      next_.emplace_back();
      Leaf& c = next_.back();
      c.estimator = std::move(e);
      c.tree = static_cast<int>(trees_.size()) - 1;
      c.score = c.peak = s_.start_score;
      c.hits = 1;
      c.recent.fill(-1);
      c.recent[0] = j;
      c.last_time = s.time;
      c.dead = false;
      tree_of_detection_[static_cast<std::size_t>(j)] = c.tree;
      root_of_detection_[static_cast<std::size_t>(j)] = static_cast<int>(next_.size()) - 1;
      ++counters_.trees_started;
    }
  }

  // Union-find over a parent's rows (clusters of rows sharing gated detections).
  int find(int r) {
    while (link_[static_cast<std::size_t>(r)] != r) {
      link_[static_cast<std::size_t>(r)] = link_[static_cast<std::size_t>(link_[static_cast<std::size_t>(r)])];
      r = link_[static_cast<std::size_t>(r)];
    }
    return r;
  }

  bool full() const { return static_cast<int>(kept_.size()) >= s_.max_hypotheses; }
  // "a is better than b" (higher score; ties: the earlier parent, then the earlier answer): as a
  // heap order it keeps the worst kept candidate on top; as a sort order it puts the best first.
  auto worse_on_top() const {
    return [this](int a, int b) {
      const Candidate& x = cands_[static_cast<std::size_t>(a)];
      const Candidate& y = cands_[static_cast<std::size_t>(b)];
      if (x.score != y.score) return x.score > y.score;
      return x.parent < y.parent || (x.parent == y.parent && x.seq < y.seq);
    };
  }
  double worst_kept() const { return cands_[static_cast<std::size_t>(kept_.front())].score; }

  // Step 2: the children of every hypothesis, the best max_hypotheses kept (hyps_ <- them).
  void form_hypotheses(const Scan& s) {
    const int m = static_cast<int>(s.detections.size());
    double bonus = 0.0;  // sum_j L0_j: every detection left free starts a tree
    for (int j = 0; j < m; ++j)
      if (tree_of_detection_[static_cast<std::size_t>(j)] >= 0) bonus += s_.start_score;
    cands_.clear();
    cand_leaves_.clear();
    kept_.clear();
    cache_.clear();
    cache_keys_.clear();
    murty_entry_ = -1;
    std::fill(cache_table_.begin(), cache_table_.end(), -1);
    answer_child_.clear();
    answer_costs_.clear();
    memory::assign_grown(owner_, static_cast<std::size_t>(m), -1);
    memory::assign_grown(used_, static_cast<std::size_t>(m), char{0});
    for (int h = 0; h < static_cast<int>(hyps_.size()); ++h) {
      const Hypothesis& H = hyps_[static_cast<std::size_t>(h)];
      // Rows: the hypothesis's live leaves (a dead leaf's tree leaves it).
      rows_.clear();
      double cheapest = 0.0;  // sum over rows of the cheapest option: the bound on any child
      for (int q = 0; q < H.count; ++q) {
        const int li = hyp_leaves_[static_cast<std::size_t>(H.first + q)];
        const Leaf& l = leaves_[static_cast<std::size_t>(li)];
        if (l.dead) continue;
        rows_.push_back(li);
        double c = -miss_dL_;
        for (int o = 0; o < l.hit_count; ++o) {
          const HitOption& x = hits_[static_cast<std::size_t>(l.first_hit + o)];
          c = std::min(c, hit_cost(x));
        }
        cheapest += c;
      }
      if (full() && !(H.score + bonus - cheapest > worst_kept())) continue;
      // The first parent ranks its clusters as deep as max_hypotheses at once (its children fill the
      // places); the others start from each cluster's best, enough to test whether their best child
      // enters, and go deeper only on demand.
      first_k_ = h == 0 ? s_.max_hypotheses : 1;
      solve_clusters(m);
      if (full()) {
        double best = forced_cost_;
        for (std::size_t c = 0; c < cluster_entry_.size(); ++c)
          best += answer_costs_[static_cast<std::size_t>(cache_[static_cast<std::size_t>(cluster_entry_[c])].cost_first)];
        if (!(H.score + bonus - best > worst_kept())) continue;
      }
      // The joint answers best first, while they can still enter.
      lists_.e = this;
      sums_.start(lists_);
      int seq = 0;
      while (sums_.next()) {
        const double score = H.score + bonus - (forced_cost_ + sums_.cost());
        if (full() && !(score > worst_kept())) break;
        add_candidate(h, seq++, score, m);
      }
    }
    // The kept ones best first (score, then parent rank, then rank in the parent).
    std::sort(kept_.begin(), kept_.end(), [&](int a, int b) { return worse_on_top()(a, b); });
    next_hyps_.clear();
    next_hyp_leaves_.clear();
    for (const int c : kept_) {
      const Candidate& x = cands_[static_cast<std::size_t>(c)];
      Hypothesis y;
      y.score = x.score;
      y.first = static_cast<int>(next_hyp_leaves_.size());
      y.count = x.count;
      next_hyp_leaves_.insert(next_hyp_leaves_.end(), cand_leaves_.begin() + x.first,
                              cand_leaves_.begin() + x.first + x.count);
      next_hyps_.push_back(y);
    }
    std::swap(hyps_, next_hyps_);
    std::swap(hyp_leaves_, next_hyp_leaves_);
    // The children replace their parents; the parents' left-over estimators become spares.
    for (Leaf& l : leaves_)
      if (l.estimator) spare_.push_back(std::move(l.estimator));
    std::swap(leaves_, next_);
  }

  double hit_cost(const HitOption& x) const {
    const double L0 = tree_of_detection_[static_cast<std::size_t>(x.detection)] >= 0 ? s_.start_score : 0.0;
    return -(x.dL - L0);
  }

  // The clusters of rows_ and each one's ranked answers (RankedSums lists; answer_child_: the
  // chosen child of each row per answer). Rows without a gated detection take their miss.
  void solve_clusters(int m) {
    const int n = static_cast<int>(rows_.size());
    memory::assign_grown(link_, static_cast<std::size_t>(n), 0);
    for (int r = 0; r < n; ++r) link_[static_cast<std::size_t>(r)] = r;
    touched_.clear();
    for (int r = 0; r < n; ++r) {
      const Leaf& l = leaves_[static_cast<std::size_t>(rows_[static_cast<std::size_t>(r)])];
      for (int o = 0; o < l.hit_count; ++o) {
        const int j = hits_[static_cast<std::size_t>(l.first_hit + o)].detection;
        int& w = owner_[static_cast<std::size_t>(j)];
        if (w < 0) {
          w = r;
          touched_.push_back(j);
        } else {
          const int a = find(w), b = find(r);
          if (a != b) link_[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
        }
      }
    }
    for (const int j : touched_) owner_[static_cast<std::size_t>(j)] = -1;
    // Rows grouped by cluster root (clusters in order of their first row; rows in order).
    memory::assign_grown(cluster_of_root_, static_cast<std::size_t>(n), -1);
    cluster_rows_.clear();
    cluster_first_.clear();
    order_.clear();
    forced_cost_ = 0.0;
    memory::assign_grown(row_choice_, static_cast<std::size_t>(n), -1);
    int clusters = 0;
    for (int r = 0; r < n; ++r) {
      const Leaf& l = leaves_[static_cast<std::size_t>(rows_[static_cast<std::size_t>(r)])];
      if (l.hit_count == 0) {  // only the miss
        forced_cost_ += -miss_dL_;
        row_choice_[static_cast<std::size_t>(r)] = l.miss_child;
        continue;
      }
      const int root = find(r);
      if (cluster_of_root_[static_cast<std::size_t>(root)] < 0) cluster_of_root_[static_cast<std::size_t>(root)] = clusters++;
    }
    memory::assign_grown(cluster_size_, static_cast<std::size_t>(clusters) + 1, 0);
    for (int r = 0; r < n; ++r)
      if (row_choice_[static_cast<std::size_t>(r)] < 0) ++cluster_size_[static_cast<std::size_t>(cluster_of_root_[static_cast<std::size_t>(find(r))]) + 1];
    for (int c = 0; c < clusters; ++c) cluster_size_[static_cast<std::size_t>(c) + 1] += cluster_size_[static_cast<std::size_t>(c)];
    cluster_first_.assign(cluster_size_.begin(), cluster_size_.begin() + clusters + 1);
    memory::assign_grown(cluster_rows_, static_cast<std::size_t>(cluster_first_.back()), 0);
    for (int r = 0; r < n; ++r)
      if (row_choice_[static_cast<std::size_t>(r)] < 0) {
        const int c = cluster_of_root_[static_cast<std::size_t>(find(r))];
        cluster_rows_[static_cast<std::size_t>(cluster_size_[static_cast<std::size_t>(c)]++)] = r;
      }
    for (int r = 0; r < n; ++r) cluster_of_root_[static_cast<std::size_t>(r)] = -1;

    cluster_entry_.clear();
    for (int c = 0; c < clusters; ++c) solve_cluster(c);
    (void)m;
  }

  // The cluster's leaves (its key in the cache: the same leaves make the same matrix).
  std::uint64_t cluster_key(int b0, int b1) {
    key_.clear();
    std::uint64_t h = 1469598103934665603ull;  // FNV-1a over the leaf indices
    for (int q = b0; q < b1; ++q) {
      const int li = rows_[static_cast<std::size_t>(cluster_rows_[static_cast<std::size_t>(q)])];
      key_.push_back(li);
      h = (h ^ static_cast<std::uint64_t>(li)) * 1099511628211ull;
    }
    return h;
  }

  // The cache entry of key_ (hash h), or -1; open addressing in a power-of-two table.
  int cache_find(std::uint64_t h) const {
    if (cache_table_.empty()) return -1;
    const std::size_t mask = cache_table_.size() - 1;
    for (std::size_t q = h & mask;; q = (q + 1) & mask) {
      const int e = cache_table_[q];
      if (e < 0) return -1;
      const CacheEntry& x = cache_[static_cast<std::size_t>(e)];
      if (x.hash == h && x.key_count == static_cast<int>(key_.size()) &&
          std::equal(key_.begin(), key_.end(), cache_keys_.begin() + x.key_first))
        return e;
    }
  }
  void cache_insert(std::uint64_t h, const CacheEntry& entry) {
    if (2 * (cache_.size() + 1) > cache_table_.size()) {  // grow and rehash (load <= 1/2)
      memory::assign_grown(cache_table_, std::max<std::size_t>(64, 2 * cache_table_.size()), -1);
      const std::size_t mask = cache_table_.size() - 1;
      for (std::size_t e = 0; e < cache_.size(); ++e) {
        std::size_t q = cache_[e].hash & mask;
        while (cache_table_[q] >= 0) q = (q + 1) & mask;
        cache_table_[q] = static_cast<int>(e);
      }
    }
    const std::size_t mask = cache_table_.size() - 1;
    std::size_t q = h & mask;
    while (cache_table_[q] >= 0) q = (q + 1) & mask;
    cache_.push_back(entry);
    cache_table_[q] = static_cast<int>(cache_.size()) - 1;
  }

  // Cluster c's ranked answers: its cache entry (cluster_entry_[c]). Parents share most of their
  // leaves, so most clusters recur across the parents of a scan: each distinct one (by its leaves)
  // is ranked once per scan, and only as deep as the enumeration of joint answers asks (extend()).
  void solve_cluster(int c) {
    const int b0 = cluster_first_[static_cast<std::size_t>(c)], b1 = cluster_first_[static_cast<std::size_t>(c) + 1];
    const std::uint64_t h = cluster_key(b0, b1);
    int e = cache_find(h);
    if (e < 0) {
      CacheEntry entry;
      entry.hash = h;
      entry.key_first = static_cast<int>(cache_keys_.size());
      entry.key_count = b1 - b0;
      cache_keys_.insert(cache_keys_.end(), key_.begin(), key_.end());
      cache_insert(h, entry);
      e = static_cast<int>(cache_.size()) - 1;
      rank_cluster(c, e, first_k_);
    }
    cluster_entry_.push_back(e);
  }

  // More answers of cluster c (twice as many, at most max_hypotheses); false when it has no more.
  bool extend_cluster(int c) {
    const int e = cluster_entry_[static_cast<std::size_t>(c)];
    const CacheEntry& x = cache_[static_cast<std::size_t>(e)];
    if (x.complete) return false;
    const int before = x.answers;
    rank_cluster(c, e, std::min(s_.max_hypotheses, std::max(2, 2 * x.requested)));
    return cache_[static_cast<std::size_t>(e)].answers > before;
  }

  // Ranks cluster c's k best answers into entry e (appended to the pools; an earlier, shorter
  // ranking of the same entry is superseded).
  void rank_cluster(int c, int e, int k) {
    const int b0 = cluster_first_[static_cast<std::size_t>(c)], b1 = cluster_first_[static_cast<std::size_t>(c) + 1];
    const int a = b1 - b0;
    const int child_first = static_cast<int>(answer_child_.size()), cost_first = static_cast<int>(answer_costs_.size());
    bool complete = false;
    if (a == 1) {  // one row: its options ranked directly (cost, then detection: miss last on ties), all of them
      const Leaf& l = leaves_[static_cast<std::size_t>(rows_[static_cast<std::size_t>(cluster_rows_[static_cast<std::size_t>(b0)])])];
      single_.clear();
      for (int o = 0; o < l.hit_count; ++o) {
        const HitOption& x = hits_[static_cast<std::size_t>(l.first_hit + o)];
        single_.push_back({hit_cost(x), x.detection, x.child});
      }
      single_.push_back({-miss_dL_, std::numeric_limits<int>::max(), l.miss_child});
      std::sort(single_.begin(), single_.end(), [](const Option& x, const Option& y) {
        return x.cost < y.cost || (x.cost == y.cost && x.detection < y.detection);
      });
      const std::size_t n = std::min(single_.size(), static_cast<std::size_t>(s_.max_hypotheses));
      for (std::size_t q = 0; q < n; ++q) {
        answer_costs_.push_back(single_[q].cost);
        answer_child_.push_back(single_[q].child);
      }
      complete = true;
      k = static_cast<int>(n);
    } else {
      // Columns: the cluster's detections in index order, then the rows' miss columns.
      cols_.clear();
      for (int q = b0; q < b1; ++q) {
        const Leaf& l = leaves_[static_cast<std::size_t>(rows_[static_cast<std::size_t>(cluster_rows_[static_cast<std::size_t>(q)])])];
        for (int o = 0; o < l.hit_count; ++o) cols_.push_back(hits_[static_cast<std::size_t>(l.first_hit + o)].detection);
      }
      std::sort(cols_.begin(), cols_.end());
      cols_.erase(std::unique(cols_.begin(), cols_.end()), cols_.end());
      const int b = static_cast<int>(cols_.size()), w = b + a;
      constexpr double kInf = std::numeric_limits<double>::infinity();
      memory::assign_grown(cost_, static_cast<std::size_t>(a) * static_cast<std::size_t>(w), kInf);
      memory::assign_grown(child_, static_cast<std::size_t>(a) * static_cast<std::size_t>(w), -1);
      for (int r = 0; r < a; ++r) {
        const Leaf& l = leaves_[static_cast<std::size_t>(rows_[static_cast<std::size_t>(cluster_rows_[static_cast<std::size_t>(b0 + r)])])];
        for (int o = 0; o < l.hit_count; ++o) {
          const HitOption& x = hits_[static_cast<std::size_t>(l.first_hit + o)];
          const int col = static_cast<int>(std::lower_bound(cols_.begin(), cols_.end(), x.detection) - cols_.begin());
          cost_[static_cast<std::size_t>(r * w + col)] = hit_cost(x);
          child_[static_cast<std::size_t>(r * w + col)] = x.child;
        }
        cost_[static_cast<std::size_t>(r * w + b + r)] = -miss_dL_;
        child_[static_cast<std::size_t>(r * w + b + r)] = l.miss_child;
      }
      // Too large to rank: its best assignment only, and no more answers asked of it.
      const bool capped = a > s_.max_cluster_trees;
      if (capped) {
        k = 1;
        ++counters_.clusters_capped;
      }
      // The solver still holds this cluster's search when it ranked it last: continue it.
      const bool resume = murty_entry_ == e;
      const std::span<const assignment::RankedAssignment> answers = resume ? murty_.resume(k) : murty_.solve(cost_, a, w, k);
      murty_entry_ = e;
      for (const assignment::RankedAssignment& x : answers) {
        answer_costs_.push_back(x.total_cost);
        for (int r = 0; r < a; ++r)
          answer_child_.push_back(child_[static_cast<std::size_t>(r * w + x.column_for_row[static_cast<std::size_t>(r)])]);
      }
      complete = capped || static_cast<int>(answers.size()) < k || k >= s_.max_hypotheses;
    }
    CacheEntry& x = cache_[static_cast<std::size_t>(e)];
    x.child_first = child_first;
    x.cost_first = cost_first;
    x.answers = static_cast<int>(answer_costs_.size()) - cost_first;
    x.requested = k;
    x.complete = complete;
  }

  // The clusters' ranked lists as RankedSums reads them.
  struct ClusterLists final : RankedLists {
    Engine* e = nullptr;
    int lists() const override { return static_cast<int>(e->cluster_entry_.size()); }
    int size(int c) const override { return entry(c).answers; }
    double at(int c, int i) const override { return e->answer_costs_[static_cast<std::size_t>(entry(c).cost_first + i)]; }
    bool extend(int c) override { return e->extend_cluster(c); }
    const CacheEntry& entry(int c) const {
      return e->cache_[static_cast<std::size_t>(e->cluster_entry_[static_cast<std::size_t>(c)])];
    }
  };

  // The child hypothesis of parent h for the current joint answer of sums_, kept if it enters.
  void add_candidate(int h, int seq, double score, int m) {
    const int n = static_cast<int>(rows_.size());
    Candidate x;
    x.score = score;
    x.parent = h;
    x.seq = seq;
    // Its storage: a fresh slot, or the evicted worst one's when it is as long or longer.
    choice_.assign(row_choice_.begin(), row_choice_.begin() + n);
    const int clusters = static_cast<int>(cluster_first_.size()) - 1;
    for (int c = 0; c < clusters; ++c) {
      const int b0 = cluster_first_[static_cast<std::size_t>(c)], a = cluster_first_[static_cast<std::size_t>(c) + 1] - b0;
      const int base = cache_[static_cast<std::size_t>(cluster_entry_[static_cast<std::size_t>(c)])].child_first + sums_.index(c) * a;
      for (int r = 0; r < a; ++r)
        choice_[static_cast<std::size_t>(cluster_rows_[static_cast<std::size_t>(b0 + r)])] = answer_child_[static_cast<std::size_t>(base + r)];
    }
    x.first = static_cast<int>(cand_leaves_.size());
    for (int r = 0; r < n; ++r) {
      const int child = choice_[static_cast<std::size_t>(r)];
      cand_leaves_.push_back(child);
      const int j = leaves_next(child).recent[0];
      if (j >= 0) used_[static_cast<std::size_t>(j)] = 1;
    }
    for (int j = 0; j < m; ++j) {
      if (!used_[static_cast<std::size_t>(j)] && root_of_detection_[static_cast<std::size_t>(j)] >= 0)
        cand_leaves_.push_back(root_of_detection_[static_cast<std::size_t>(j)]);
      used_[static_cast<std::size_t>(j)] = 0;
    }
    x.count = static_cast<int>(cand_leaves_.size()) - x.first;
    cands_.push_back(x);
    const int id = static_cast<int>(cands_.size()) - 1;
    if (full()) {  // evict the worst (it is worse: the caller checked)
      std::pop_heap(kept_.begin(), kept_.end(), worse_on_top());
      kept_.back() = id;
    } else {
      kept_.push_back(id);
    }
    std::push_heap(kept_.begin(), kept_.end(), worse_on_top());
  }
  const Leaf& leaves_next(int i) const { return next_[static_cast<std::size_t>(i)]; }

  // Step 3: confirmation and deletion by the best hypothesis.
  void manage() {
    for (Tree& t : trees_) {
      t.in_best = -1;
      t.deleted = false;
    }
    bool any_deleted = false;
    for (const int li : hypothesis_leaves(0)) {
      const Leaf& l = leaves_[static_cast<std::size_t>(li)];
      Tree& t = trees_[static_cast<std::size_t>(l.tree)];
      t.in_best = li;
      if (l.dead) {
        t.deleted = true;
        any_deleted = true;
      } else if (t.status == TrackStatus::Tentative && l.score >= confirm_) {
        t.status = TrackStatus::Confirmed;
        ++counters_.confirmed;
      }
    }
    if (!any_deleted) return;
    // A deleted tree leaves every hypothesis (each keeps its score: the tree's share of its history).
    for (Hypothesis& h : hyps_) {
      const int first = h.first;
      int kept = 0;
      for (int q = 0; q < h.count; ++q) {
        const int li = hyp_leaves_[static_cast<std::size_t>(first + q)];
        if (!trees_[static_cast<std::size_t>(leaves_[static_cast<std::size_t>(li)].tree)].deleted)
          hyp_leaves_[static_cast<std::size_t>(first + kept++)] = li;
      }
      h.count = kept;
    }
  }

  // Drops the hypotheses (not the best) that `keep` refuses; order kept.
  template <class Keep>
  void filter_hypotheses(Keep&& keep) {
    std::size_t out = 1;
    for (std::size_t h = 1; h < hyps_.size(); ++h) {
      if (keep(hypothesis_leaves(static_cast<int>(h))))
        hyps_[out++] = hyps_[h];
      else
        ++counters_.pruned_hypotheses;
    }
    hyps_.resize(out);
  }

  // Step 4: N-scan pruning against the best hypothesis at scan k - N.
  void prune_n_scan() {
    const int N = s_.n_scan;
    const int fixed_scan = scan_ - N;  // decisions of scans <= this are the best hypothesis's
    if (fixed_scan < 1 || hyps_.size() <= 1) return;
    filter_hypotheses([&](std::span<const int> leaves) {
      for (const int li : leaves) {
        const Leaf& l = leaves_[static_cast<std::size_t>(li)];
        const Tree& t = trees_[static_cast<std::size_t>(l.tree)];
        if (t.birth_scan > fixed_scan) continue;
        if (t.in_best < 0) return false;
        if (l.recent[static_cast<std::size_t>(N)] != leaves_[static_cast<std::size_t>(t.in_best)].recent[static_cast<std::size_t>(N)])
          return false;
      }
      return true;
    });
  }

  void count_usage() {
    memory::assign_grown(leaf_used_, leaves_.size(), 0);
    for (std::size_t h = 0; h < hyps_.size(); ++h)
      for (const int li : hypothesis_leaves(static_cast<int>(h))) ++leaf_used_[static_cast<std::size_t>(li)];
  }

  // Step 5: at most max_leaves_per_tree used leaves per tree.
  void bound_leaves() {
    count_usage();
    by_tree_.clear();
    for (std::size_t i = 0; i < leaves_.size(); ++i)
      if (leaf_used_[i] > 0) by_tree_.push_back(static_cast<int>(i));
    // By tree, then the best hypothesis's leaf first, then score (descending), then index.
    std::sort(by_tree_.begin(), by_tree_.end(), [&](int a, int b) {
      const Leaf& x = leaves_[static_cast<std::size_t>(a)];
      const Leaf& y = leaves_[static_cast<std::size_t>(b)];
      if (x.tree != y.tree) return x.tree < y.tree;
      const bool bx = trees_[static_cast<std::size_t>(x.tree)].in_best == a, by = trees_[static_cast<std::size_t>(y.tree)].in_best == b;
      if (bx != by) return bx;
      if (x.score != y.score) return x.score > y.score;
      return a < b;
    });
    bool dropped = false;
    for (std::size_t q = 0, rank = 0; q < by_tree_.size(); ++q) {
      if (q > 0 && leaves_[static_cast<std::size_t>(by_tree_[q])].tree != leaves_[static_cast<std::size_t>(by_tree_[q - 1])].tree) rank = 0;
      if (static_cast<int>(rank++) >= s_.max_leaves_per_tree) {
        leaf_used_[static_cast<std::size_t>(by_tree_[q])] = -1;  // over the bound
        dropped = true;
      }
    }
    if (dropped)
      filter_hypotheses([&](std::span<const int> leaves) {
        for (const int li : leaves)
          if (leaf_used_[static_cast<std::size_t>(li)] < 0) return false;
        return true;
      });
    count_usage();
  }

  // The best hypothesis's tracks, and the trees gone for good (once, as deleted).
  void publish(double time) {
    for (Tree& t : trees_) t.used = 0;
    for (std::size_t i = 0; i < leaves_.size(); ++i)
      if (leaf_used_[i] > 0) ++trees_[static_cast<std::size_t>(leaves_[i].tree)].used;
    set_.clear();
    for (Tree& t : trees_) {
      if (t.deleted || (t.used == 0 && t.id != 0)) {
        if (t.id == 0) continue;  // never shown: nothing to retract
        if (t.deleted && t.in_best >= 0) fill(t, leaves_[static_cast<std::size_t>(t.in_best)], time);
        t.last.status = TrackStatus::Deleted;
        t.last.estimate.time = time;
        t.deleted = true;
        t.used = 0;
        ++counters_.deleted;
        set_.push_back(t.last);
        continue;
      }
      if (t.in_best < 0) continue;
      const Leaf& l = leaves_[static_cast<std::size_t>(t.in_best)];
      if (t.id == 0) t.id = next_id_++;
      fill(t, l, time);
      if (t.status != TrackStatus::Tentative) {
        t.status = l.misses > 0 ? TrackStatus::Coasting : TrackStatus::Confirmed;
        ++counters_.confirmed_track_scans;
      }
      t.last.status = t.status;
      set_.push_back(t.last);
    }
  }

  void fill(Tree& t, const Leaf& l, double time) {
    TrackEstimate& p = t.last;
    p.id = t.id;
    p.score = l.score;
    p.hits = l.hits;
    p.misses = l.misses;
    Estimate& e = p.estimate;
    l.estimator->fill(e);
    e.time = time;
    e.initialised = true;
    e.target = t.origin;
    e.updated = l.updated;
    e.nis = l.updated ? l.nis : 0.0;
    if (l.updated) {
      e.innovation = l.innovation;
      e.innovation_covariance = l.innovation_covariance;
    } else {
      e.innovation.resize(0);
      e.innovation_covariance.resize(0, 0);
    }
  }

  // Unused leaves and gone trees removed, indices renumbered (order kept: trees by id, leaves by tree).
  void compact() {
    memory::assign_grown(leaf_index_, leaves_.size(), -1);
    std::size_t kept = 0;
    for (std::size_t i = 0; i < leaves_.size(); ++i) {
      if (leaf_used_[i] > 0) {
        leaf_index_[i] = static_cast<int>(kept);
        if (kept != i) leaves_[kept] = std::move(leaves_[i]);
        ++kept;
      } else {
        ++counters_.pruned_leaves;
        if (leaves_[i].estimator) spare_.push_back(std::move(leaves_[i].estimator));
      }
    }
    leaves_.resize(kept);
    for (int& li : hyp_leaves_) li = li >= 0 ? leaf_index_[static_cast<std::size_t>(li)] : li;
    memory::assign_grown(tree_index_, trees_.size(), -1);
    std::size_t kt = 0;
    for (std::size_t i = 0; i < trees_.size(); ++i) {
      if (trees_[i].used > 0 && !trees_[i].deleted) {
        tree_index_[i] = static_cast<int>(kt);
        if (kt != i) trees_[kt] = std::move(trees_[i]);
        ++kt;
      }
    }
    trees_.resize(kt);
    for (Leaf& l : leaves_) l.tree = tree_index_[static_cast<std::size_t>(l.tree)];
    // Hypotheses' leaf lists packed (the pool may hold gaps after deletions).
    next_hyp_leaves_.clear();
    for (Hypothesis& h : hyps_) {
      const int first = static_cast<int>(next_hyp_leaves_.size());
      next_hyp_leaves_.insert(next_hyp_leaves_.end(), hyp_leaves_.begin() + h.first, hyp_leaves_.begin() + h.first + h.count);
      h.first = first;
    }
    std::swap(hyp_leaves_, next_hyp_leaves_);
  }

  struct Option {
    double cost = 0.0;
    int detection = 0, child = 0;
  };

  Settings s_;
  std::unique_ptr<Estimator> prototype_;
  std::string who_;
  double confirm_, fail_;
  association::GatedPairs gated_;
  Context context_;
  Estimate scratch_;
  std::vector<std::string> warnings_;
  Measurement m_;
  double miss_dL_ = 0.0;
  int scan_ = 0;
  std::uint64_t next_id_ = 1;
  Counters counters_;

  std::vector<Leaf> leaves_, next_;
  std::vector<std::unique_ptr<Estimator>> spare_;
  std::vector<Tree> trees_;
  std::vector<Hypothesis> hyps_, next_hyps_;
  std::vector<int> hyp_leaves_, next_hyp_leaves_;
  std::vector<TrackView> views_;
  std::vector<HitOption> hits_;
  std::vector<int> tree_of_detection_, root_of_detection_;
  // Hypothesis formation's work arrays.
  std::vector<Candidate> cands_;
  std::vector<int> cand_leaves_, kept_, rows_, link_, owner_, touched_, cluster_of_root_, cluster_rows_, cluster_first_,
      cluster_size_, order_, row_choice_, choice_, answer_child_, cols_, child_;
  std::vector<char> used_;
  std::vector<double> answer_costs_, cost_;
  std::vector<CacheEntry> cache_;
  std::vector<int> cache_keys_, cache_table_, key_;
  std::vector<Option> single_;
  double forced_cost_ = 0.0;
  int first_k_ = 1;       // the k of a cluster's first ranking
  int murty_entry_ = -1;  // the cache entry whose search murty_ holds (resumable)
  RankedSums sums_;
  ClusterLists lists_;
  std::vector<int> cluster_entry_;
  assignment::KBestAssignment murty_;
  std::vector<int> leaf_used_, by_tree_, leaf_index_, tree_index_;
  std::vector<TrackEstimate> set_;
};

}  // namespace trackflow::tomht
