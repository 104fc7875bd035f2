// Purpose: filter.track_fusion — track-to-track fusion of two or more filters' estimates (covariance intersection, or information matrix fusion that counts the common process noise once).
#include "fusion_math.hpp"

#include <trackflow/error.hpp>
#include <trackflow/estimate_state.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/transition_model.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace trackflow {
namespace {

enum class Method { CovarianceIntersection, Information, Independent };
using Motion = TransitionModel::Motion;
using Noise = TransitionModel::Noise;

// The inputs' transition model (theirs, or the node's parameters), the fusion method.
struct Settings : TransitionModel {
  Method method = Method::CovarianceIntersection;
  fusion::CiCriterion criterion = fusion::CiCriterion::Trace;
  std::string node;
};

constexpr int kMaxInputs = 8;

// Per run: fused estimates published, fused-track restarts (information not positive
// definite, or a local track that restarted), and for CI the sum of the first input's weight.
struct FusionRunResult final : RunResult {
  std::uint64_t fused = 0, restarts = 0, ci_count = 0;
  double ci_weight_sum = 0.0;
  // Its codec under mpirun (run_result_codec.hpp): one list, written and read in this order.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.fused, r.restarts, r.ci_count, r.ci_weight_sum);
  }
};

// The fused track's arithmetic for one state size (Order states per axis): every input's latest
// estimate, the fused state, and the transition matrices of the last interval.
template <int Order>
struct FusionCore {
  using Model = KinematicModel<Order>;
  static constexpr int N = Model::kDim;
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = Eigen::Matrix<double, N, N>;
  using AxisMatrix = typename Model::AxisMatrix;
  struct Local {
    bool has = false;
    double time = 0.0;
    Vec x = Vec::Zero();
    Mat P = Mat::Identity();
  };

  FusionCore() {
    idx[0] = Model::position_index(0), idx[1] = Model::position_index(1), idx[2] = Model::position_index(2);
    idx[3] = Model::velocity_index(0), idx[4] = Model::velocity_index(1), idx[5] = Model::velocity_index(2);
  }
  void reset() {
    for (Local& l : local) l = Local{};
  }

  Local local[kMaxInputs];
  Vec xf = Vec::Zero();
  Mat Pf = Mat::Identity();
  Mat F = Mat::Identity(), Q = Mat::Zero();
  double last_T = -1.0;
  int idx[6] = {};
};

// The local filters' estimates arrive in time order (the engine's merge; equal time stamps in
// its delivery order). Each one is fused at its time with the latest estimate of every other
// input (CI: predicted to that time with the transition model), or folded into the fused track
// (information), and the fused estimate is published at that time. The transition model is the
// inputs' (InputInfo::transition) unless the node's parameters give it; the state size follows it.
class TrackFusion final : public Component, public FieldListCodec<FusionRunResult> {
 public:
  // Until set_inputs gives the inputs' model, the node's own (given, or the default CV).
  TrackFusion(Settings s, bool model_given) : s_(std::move(s)), model_given_(model_given) { choose_core(); }

  void set_inputs(const std::vector<InputInfo>& inputs) override {
    inputs_.clear();
    for (const InputInfo& in : inputs) {
      // The same track twice is not two sensors: fusing it with itself counts its information
      // twice (the fused covariance halves with no new data), so it is refused (issue 27).
      if (std::find(inputs_.begin(), inputs_.end(), in.node) != inputs_.end())
        throw ConfigError("filter.track_fusion (node '" + s_.node + "'): input '" + in.node +
                          "' is listed twice; fusing a track with itself counts its information twice (list each "
                          "local filter once)");
      inputs_.push_back(in.node);
    }
    // Every input that names its model must name the same one, and the node predicts with it.
    const InputInfo* first = nullptr;
    for (const InputInfo& in : inputs) {
      if (!in.transition) continue;
      if (!first) {
        first = &in;
        if (!model_given_) static_cast<TransitionModel&>(s_) = *in.transition;
      }
      if (*in.transition != static_cast<const TransitionModel&>(s_))
        throw ConfigError("filter.track_fusion (node '" + s_.node + "'): input '" + in.node + "' (" + in.type +
                          ") predicts with " + in.transition->text() + ", but " +
                          (model_given_ ? std::string("this node's parameters give ")
                                        : "input '" + first->node + "' with ") +
                          s_.text() + "; the fused track must predict as its inputs do" +
                          (model_given_ ? " (leave the motion parameters out to take the inputs' model)" : ""));
    }
    if (!first && !model_given_)
      throw ConfigError("filter.track_fusion (node '" + s_.node + "'): no input names its transition model (" +
                        (inputs.empty() ? std::string("no inputs") : "'" + inputs[0].node + "' is " + inputs[0].type) +
                        "); give the local filters' motion and noise here (motion, q / q_jerk / sigma_accel / singer_*)");
    choose_core();
  }

