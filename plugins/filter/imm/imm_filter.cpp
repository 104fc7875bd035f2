// Purpose: filter.imm — interacting multiple model filter: 2-4 Cartesian radar EKF modes (CV, CA, Singer, each with its own noise) mixed on the common Cartesian state, mode probabilities published as annotations.
#include "estimation/cartesian_radar_state.hpp"
#include "estimation/ekf_radar_update.hpp"
#include "imm_mixing.hpp"

#include <trackflow/common_params.hpp>
#include <trackflow/single_track_filter.hpp>
#include <trackflow/plugin.hpp>

#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace trackflow {
namespace {

using cartesian_filter::CartesianRadarState;
using cartesian_filter::Settings;
using imm::kMaxModes;

// One mode: a Cartesian radar state of order 2 (CV) or 3 (CA, Singer); the other one is unused.
struct Mode {
  std::string name;
  int order = 2;
  CartesianRadarState<2> cv;
  CartesianRadarState<3> ca;
};

template <class S>
constexpr int order_of = std::decay_t<S>::Layout::kOrder;

template <class F>
void visit(Mode& m, F&& f) {
  if (m.order == 2)
    f(m.cv);
  else
    f(m.ca);
}
template <class F>
void visit(const Mode& m, F&& f) {
  if (m.order == 2)
    f(m.cv);
  else
    f(m.ca);
}

struct ImmConfig {
  std::string node;
  RangeRateUse range_rate = RangeRateUse::Auto;
  std::vector<Mode> modes;
  std::vector<double> transition, initial;
};

// Blom & Bar-Shalom (1988) IMM, one cycle per measurement: mixing (predict), mode-matched EKF
// updates, mode probabilities from the innovation likelihoods, and the combined estimate
// (fill_estimate). The equations and the treatment of unequal state sizes: docs/filters.md.
class ImmEstimator final : public Estimator {

 public:
  explicit ImmEstimator(const ImmConfig& c)
      : Estimator(MeasurementSpec{Frame::Spherical, c.range_rate,
                                    {"azimuth_dropped", "mode_updates_refused"}, true}),
        count_(static_cast<int>(c.modes.size())) {
    for (int j = 0; j < count_; ++j) {
      modes_[j] = c.modes[static_cast<size_t>(j)];
      mu0_[j] = c.initial[static_cast<size_t>(j)];
      any_acceleration_ = any_acceleration_ || modes_[j].order == 3;
      all_acceleration_ = all_acceleration_ && modes_[j].order == 3;
      for (int i = 0; i < count_; ++i) pi_[j * count_ + i] = c.transition[static_cast<size_t>(j * count_ + i)];
    }
  }

  NoiseHandles noise() override {
    NoiseHandles h;  // R only: each mode keeps its own process noise
    h.measurement = {&R_, MeasurementSpace::Spherical};
    return h;
  }
  StateLayout layout() const override {
    return any_acceleration_ ? ConstantAcceleration::state_layout() : ConstantVelocity::state_layout();
  }
  std::vector<std::string> annotation_names() const override {
    std::vector<std::string> names;
    for (int j = 0; j < count_; ++j) names.push_back("p_" + modes_[j].name);
    return names;
  }

 private:
  enum Counter { kAzimuthDropped, kModeRefused };

  bool reset() override {
    bool initialised = false;
    for (int j = 0; j < count_; ++j) visit(modes_[j], [&](auto& s) { initialised = s.reset_state(); });
    std::copy(mu0_, mu0_ + count_, mu_);
    mixed_ = false;
    publish_probabilities();
    return initialised;
  }

  // Every mode starts from the same two converted points (init: two_point).
  bool initiate(const Measurement& m, int) override {
    bool formed = false;
    for (int j = 0; j < count_; ++j) visit(modes_[j], [&](auto& s) { formed = s.add_point(m, R_); });
    publish_probabilities();
    return formed;
  }

  // Interaction (mixing) on the common state, then each mode's own exact prediction. All mixed
  // starts are formed before any mode is overwritten.
  void predict(double T) override {
    imm::mixing_weights(pi_, mu_, count_, c_, w_);
    const imm::ModeView& v = view();
    for (int j = 0; j < count_; ++j) {
      // A receiver with acceleration lends its own to the modes without (imm_mixing.hpp); a CV
      // receiver keeps only the position and velocity of the mixture.
      imm::mix(v, w_[j], *v.x[j], *v.P[j], x0s_[j], P0s_[j]);
    }
    for (int j = 0; j < count_; ++j)
      visit(modes_[j], [&](auto& s) {
        imm::from_common<order_of<decltype(s)>>(x0s_[j], P0s_[j], s.x_, s.P_);
        s.predict_state(T, same_interval(T, s.last_interval()));
      });
    mixed_ = true;
  }

