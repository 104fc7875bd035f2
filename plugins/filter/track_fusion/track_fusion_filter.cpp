// Purpose: filter.track_fusion — track-to-track fusion of two or more filters' estimates (covariance intersection, or information matrix fusion that counts the common process noise once).
#include "fusion_math.hpp"

#include "estimation/cartesian_filter_settings.hpp"

#include <trackflow/error.hpp>
#include <trackflow/estimate_state.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace trackflow {
namespace {

enum class Method { CovarianceIntersection, Information, Independent };
using Motion = cartesian_filter::MotionModel::Motion;
using Noise = cartesian_filter::MotionModel::Noise;

// The inputs' motion model (the Cartesian filters' parameter block), the fusion method.
struct Settings : cartesian_filter::MotionModel {
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

// The local filters' estimates arrive in time order (the engine's merge; equal time stamps in
// its delivery order). Each one is fused at its time with the latest estimate of every other
// input (CI: predicted to that time with the motion model), or folded into the fused track
// (information), and the fused estimate is published at that time.
template <int Order>
class TrackFusion final : public Component, public FieldListCodec<FusionRunResult> {
  using Model = KinematicModel<Order>;
  static constexpr int N = Model::kDim;
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = Eigen::Matrix<double, N, N>;
  using AxisMatrix = typename Model::AxisMatrix;

 public:
  explicit TrackFusion(Settings s) : s_(std::move(s)) {
    idx_[0] = Model::position_index(0), idx_[1] = Model::position_index(1), idx_[2] = Model::position_index(2);
    idx_[3] = Model::velocity_index(0), idx_[4] = Model::velocity_index(1), idx_[5] = Model::velocity_index(2);
    est_.state.resize(N);
    est_.covariance.resize(N, N);
  }

  void set_inputs(const std::vector<InputInfo>& inputs) override {
    inputs_.clear();
    for (const InputInfo& in : inputs) inputs_.push_back(in.node);
  }

  void start_run(const RunContext& ctx) override {
    diag_ = ctx.diagnostics;
    run_ = FusionRunResult{};
    for (Local& l : local_) l = Local{};
    fused_ = false;
    restart_reported_ = false;
  }