  void start_run(const RunContext& ctx) override {
    diag_ = ctx.diagnostics;
    run_ = FusionRunResult{};
    std::visit([](auto& core) { core.reset(); }, core_);
    fused_ = false;
    restart_reported_ = false;
  }

  void on_estimate(const Estimate& e, int port) override {
    if (port < 0 || port >= kMaxInputs) return;
    std::visit([&](auto& core) { fuse(core, e, port); }, core_);
  }

  std::unique_ptr<RunResult> end_run() override { return std::make_unique<FusionRunResult>(run_); }
  void merge(RunResult& result) override {
    const auto& r = static_cast<const FusionRunResult&>(result);
    total_.fused += r.fused;
    total_.restarts += r.restarts;
    total_.ci_count += r.ci_count;
    total_.ci_weight_sum += r.ci_weight_sum;
  }
  void finish(Summary& s, const FinishContext&) override {
    s.metric("fused", static_cast<double>(total_.fused));
    s.metric("restarts", static_cast<double>(total_.restarts));
    if (s_.method == Method::CovarianceIntersection && total_.ci_count > 0 && !inputs_.empty())
      s.metric("ci_weight_mean." + inputs_[0], total_.ci_weight_sum / static_cast<double>(total_.ci_count));
  }

 private:
  void choose_core() {
    if (s_.order() == 2)
      core_.emplace<FusionCore<2>>();
    else
      core_.emplace<FusionCore<3>>();
    est_.state.resize(s_.state_dim());
    est_.covariance.resize(s_.state_dim(), s_.state_dim());
  }

  template <class Core>
  void fuse(Core& c, const Estimate& e, int port) {
    constexpr int N = Core::N;
    auto& l = c.local[port];
    if (!e.initialised) {
      if (l.has) restart("input '" + inputs_[port] + "' restarted its track", e.time);
      l.has = false;
      publish(c, e.time, e.updated);
      return;
    }
    check_shape(e, port, N);
    const typename Core::Vec x = e.state.template head<N>();
    const typename Core::Mat P = e.covariance.template topLeftCorner<N, N>();
    if (s_.method == Method::Information)
      fold_in(c, l, x, P, e.time);
    else
      intersect(c, port, x, P, e.time);
    l.has = true;
    l.time = e.time;
    l.x = x;
    l.P = P;
    publish(c, e.time, e.updated);
  }

  void check_shape(const Estimate& e, int port, int n) const {
    if (e.state.size() != n || e.covariance.rows() != n || e.covariance.cols() != n)
      throw DataError("filter.track_fusion (node '" + s_.node + "'): input '" + inputs_[port] + "' publishes a " +
                      std::to_string(e.state.size()) + "-element state; this node's transition model (" + s_.text() +
                      ") has " + std::to_string(n) + " (give it the local filters' motion and noise)");
  }