  // The modes on the common state: a 9-state mode as it is, a CV mode through a copy.
  const imm::ModeView& view() const {
    view_.count = count_;
    for (int i = 0; i < count_; ++i) {
      if (modes_[i].order == 3) {
        view_.x[i] = &modes_[i].ca.x_;
        view_.P[i] = &modes_[i].ca.P_;
      } else {
        imm::to_common<2>(modes_[i].cv.x_, modes_[i].cv.P_, common_[i]);
        view_.x[i] = &common_[i].x;
        view_.P[i] = &common_[i].P;
      }
      view_.has_acceleration[i] = modes_[i].order == 3;
    }
    return view_;
  }

  bool update(const Measurement& m, int dim) override {
    return dim == 4 ? update_values<4>(m) : update_values<3>(m);
  }
  bool predict_measurement(const SensorFrame& s, const MeasCov& R, PredictedMeasurement& p) const override {
    return predicted_by_update<ImmEstimator>(s, R, p);
  }
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<ImmEstimator>(*this); }

  template <int M>
  bool update_values(const Measurement& m) {
    if (!mixed_) std::copy(mu_, mu_ + count_, c_);  // no time elapsed: no transition
    mixed_ = false;
    const Eigen::Matrix<double, M, M> R = R_.template topLeftCorner<M, M>();
    double ll[kMaxModes];
    bool used[kMaxModes];
    bool any = false, dropped = false;
    double worst = std::numeric_limits<double>::infinity();
    for (int j = 0; j < count_; ++j) {
      cartesian_filter::EkfOutcome outcome{};
      visit(modes_[j], [&](auto& s) {
        outcome = cartesian_filter::ekf_radar_update<3 * order_of<decltype(s)>, M>(s.x_, s.P_, s.idx_, m, R, uses_curvature(s), innovation<M>(j));
      });
      used[j] = outcome == cartesian_filter::EkfOutcome::Used;
      dropped = dropped || innovation<M>(j).azimuth_dropped;
      ll[j] = used[j] ? imm::log_likelihood(M, innovation<M>(j).nis, innovation<M>(j).det_S)
                      : -std::numeric_limits<double>::infinity();
      if (!used[j]) count(kModeRefused);
      if (used[j] && std::isfinite(ll[j])) {
        any = true;
        worst = std::min(worst, ll[j]);
      }
    }
    if (dropped) count(kAzimuthDropped);
    if (!any) {
      std::copy(c_, c_ + count_, mu_);
      publish_probabilities();
      warn("no mode could use the measurement at t=" + std::to_string(m.time) +
           " s (predicted position at the sensor, or S not positive definite); measurement not used");
      return false;
    }
    // A mode that could not update is neither favoured nor dropped: it gets the worst likelihood.
    for (int j = 0; j < count_; ++j)
      if (!used[j] || !std::isfinite(ll[j])) ll[j] = worst;
    imm::update_probabilities(c_, ll, count_, mu_);
    publish_probabilities();
    publish_innovation<M>(used);
    return true;
  }

  // The measurement-prediction mixture: z^ = sum c_j z^_j, so nu = sum c_j nu_j and
  // S = sum c_j (S_j + (nu_j - nu)(nu_j - nu)'), over the modes that updated (weights renormalised).
  template <int M>
  void publish_innovation(const bool* used) {
    using VecM = Eigen::Matrix<double, M, 1>;
    using MatM = Eigen::Matrix<double, M, M>;
    double total = 0.0;
    for (int j = 0; j < count_; ++j)
      if (used[j]) total += c_[j];
    VecM nu = VecM::Zero();
    MatM S = MatM::Zero();
    for (int j = 0; j < count_; ++j)
      if (used[j] && total > 0.0) nu += (c_[j] / total) * innovation<M>(j).nu;
    for (int j = 0; j < count_; ++j)
      if (used[j] && total > 0.0) {
        const VecM d = innovation<M>(j).nu - nu;
        S += (c_[j] / total) * (innovation<M>(j).S + d * d.transpose());
      }
    double nis = 0.0;
    if (!imm::quadratic_form<M>(S, nu, nis)) nis = 0.0;  // a mixture of PD matrices is PD: not reached
    accept_update<M>(nu, S, nis);
  }

  void publish_probabilities() {
    for (int j = 0; j < count_; ++j) annotate(j, mu_[j]);
  }