  void on_estimate(const Estimate& e, int port) override {
    if (port < 0 || port >= kMaxInputs) return;
    Local& l = local_[port];
    if (!e.initialised) {
      if (l.has) restart("input '" + inputs_[port] + "' restarted its track", e.time);
      l.has = false;
      publish(e.time, e.updated);
      return;
    }
    check_shape(e, port);
    const Vec x = e.state.template head<N>();
    const Mat P = e.covariance.template topLeftCorner<N, N>();
    if (s_.method == Method::Information)
      fold_in(l, x, P, e.time);
    else
      intersect(port, x, P, e.time);
    l.has = true;
    l.time = e.time;
    l.x = x;
    l.P = P;
    publish(e.time, e.updated);
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
  struct Local {
    bool has = false;
    double time = 0.0;
    Vec x = Vec::Zero();
    Mat P = Mat::Identity();
  };

  void check_shape(const Estimate& e, int port) const {
    if (e.state.size() != N || e.covariance.rows() != N || e.covariance.cols() != N)
      throw DataError("filter.track_fusion (node '" + s_.node + "'): input '" + inputs_[port] + "' publishes a " +
                      std::to_string(e.state.size()) + "-element state; this node's motion model has " +
                      std::to_string(N) + " (give it the local filters' motion and noise)");
  }

  // x <- F x, P <- F P F' + Q over T >= 0 (the local filters' model, so a local track's own
  // prediction is reproduced).
  void predict(Vec& x, Mat& P, double T) {
    if (!(T > 0.0)) return;
    if (T != last_T_) {
      AxisMatrix F, Q;
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
      F_.setZero();
      Q_.setZero();
      for (int a = 0; a < 3; ++a) {
        F_.template block<Order, Order>(a * Order, a * Order) = F;
        Q_.template block<Order, Order>(a * Order, a * Order) = scale * Q;
      }
      last_T_ = T;
    }
    x = F_ * x;
    P = F_ * P * F_.transpose() + Q_;
    P = 0.5 * (P + P.transpose());
  }

  // Information matrix fusion: the fused track predicted to t, plus what this local update added.
  void fold_in(Local& l, const Vec& x, const Mat& P, double t) {
    if (fused_) predict(xf_, Pf_, t - tf_);
    Vec xp = l.x;
    Mat Pp = l.P;
    if (l.has) predict(xp, Pp, t - l.time);
    Vec xf = xf_;
    Mat Pf = Pf_;
    if (fusion::information_fusion<N>(xf, Pf, fused_, x, P, l.has, xp, Pp)) {
      xf_ = xf;
      Pf_ = Pf;
    } else {
      restart("the fused information was not positive definite", t);
      xf_ = x;
      Pf_ = P;
    }
    fused_ = true;
    tf_ = t;
  }

  // Covariance intersection (or the independent-errors fusion) of this input's estimate with every
  // other input's latest, predicted to t, in input order.
  void intersect(int port, const Vec& x, const Mat& P, double t) {
    xf_ = x;
    Pf_ = P;
    for (int j = 0; j < static_cast<int>(inputs_.size()) && j < kMaxInputs; ++j) {
      if (j == port || !local_[j].has) continue;
      Vec xj = local_[j].x;
      Mat Pj = local_[j].P;
      predict(xj, Pj, t - local_[j].time);
      fusion::CiResult<N> r;
      const bool first_is_j = j < port;  // the first input's weight is the one reported
      bool ok;
      if (s_.method == Method::Independent)
        ok = fusion::independent_fusion<N>(xf_, Pf_, xj, Pj, r);
      else
        ok = first_is_j ? fusion::covariance_intersection<N>(xj, Pj, xf_, Pf_, s_.criterion, r)
                        : fusion::covariance_intersection<N>(xf_, Pf_, xj, Pj, s_.criterion, r);
      if (!ok) continue;  // that input is left out of this step
      if (s_.method == Method::CovarianceIntersection && (j == 0 || port == 0)) {
        run_.ci_weight_sum += r.w;
        ++run_.ci_count;
      }
      xf_ = r.x;
      Pf_ = r.P;
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

  void publish(double t, bool updated) {
    est_.time = t;
    est_.updated = updated;
    est_.innovation.resize(0);
    est_.innovation_covariance.resize(0, 0);
    est_.nis = 0.0;
    est_.annotation_count = 0;
    if (!fused_ || !xf_.allFinite() || !Pf_.allFinite()) {
      if (fused_) restart("the fused state came out non-finite", t);
      set_uninitialised(est_, t);
      out.emit(est_);
      return;
    }
    est_.initialised = true;
    set_estimate_state(est_, xf_, Pf_, idx_);
    ++run_.fused;
    out.emit(est_);
  }

  Settings s_;
  std::vector<std::string> inputs_;
  Diagnostics* diag_ = nullptr;
  FusionRunResult run_, total_;
  Local local_[kMaxInputs];
  bool fused_ = false, restart_reported_ = false;
  double tf_ = 0.0, last_T_ = -1.0;
  Vec xf_ = Vec::Zero();
  Mat Pf_ = Mat::Identity();
  Mat F_ = Mat::Identity(), Q_ = Mat::Zero();
  int idx_[6] = {};
  Estimate est_;
};

Settings parse(const Params& p) {
  Settings s;
  s.node = p.node();
  s.method = p.choice<Method>("method");
  s.criterion = p.choice<fusion::CiCriterion>("ci_criterion");
  if (s.method != Method::CovarianceIntersection && p.given("ci_criterion"))
    throw p.error("ci_criterion", "is for method: covariance_intersection");
  cartesian_filter::parse_motion(p, s);
  return s;
}

std::unique_ptr<Component> create(const Params& p) {
  const Settings s = parse(p);
  if (s.order() == 2) return std::make_unique<TrackFusion<2>>(s);
  return std::make_unique<TrackFusion<3>>(s);
}

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
      "correlated, as they are through the common process noise; a baseline). All three need the local filters' "
      "motion and noise: give the same motion and q / q_jerk / sigma_accel / singer_* here (the state sizes are "
      "checked). The summary gives fused estimates, fused-track restarts and, for CI, the mean weight of the first "
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
  // The local filters' motion and noise, declared as theirs (the same words in the same units).
  for (ParamSpec& spec : cartesian_filter::motion_param_specs()) d.params.push_back(std::move(spec));
  d.create = create;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.track_fusion", trackflow::register_components)