  // x <- F x, P <- F P F' + Q over T >= 0 (the local filters' model, so a local track's own
  // prediction is reproduced).
  template <class Core>
  void predict(Core& c, typename Core::Vec& x, typename Core::Mat& P, double T) {
    using Model = typename Core::Model;
    constexpr int Order = Model::kOrder;
    if (!(T > 0.0)) return;
    if (T != c.last_T) {
      typename Core::AxisMatrix F, Q;
      if constexpr (Order == 3) {
        if (s_.motion == Motion::Singer) {
          F = SingerModel::axis_transition(s_.singer_alpha, T);
          Q = (2.0 * s_.singer_alpha) * SingerModel::noise_per_psd(s_.singer_alpha, T);
        }
      }
      if (s_.motion != Motion::Singer) {
        F = Model::axis_transition(T);
        Q = s_.noise == Noise::Continuous ? Model::axis_noise_continuous(T, 1.0) : Model::axis_noise_discrete(T, 1.0);
      }
      const double scale = s_.noise == Noise::Continuous ? s_.intensity : s_.intensity * s_.intensity;
      c.F.setZero();
      c.Q.setZero();
      for (int a = 0; a < 3; ++a) {
        c.F.template block<Order, Order>(a * Order, a * Order) = F;
        c.Q.template block<Order, Order>(a * Order, a * Order) = scale * Q;
      }
      c.last_T = T;
    }
    x = c.F * x;
    P = c.F * P * c.F.transpose() + c.Q;
    P = 0.5 * (P + P.transpose());
  }

  // Information matrix fusion: the fused track predicted to t, plus what this local update added.
  template <class Core>
  void fold_in(Core& c, typename Core::Local& l, const typename Core::Vec& x, const typename Core::Mat& P, double t) {
    if (fused_) predict(c, c.xf, c.Pf, t - tf_);
    typename Core::Vec xp = l.x;
    typename Core::Mat Pp = l.P;
    if (l.has) predict(c, xp, Pp, t - l.time);
    typename Core::Vec xf = c.xf;
    typename Core::Mat Pf = c.Pf;
    if (fusion::information_fusion<Core::N>(xf, Pf, fused_, x, P, l.has, xp, Pp)) {
      c.xf = xf;
      c.Pf = Pf;
    } else {
      restart("the fused information was not positive definite", t);
      c.xf = x;
      c.Pf = P;
    }
    fused_ = true;
    tf_ = t;
  }

  // Covariance intersection (or the independent-errors fusion) of this input's estimate with every
  // other input's latest, predicted to t, in input order.
  template <class Core>
  void intersect(Core& c, int port, const typename Core::Vec& x, const typename Core::Mat& P, double t) {
    c.xf = x;
    c.Pf = P;
    for (int j = 0; j < static_cast<int>(inputs_.size()) && j < kMaxInputs; ++j) {
      if (j == port || !c.local[j].has) continue;
      typename Core::Vec xj = c.local[j].x;
      typename Core::Mat Pj = c.local[j].P;
      predict(c, xj, Pj, t - c.local[j].time);
      fusion::CiResult<Core::N> r;
      const bool first_is_j = j < port;  // the first input's weight is the one reported
      bool ok;
      if (s_.method == Method::Independent)
        ok = fusion::independent_fusion<Core::N>(c.xf, c.Pf, xj, Pj, r);
      else
        ok = first_is_j ? fusion::covariance_intersection<Core::N>(xj, Pj, c.xf, c.Pf, s_.criterion, r)
                        : fusion::covariance_intersection<Core::N>(c.xf, c.Pf, xj, Pj, s_.criterion, r);
      if (!ok) continue;  // that input is left out of this step
      if (s_.method == Method::CovarianceIntersection && (j == 0 || port == 0)) {
        run_.ci_weight_sum += r.w;
        ++run_.ci_count;
      }
      c.xf = r.x;
      c.Pf = r.P;
    }
    fused_ = true;
    tf_ = t;
  }

  void restart(const std::string& why, double t) {
    ++run_.restarts;
    if (!restart_reported_ && diag_)
      diag_->warn(s_.node, why + " at t=" + std::to_string(t) +
                               " s; the fused track restarts from the next local estimate (further restarts counted)");
    restart_reported_ = true;
    fused_ = false;
  }

  template <class Core>
  void publish(Core& c, double t, bool updated) {
    est_.time = t;
    est_.updated = updated;
    est_.innovation.resize(0);
    est_.innovation_covariance.resize(0, 0);
    est_.nis = 0.0;
    est_.annotation_count = 0;
    if (!fused_ || !c.xf.allFinite() || !c.Pf.allFinite()) {
      if (fused_) restart("the fused state came out non-finite", t);
      set_uninitialised(est_, t);
      out.emit(est_);
      return;
    }
    est_.initialised = true;
    set_estimate_state(est_, c.xf, c.Pf, c.idx);
    ++run_.fused;
    out.emit(est_);
  }