  // The combined estimate, moment-matched on the common state. The acceleration of a mode
  // without one is the probability-weighted acceleration of the modes that carry it.
  void fill(Estimate& e) const override {
    const imm::ModeView& v = view();
    // Every mode mixed into the reference has its own acceleration, so the reference passed to
    // that mixture is never read.
    imm::VecC ref_x = imm::VecC::Zero();
    imm::MatC ref_P = imm::MatC::Zero();
    if (any_acceleration_ && !all_acceleration_) {
      double wa[kMaxModes] = {}, total = 0.0;
      for (int i = 0; i < count_; ++i)
        if (modes_[i].order == 3) total += mu_[i];
      for (int i = 0; i < count_; ++i)
        if (modes_[i].order == 3) wa[i] = total > 0.0 ? mu_[i] / total : 1.0;
      double sum = 0.0;
      for (int i = 0; i < count_; ++i) sum += wa[i];
      for (int i = 0; i < count_; ++i) wa[i] /= sum;
      imm::mix(v, wa, ref_x, ref_P, x0_, P0_);
      ref_x = x0_;
      ref_P = P0_;
    }
    imm::mix(v, mu_, ref_x, ref_P, x0_, P0_);
    const int n = any_acceleration_ ? 9 : 6;
    e.state.resize(n);
    e.covariance.resize(n, n);
    int idx[6];
    if (any_acceleration_) {
      e.state.head<9>() = x0_;
      e.covariance.topLeftCorner<9, 9>() = P0_;
      for (int a = 0; a < 3; ++a) {
        idx[a] = 3 * a;
        idx[a + 3] = 3 * a + 1;
      }
    } else {
      for (int i = 0; i < 6; ++i) {
        e.state(i) = x0_(imm::common_index<2>(i));
        for (int k = 0; k < 6; ++k) e.covariance(i, k) = P0_(imm::common_index<2>(i), imm::common_index<2>(k));
      }
      for (int a = 0; a < 3; ++a) {
        idx[a] = 2 * a;
        idx[a + 3] = 2 * a + 1;
      }
    }
    for (int i = 0; i < 6; ++i) {
      e.enu(i) = e.state(idx[i]);
      for (int k = 0; k < 6; ++k) e.enu_covariance(i, k) = e.covariance(idx[i], idx[k]);
    }
  }

  void scale_covariance(double k) override {
    for (int j = 0; j < count_; ++j) visit(modes_[j], [&](auto& s) { s.P_ *= k; });
  }

  template <class State>
  static bool uses_curvature(const State& s) {
    return s.settings().zenith == Settings::Zenith::Curvature;
  }

  template <int M>
  cartesian_filter::EkfInnovation<M>& innovation(int j) {
    if constexpr (M == 3)
      return in3_[j];
    else
      return in4_[j];
  }

  int count_ = 0;
  std::array<Mode, kMaxModes> modes_;
  bool any_acceleration_ = false, all_acceleration_ = true, mixed_ = false;
  double pi_[kMaxModes * kMaxModes] = {};  // row i: from mode i
  double mu0_[kMaxModes] = {}, mu_[kMaxModes] = {}, c_[kMaxModes] = {};
  double w_[kMaxModes][kMaxModes] = {};  // w_[j][i]: weight of mode i in mode j's mixed start
  cartesian_filter::EkfInnovation<3> in3_[kMaxModes];
  cartesian_filter::EkfInnovation<4> in4_[kMaxModes];
  // Scratch (fill_estimate is const: what it forms is no state of the filter).
  mutable imm::CommonEstimate common_[kMaxModes];  // CV modes on the common state
  mutable imm::ModeView view_;
  imm::VecC x0s_[kMaxModes];  // mixed starts
  imm::MatC P0s_[kMaxModes];
  mutable imm::VecC x0_ = imm::VecC::Zero();
  mutable imm::MatC P0_ = imm::MatC::Zero();
};

std::vector<ParamSpec> mode_fields() {
  std::vector<ParamSpec> f = {ParamSpec::string("name", "mode name in the annotations (p_<name>); default cv, ca or singer")};
  for (ParamSpec& s : cartesian_filter::motion_param_specs()) f.push_back(std::move(s));
  f.push_back(cartesian_filter::initial_sigma_acceleration_param());
  return f;
}

const char* default_name(Settings::Motion m) {
  switch (m) {
    case Settings::Motion::ConstantVelocity: return "cv";
    case Settings::Motion::ConstantAcceleration: return "ca";
    case Settings::Motion::Singer: return "singer";
  }
  return "mode";
}

// The estimator of one track from the node's parameters (the node and a tracker take it alike).
ImmEstimator make_estimator(const Params& p) {
  ImmConfig c;
  c.node = p.node();
  c.range_rate = p.choice<RangeRateUse>("range_rate");
  const auto zenith = p.choice<Settings::Zenith>("zenith");
  const std::vector<Params>& records = p.records("modes");
  if (records.size() < 2 || records.size() > static_cast<size_t>(kMaxModes))
    throw p.error("modes", "an IMM takes 2 to " + std::to_string(kMaxModes) + " modes (got " +
                               std::to_string(records.size()) + ")");
  for (const Params& r : records) {
    Settings s;
    s.type = "filter.imm";
    s.node = c.node;
    cartesian_filter::parse_motion(r, s);
    s.range_rate = c.range_rate;
    s.zenith = zenith;
    s.init = Settings::Init::TwoPoint;
    if (s.motion == Settings::Motion::ConstantVelocity && r.given("initial_sigma_acceleration"))
      throw r.error("initial_sigma_acceleration", "the constant_velocity state has no acceleration");
    s.sa0 = r.real_or("initial_sigma_acceleration", s.motion == Settings::Motion::Singer ? s.intensity : 50.0);
    Mode m;
    m.name = r.has("name") ? r.text("name") : default_name(s.motion);
    for (const Mode& other : c.modes)
      if (other.name == m.name)
        throw r.error(r.has("name") ? "name" : "motion",
                      "two modes named '" + m.name + "': give each a distinct name: (it names the annotation p_" +
                          m.name + ")");
    m.order = s.order();
    if (m.order == 2)
      m.cv = CartesianRadarState<2>(s);
    else
      m.ca = CartesianRadarState<3>(s);
    c.modes.push_back(std::move(m));
  }
  const int n = static_cast<int>(c.modes.size());
  c.transition = p.reals("transition");
  if (std::string why = imm::check_transition(c.transition, n); !why.empty()) throw p.error("transition", why);
  if (p.has("initial_probabilities")) {
    c.initial = p.reals("initial_probabilities");
    double sum = 0.0;
    for (double v : c.initial) sum += v;
    if (static_cast<int>(c.initial.size()) != n || std::fabs(sum - 1.0) > 1e-9)
      throw p.error("initial_probabilities", "give one probability per mode (" + std::to_string(n) +
                                                 "), summing to 1 (they sum to " + std::to_string(sum) + ")");
    for (double v : c.initial)
      if (!(v >= 0.0)) throw p.error("initial_probabilities", "probabilities cannot be negative");
  } else {
    c.initial.assign(static_cast<size_t>(n), 1.0 / n);
  }
  return ImmEstimator(c);
}

std::unique_ptr<Component> create(const Params& p) {
  return make_single_track_filter("filter.imm", p.node(), make_estimator(p));
}

std::unique_ptr<Estimator> create_estimator(const Params& p) { return std::make_unique<ImmEstimator>(make_estimator(p)); }

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.imm";
  d.kind = ComponentKind::Filter;
  d.summary = "Interacting multiple model filter: 2-4 Cartesian EKF modes (CV, CA, Singer) on spherical [r, az, el(, "
              "rdot)] measurements, mode probabilities as annotations";
  d.doc =
      "Blom & Bar-Shalom (1988) IMM. Each mode is filter.ekf's Cartesian ENU EKF with its own motion model and "
      "noise (modes: a list of records with filter.ekf's motion parameters). Per measurement: mixing of the mode "
      "estimates with the Markov transition matrix (transition: row-major, row i = the probabilities of going from "
      "mode i to each mode; rows sum to 1) on the common state [x vx ax y vy ay z vz az]; a mode without "
      "acceleration (CV) borrows the receiving mode's acceleration, uncorrelated (unbiased mixing, Granstrom, "
      "Willett & Bar-Shalom 2015); each mode's exact prediction and EKF update; mode probabilities from the "
      "Gaussian innovation likelihoods in the log domain; the published estimate is the moment-matched mixture (9 "
      "states if any mode has acceleration). Annotations <id>.p_<mode name>: the mode probabilities after each "
      "update. Initialised by two-point differencing (all modes alike). Adapters may replace R (not the modes' "
      "process noise). See docs/filters.md.";
  d.accepts = mask(ItemKind::Measurement);
  d.produces = mask(ItemKind::Estimate);
  d.accepts_frames = mask(Frame::Spherical);
  d.params = {
      ParamSpec::records("modes", mode_fields(), "the mode filters (2 to 4): motion model and its noise each").req(),
      ParamSpec::real_list("transition", dim::none,
                           "Markov transition matrix, row-major (modes x modes): row i = P(next mode | mode i), rows "
                           "sum to 1")
          .req(),
      ParamSpec::real_list("initial_probabilities", dim::none, "mode probabilities at the start (default: uniform)"),
      range_rate_param(),
      cartesian_filter::zenith_param(),
  };
  d.create = create;
  d.create_estimator = create_estimator;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.imm", trackflow::register_components)