  Settings s_;
  bool model_given_ = false;
  std::vector<std::string> inputs_;
  Diagnostics* diag_ = nullptr;
  FusionRunResult run_, total_;
  std::variant<FusionCore<2>, FusionCore<3>> core_;
  bool fused_ = false, restart_reported_ = false;
  double tf_ = 0.0;
  Estimate est_;
};

Settings parse(const Params& p) {
  Settings s;
  s.node = p.node();
  s.method = p.choice<Method>("method");
  s.criterion = p.choice<fusion::CiCriterion>("ci_criterion");
  if (s.method != Method::CovarianceIntersection && p.given("ci_criterion"))
    throw p.error("ci_criterion", "is for method: covariance_intersection");
  if (transition_given(p)) static_cast<TransitionModel&>(s) = parse_transition(p);
  return s;
}

std::unique_ptr<Component> create(const Params& p) { return std::make_unique<TrackFusion>(parse(p), transition_given(p)); }

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.track_fusion";
  d.kind = ComponentKind::Filter;
  d.summary = "Track-to-track fusion of two or more filters' estimates: covariance intersection, or information "
              "matrix fusion that counts the common process noise once";
  d.doc =
      "Inputs: two to eight filters with the same Cartesian state (filter.ekf, filter.ukf, ... with the same motion "
      "model), usually one per station. Each local estimate is fused when it arrives (time order; equal time stamps "
      "in the engine's delivery order) and the fused estimate published at its time, so sink.metrics scores it like "
      "any filter. method covariance_intersection (Julier & Uhlmann 1997): P^-1 = w P1^-1 + (1-w) P2^-1 with the "
      "other inputs' latest estimates predicted to that time, w in [0, 1] minimising the trace (ci_criterion: trace) "
      "or the determinant of P; consistent for any unknown correlation of the local errors, at the price of being "
      "conservative. method information: information matrix fusion (Chong, Mori & Chang 1990; exact for fusion after "
      "every local update, Tian & Bar-Shalom 2009): the fused track, predicted with the motion model, adds each local "
      "update's new information Y_i(k|k) - Y_i(k|k-1), the local prediction being formed here from that input's "
      "previous estimate, so the process noise the local tracks share is counted once. method independent: "
      "P^-1 = P1^-1 + P2^-1, the fusion that ignores the cross-covariance (overconfident when the local errors are "
      "correlated, as they are through the common process noise; a baseline). All three predict with the local "
      "filters' transition model, which the node takes from its inputs (every input naming one must name the same); "
      "motion and q / q_jerk / sigma_accel / singer_* given here must agree with it, and are needed only when no "
      "input names its model. The summary gives fused estimates, fused-track restarts and, for CI, the mean weight of the first "
      "input. See docs/filters.md, Track-to-track fusion.";
  d.accepts = mask(ItemKind::Estimate);
  d.min_inputs = 2;
  d.max_inputs = kMaxInputs;
  d.produces = mask(ItemKind::Estimate);
  d.params = {
      ParamSpec::choice<Method>("method",
                                {{Method::CovarianceIntersection, "covariance_intersection"},
                                 {Method::Information, "information"},
                                 {Method::Independent, "independent"}},
                                "covariance intersection (any correlation), information matrix fusion (removes the "
                                "common prior; needs each local estimate), or independent: as if the local errors "
                                "were uncorrelated (overconfident when they are not; for comparison)")
          .def("covariance_intersection"),
      ParamSpec::choice<fusion::CiCriterion>("ci_criterion",
                                             {{fusion::CiCriterion::Trace, "trace"},
                                              {fusion::CiCriterion::Determinant, "determinant"}},
                                             "covariance intersection: the weight minimises the fused covariance's "
                                             "trace or its determinant")
          .def("trace"),
  };
  // The local filters' motion and noise, declared as theirs (the same words in the same units):
  // left out, the node takes its inputs' model (InputInfo::transition).
  for (ParamSpec& spec : transition_param_specs()) d.params.push_back(std::move(spec));
  d.create = create;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.track_fusion", trackflow::register_components)
