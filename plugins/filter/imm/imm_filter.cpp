// Purpose: filter.imm — interacting multiple model filter: 2-4 Cartesian radar EKF modes (CV, CA, Singer, each with its own noise) mixed on the common Cartesian state, mode probabilities published as annotations; the IMM-PDA combined update under probabilistic association (imm_pda.hpp).
#include "estimation/cartesian_radar_state.hpp"
#include "estimation/ekf_radar_update.hpp"
#include "imm_mixing.hpp"
#include "imm_pda.hpp"
#include "memory/grow.hpp"

#include <trackflow/common_params.hpp>
#include <trackflow/names.hpp>
#include <trackflow/single_track_filter.hpp>
#include <trackflow/plugin.hpp>

#include <array>
#include <cmath>
#include <limits>
#include <span>
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

// Both forms: the noise adapters may replace (R only: each mode keeps its own process noise), the
// published state (imm::publish), the annotations (the mode probabilities).
NoiseHandles imm_noise(MeasCov& R) {
  NoiseHandles h;
  h.measurement = {&R, MeasurementSpace::Spherical};
  return h;
}
StateLayout imm_layout(bool any_acceleration) {
  return any_acceleration ? ConstantAcceleration::state_layout() : ConstantVelocity::state_layout();
}
template <class Name>
std::vector<std::string> probability_names(int count, Name name) {
  std::vector<std::string> names;
  for (int j = 0; j < count; ++j) names.push_back("p_" + name(j));
  return names;
}

// Blom & Bar-Shalom (1988) IMM, one cycle per measurement: mixing (predict), mode-matched EKF
// updates, mode probabilities from the innovation likelihoods, and the combined estimate
// (fill_estimate). The equations and the treatment of unequal state sizes: docs/filters.md.
class ImmEstimator final : public Estimator {

 public:
  explicit ImmEstimator(const ImmConfig& c)
      : Estimator(MeasurementSpec{mask(Frame::Spherical), c.range_rate,
                                    {"azimuth_dropped", "mode_updates_refused"}, true}),
        count_(static_cast<int>(c.modes.size())) {
    for (int j = 0; j < count_; ++j) {
      modes_[j] = c.modes[static_cast<size_t>(j)];
      mu0_[j] = c.initial[static_cast<size_t>(j)];
      any_acceleration_ = any_acceleration_ || modes_[j].order == 3;
      for (int i = 0; i < count_; ++i) pi_[j * count_ + i] = c.transition[static_cast<size_t>(j * count_ + i)];
    }
  }

  NoiseHandles noise() override { return imm_noise(R_); }
  StateLayout layout() const override { return imm_layout(any_acceleration_); }
  std::vector<std::string> annotation_names() const override {
    return probability_names(count_, [&](int j) { return modes_[j].name; });
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
    // The prediction's mode probabilities are the Markov chain's c_j = sum_i pi_ij mu_i (Blom &
    // Bar-Shalom 1988): through a coast (no update) they move towards the chain's stationary
    // distribution, the next mixing starts from them, and the published estimate combines the
    // predicted modes with them rather than with the last posterior (issue 25).
    std::copy(c_, c_ + count_, mu_);
    publish_probabilities();
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
    bool dropped = false;
    for (int j = 0; j < count_; ++j) {
      cartesian_filter::EkfOutcome outcome{};
      visit(modes_[j], [&](auto& s) {
        outcome = cartesian_filter::ekf_radar_update<3 * order_of<decltype(s)>, M>(
            s.x_, s.P_, s.idx_, m, R, uses_curvature(s), innovation<M>(j), /*iterate=*/false);
      });
      used[j] = outcome == cartesian_filter::EkfOutcome::Used;
      dropped = dropped || innovation<M>(j).azimuth_dropped;
      ll[j] = used[j] ? imm::log_likelihood(M, innovation<M>(j).nis, innovation<M>(j).det_S)
                      : -std::numeric_limits<double>::infinity();
      if (!used[j]) count(kModeRefused);
    }
    if (dropped) count(kAzimuthDropped);
    if (!imm::floor_likelihoods(ll, used, count_)) {
      for (int j = 0; j < count_; ++j) mu_[j] = c_[j];
      publish_probabilities();
      warn("no mode could use the measurement at t=" + std::to_string(m.time) +
           " s (predicted position at the sensor, or S not positive definite); measurement not used");
      return false;
    }
    imm::update_probabilities(c_, ll, count_, mu_);
    publish_probabilities();
    publish_innovation<M>(used);
    return true;
  }

  // IMM-PDA (imm_pda.hpp): the mode-matched EKF update with each candidate from each mode's
  // prediction, mixed per mode by moments with the weights w_jk, w_j0 and the new mu_j.
  bool takes_weighted_updates() const override { return true; }
  bool update_weighted(std::span<const Measurement> detections, std::span<const double> probability, double none,
                       int dim) override {
    return dim == 4 ? weighted_values<4>(detections, probability, none) : weighted_values<3>(detections, probability, none);
  }

  template <int M>
  bool weighted_values(std::span<const Measurement> detections, std::span<const double> probability, double none) {
    if (!mixed_) std::copy(mu_, mu_ + count_, c_);  // no time elapsed: no transition
    imm::WeightedSums sums(count_);
    imm::VecC dx[kMaxModes];  // candidate k's update of mode j, as a deviation from its prediction
    imm::MatC Pk[kMaxModes];
    double ll[kMaxModes];
    bool used[kMaxModes];
    bool dropped = false;
    Eigen::Matrix<double, M, 1> nu_bar = Eigen::Matrix<double, M, 1>::Zero();
    Eigen::Matrix<double, M, M> S_published = Eigen::Matrix<double, M, M>::Zero();
    bool have_S = false;
    for (std::size_t k = 0; k < detections.size() && k < probability.size(); ++k) {
      const double b = probability[k];
      if (!(b > 0.0)) continue;
      const Measurement& m = detections[k];
      const Eigen::Matrix<double, M, M> R = m.covariance.template topLeftCorner<M, M>();
      for (int j = 0; j < count_; ++j) {
        cartesian_filter::EkfOutcome outcome{};
        visit(modes_[j], [&](auto& s) {
          constexpr int N = 3 * order_of<decltype(s)>;
          Eigen::Matrix<double, N, 1> x = s.x_;
          Eigen::Matrix<double, N, N> P = s.P_;
          outcome = cartesian_filter::ekf_radar_update<N, M>(x, P, s.idx_, m, R, uses_curvature(s), innovation<M>(j),
                                                             /*iterate=*/false);
          if (outcome == cartesian_filter::EkfOutcome::Used) {
            dx[j].template head<N>() = x - s.x_;
            Pk[j].template topLeftCorner<N, N>() = P;
          } else {  // this mode keeps its prediction for this candidate, as update() does
            dx[j].template head<N>().setZero();
            Pk[j].template topLeftCorner<N, N>() = s.P_;
          }
        });
        used[j] = outcome == cartesian_filter::EkfOutcome::Used;
        dropped = dropped || innovation<M>(j).azimuth_dropped;
        ll[j] = used[j] ? imm::log_likelihood(M, innovation<M>(j).nis, innovation<M>(j).det_S)
                        : -std::numeric_limits<double>::infinity();
        if (!used[j]) count(kModeRefused);
      }
      double q[kMaxModes];
      if (!imm::candidate_mode_weights(c_, ll, used, count_, q)) continue;  // no mode could use it: dropped
      for (int j = 0; j < count_; ++j)
        visit(modes_[j], [&](auto& s) {
          constexpr int N = 3 * order_of<decltype(s)>;
          sums.add<N>(j, b * q[j], dx[j], Pk[j]);
        });
      sums.used += b;
      Eigen::Matrix<double, M, 1> nu;
      Eigen::Matrix<double, M, M> S;
      innovation_of<M>(used, nu, S);
      nu_bar += b * nu;
      if (!have_S) S_published = S;
      have_S = true;
    }
    if (dropped) count(kAzimuthDropped);
    if (!(sums.used > 0.0)) {
      warn("no mode could use any candidate detection at t=" + std::to_string(time()) +
           " s (predicted position at the sensor, or S not positive definite); none used");
      return false;  // nothing changed: the prediction, mode probabilities as before
    }
    const double total = none + sums.used;
    for (int j = 0; j < count_; ++j) {
      const double a = none * c_[j] + sums.W[j];  // total * mu_j
      if (a > 0.0)
        visit(modes_[j], [&](auto& s) {
          constexpr int N = 3 * order_of<decltype(s)>;
          imm::moment_step<N>(none * c_[j], sums, j, s.x_, s.P_);
        });
      mu_[j] = a / total;
    }
    imm::normalise(mu_, count_);
    mixed_ = false;
    publish_probabilities();
    nu_bar /= total;
    double nis = 0.0;
    if (!imm::quadratic_form<M>(S_published, nu_bar, nis)) nis = 0.0;
    accept_update<M>(nu_bar, S_published, nis);
    return true;
  }

  // The measurement-prediction mixture of the last candidate's mode innovations.
  template <int M>
  void innovation_of(const bool* used, Eigen::Matrix<double, M, 1>& nu, Eigen::Matrix<double, M, M>& S) {
    const Eigen::Matrix<double, M, 1>* nu_j[kMaxModes];
    const Eigen::Matrix<double, M, M>* S_j[kMaxModes];
    for (int j = 0; j < count_; ++j) {
      nu_j[j] = &innovation<M>(j).nu;
      S_j[j] = &innovation<M>(j).S;
    }
    imm::innovation_mixture<M>(c_, used, count_, nu_j, S_j, nu, S);
  }

  // The measurement-prediction mixture (imm::innovation_mixture) as the accepted innovation.
  template <int M>
  void publish_innovation(const bool* used) {
    const Eigen::Matrix<double, M, 1>* nu_j[kMaxModes];
    const Eigen::Matrix<double, M, M>* S_j[kMaxModes];
    for (int j = 0; j < count_; ++j) {
      nu_j[j] = &innovation<M>(j).nu;
      S_j[j] = &innovation<M>(j).S;
    }
    Eigen::Matrix<double, M, 1> nu;
    Eigen::Matrix<double, M, M> S;
    imm::innovation_mixture<M>(c_, used, count_, nu_j, S_j, nu, S);
    double nis = 0.0;
    if (!imm::quadratic_form<M>(S, nu, nis)) nis = 0.0;  // a mixture of PD matrices is PD: not reached
    accept_update<M>(nu, S, nis);
  }

  void publish_probabilities() {
    for (int j = 0; j < count_; ++j) annotate(j, mu_[j]);
  }

  // The combined estimate, moment-matched on the common state (imm::combine).
  void fill(Estimate& e) const override {
    imm::combine(view(), mu_, x0_, P0_);
    imm::publish(x0_, P0_, any_acceleration_, e);
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
  bool any_acceleration_ = false, mixed_ = false;
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

// --- The component form: modes: [{type: filter.ekf, ...}, {type: filter.ukf, ...}] -----------------

// The common state's component names, in its order (motion.hpp's constant-acceleration layout).
constexpr const char* kCommonNames[imm::kC] = {"x", "vx", "ax", "y", "vy", "ay", "z", "vz", "az"};

// One mode given as a nested component: its estimator (created by the host from the nested
// type's create_estimator), where each of its state components lies in the common state.
struct EstimatorMode {
  std::string name;
  std::shared_ptr<const Estimator> prototype;  // cloned per IMM estimator
  int dim = 0;
  int common[kMaxStateDim] = {};  // common-state index of the mode's state component r
  bool has_acceleration = false;
};

struct ComponentImmConfig {
  RangeRateUse range_rate = RangeRateUse::Auto;
  bool tilted_sensors = true;
  std::vector<EstimatorMode> modes;
  std::vector<double> transition, initial;
};

class ComponentImmEstimator;

// A mode's track: its warnings are collected and passed on (named) by the IMM, its counts go to
// the IMM's counters "<mode>.<counter>" (from `first_counter` on), its annotations are dropped
// (they would clash between modes); `estimate` receives the innovation of its accepted update.
struct ModeTrack final : TrackContext {
  void warn(const std::string& message) override { warnings.push_back(message); }
  void count(int counter) override;
  void annotate(int, double) override {}
  std::vector<std::string> warnings;
  ComponentImmEstimator* imm = nullptr;
  int first_counter = 0;
};

// An owned mode estimator that a copy clones.
struct OwnedEstimator {
  std::unique_ptr<Estimator> e;
  OwnedEstimator() = default;
  explicit OwnedEstimator(std::unique_ptr<Estimator> p) : e(std::move(p)) {}
  OwnedEstimator(const OwnedEstimator& o) : e(o.e ? o.e->clone() : nullptr) {}
  OwnedEstimator& operator=(const OwnedEstimator& o) {
    if (this != &o) e = o.e ? o.e->clone() : nullptr;
    return *this;
  }
};

// The same IMM cycle as ImmEstimator (imm_mixing.hpp's mixing, combination, likelihoods) over
// modes that are estimators of any type taking a state (Estimator::assign) on a Cartesian layout:
// a mode's state and covariance come from its fill() and go back, mixed, through assign(); its
// likelihood from the innovation of its own update (nu, S, NIS through its ModeTrack).
class ComponentImmEstimator final : public Estimator {
 public:
  explicit ComponentImmEstimator(const ComponentImmConfig& c) : Estimator(spec(c)) {
    count_ = static_cast<int>(c.modes.size());
    int next_counter = 1;  // after mode_updates_refused
    for (int j = 0; j < count_; ++j) {
      const EstimatorMode& m = c.modes[static_cast<size_t>(j)];
      st_.tracks[j].first_counter = next_counter;
      next_counter += static_cast<int>(m.prototype->measurement_spec().counters.size());
      st_.names[j] = m.name;
      st_.dim[j] = m.dim;
      for (int r = 0; r < m.dim && r < kMaxStateDim; ++r) st_.common[j][r] = m.common[r];
      st_.has_acceleration[j] = m.has_acceleration;
      any_acceleration_ = any_acceleration_ || m.has_acceleration;
      st_.modes[j] = OwnedEstimator(m.prototype->clone());
      st_.mu0[j] = c.initial[static_cast<size_t>(j)];
      for (int i = 0; i < count_; ++i) st_.pi[j * count_ + i] = c.transition[static_cast<size_t>(j * count_ + i)];
    }
    rebind();
  }
  ComponentImmEstimator(const ComponentImmEstimator& o)
      : Estimator(o), count_(o.count_), any_acceleration_(o.any_acceleration_), mixed_(o.mixed_), st_(o.st_) {
    rebind();
  }
  ComponentImmEstimator& operator=(const ComponentImmEstimator&) = delete;

  NoiseHandles noise() override { return imm_noise(R_); }
  StateLayout layout() const override { return imm_layout(any_acceleration_); }
  std::vector<std::string> annotation_names() const override {
    return probability_names(count_, [&](int j) { return st_.names[j]; });
  }
  void check(const Measurement& m) override {
    for (int j = 0; j < count_; ++j) mode(j).check(m);
  }
  void end_run(bool initialised) override {
    for (int j = 0; j < count_; ++j) {
      mode(j).end_run(initialised);
      pass_warnings(j);
    }
  }

 private:
  enum Counter { kModeRefused };

  Estimator& mode(int j) { return *st_.modes[j].e; }
  const Estimator& mode(int j) const { return *st_.modes[j].e; }
  friend struct ModeTrack;
  // The IMM's counters: its own, then each mode's own as "<mode>.<counter>".
  static MeasurementSpec spec(const ComponentImmConfig& c) {
    MeasurementSpec m{mask(Frame::Spherical), c.range_rate, {"mode_updates_refused"}, c.tilted_sensors};
    for (const EstimatorMode& mode : c.modes)
      for (const std::string& counter : mode.prototype->measurement_spec().counters)
        m.counters.push_back(mode.name + "." + counter);
    return m;
  }
  void rebind() {
    for (int j = 0; j < count_; ++j) {
      st_.tracks[j].imm = this;
      st_.tracks[j].estimate = &st_.outcome[j];
      mode(j).bind(st_.tracks[j]);
    }
  }
  // Before a call into mode j: the time, the measurement noise, a fresh innovation.
  void enter(int j) {
    st_.tracks[j].time = time();
    st_.outcome[j].updated = false;
    mode(j).measurement_noise() = R_;
  }
  void pass_warnings(int j) {
    for (const std::string& w : st_.tracks[j].warnings) warn("mode '" + st_.names[j] + "': " + w);
    st_.tracks[j].warnings.clear();
  }

  bool reset() override {
    bool initialised = true;
    for (int j = 0; j < count_; ++j) {
      st_.tracks[j].who = who() + " mode '" + st_.names[j] + "'";
      enter(j);
      initialised = mode(j).reset() && initialised;
      pass_warnings(j);
    }
    for (int j = 0; j < count_; ++j) st_.mu[j] = st_.mu0[j];
    mixed_ = false;
    publish_probabilities();
    return initialised;
  }

  // Every mode initiates from the same measurements; the track starts when all have.
  bool initiate(const Measurement& m, int dim) override {
    bool formed = true;
    for (int j = 0; j < count_; ++j) {
      enter(j);
      formed = mode(j).initiate(m, dim) && formed;
      pass_warnings(j);
    }
    publish_probabilities();
    return formed;
  }

  // The modes on the common state, from their fill().
  const imm::ModeView& view() const {
    view_.count = count_;
    for (int j = 0; j < count_; ++j) {
      Estimate& e = scratch_[j];
      mode(j).fill(e);
      imm::CommonEstimate& c = common_[j];
      c.x.setZero();
      c.P.setZero();
      const int n = st_.dim[j];
      for (int r = 0; r < n; ++r) {
        c.x(st_.common[j][r]) = e.state(r);
        for (int k = 0; k < n; ++k) c.P(st_.common[j][r], st_.common[j][k]) = e.covariance(r, k);
      }
      c.has_acceleration = st_.has_acceleration[j];
      view_.x[j] = &c.x;
      view_.P[j] = &c.P;
      view_.has_acceleration[j] = c.has_acceleration;
    }
    return view_;
  }

  // Interaction (mixing) on the common state, each mode's mixed start assigned, then its own
  // prediction. All mixed starts are formed before any mode is overwritten.
  void predict(double T) override {
    imm::mixing_weights(st_.pi, st_.mu, count_, st_.c, st_.w);
    const imm::ModeView& v = view();
    for (int j = 0; j < count_; ++j) imm::mix(v, st_.w[j], *v.x[j], *v.P[j], st_.x0s[j], st_.P0s[j]);
    for (int j = 0; j < count_; ++j) {
      const int n = st_.dim[j];
      StateVec x(n);
      StateCov P(n, n);
      for (int r = 0; r < n; ++r) {
        x(r) = st_.x0s[j](st_.common[j][r]);
        for (int k = 0; k < n; ++k) P(r, k) = st_.P0s[j](st_.common[j][r], st_.common[j][k]);
      }
      enter(j);
      mode(j).assign(x, P);  // checked at configuration
      mode(j).predict(T);
      pass_warnings(j);
    }
    // The predicted mode probabilities, as ImmEstimator::predict (a coast moves them along the chain).
    for (int j = 0; j < count_; ++j) st_.mu[j] = st_.c[j];
    publish_probabilities();
    mixed_ = true;
  }

  bool predict_measurement(const SensorFrame& s, const MeasCov& R, PredictedMeasurement& p) const override {
    return predicted_by_update<ComponentImmEstimator>(s, R, p);
  }
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<ComponentImmEstimator>(*this); }

  bool update(const Measurement& m, int dim) override {
    if (!mixed_)  // no time elapsed: no transition
      for (int j = 0; j < count_; ++j) st_.c[j] = st_.mu[j];
    mixed_ = false;
    double ll[kMaxModes];
    bool used[kMaxModes];
    for (int j = 0; j < count_; ++j) {
      enter(j);
      const Estimate& out = st_.outcome[j];
      used[j] = mode(j).update(m, dim) && out.updated && out.innovation.size() == dim;
      pass_warnings(j);
      ll[j] = -std::numeric_limits<double>::infinity();
      if (used[j]) {
        PredictedMeasurement pm;
        pm.S = out.innovation_covariance;
        set_log_det(pm);
        ll[j] = imm::log_likelihood_from_log_det(dim, out.nis, pm.log_det_S);
      } else {
        count(kModeRefused);
      }
    }
    if (!imm::floor_likelihoods(ll, used, count_)) {
      for (int j = 0; j < count_; ++j) st_.mu[j] = st_.c[j];
      publish_probabilities();
      warn("no mode could use the measurement at t=" + std::to_string(m.time) + " s; measurement not used");
      return false;
    }
    imm::update_probabilities(st_.c, ll, count_, st_.mu);
    publish_probabilities();
    if (dim == 4)
      publish_innovation<4>(used);
    else
      publish_innovation<3>(used);
    return true;
  }

  // IMM-PDA (imm_pda.hpp) over modes that take weighted updates: the weights w_jk from each mode's
  // predicted measurement (its predict_measurement, reused while the candidates share the sensor
  // and R), then each mode's own combined update (Estimator::update_weighted) with w_jk / mu_j and
  // w_j0 / mu_j. A mode that cannot predict a candidate keeps its prediction for it: that weight
  // joins its share of the prediction.
  bool takes_weighted_updates() const override {
    for (int j = 0; j < count_; ++j)
      if (!mode(j).takes_weighted_updates()) return false;
    return true;
  }
  bool update_weighted(std::span<const Measurement> detections, std::span<const double> probability, double none,
                       int dim) override {
    return dim == 4 ? weighted_values<4>(detections, probability, none) : weighted_values<3>(detections, probability, none);
  }

  static bool same_geometry(const Measurement& a, const Measurement& b, int dim) {
    return a.sensor == b.sensor && a.frame == b.frame && a.azimuth == b.azimuth && a.sensor_level == b.sensor_level &&
           a.sensor_position == b.sensor_position && a.sensor_axes == b.sensor_axes && a.time == b.time &&
           a.has_range_rate == b.has_range_rate &&
           a.covariance.topLeftCorner(dim, dim) == b.covariance.topLeftCorner(dim, dim);
  }

  template <int M>
  bool weighted_values(std::span<const Measurement> detections, std::span<const double> probability, double none) {
    using VecM = Eigen::Matrix<double, M, 1>;
    using MatM = Eigen::Matrix<double, M, M>;
    if (!mixed_)  // no time elapsed: no transition
      for (int j = 0; j < count_; ++j) st_.c[j] = st_.mu[j];
    const std::size_t n = std::min(detections.size(), probability.size());
    memory::assign_grown(weights_, n * static_cast<std::size_t>(count_), 0.0);  // [j * n + k] = w_jk
    double W[kMaxModes] = {}, kept[kMaxModes] = {};  // sum_k w_jk of the updates; of the candidates kept as prediction
    PredictedMeasurement pm[kMaxModes];
    Eigen::LLT<MeasCov> llt[kMaxModes];
    bool can[kMaxModes] = {};
    const Measurement* geometry = nullptr;  // the candidate whose sensor and R pm[] were formed for
    VecM nu_bar = VecM::Zero();
    MatM S_published = MatM::Zero();
    bool have_S = false;
    double used = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      const double b = probability[k];
      if (!(b > 0.0)) continue;
      const Measurement& m = detections[k];
      if (!geometry || !same_geometry(*geometry, m, M)) {
        const MeasCov R = m.covariance.topLeftCorner(M, M);
        for (int j = 0; j < count_; ++j) {
          enter(j);
          can[j] = mode(j).predict_measurement(m, R, pm[j]) && pm[j].z.size() == M;
          if (can[j]) {
            llt[j].compute(pm[j].S);
            can[j] = llt[j].info() == Eigen::Success;
          }
          pass_warnings(j);
        }
        geometry = &m;
      }
      double ll[kMaxModes];
      bool ok[kMaxModes];
      VecM nus[kMaxModes];
      MatM Ss[kMaxModes];
      const VecM* nu_j[kMaxModes];
      const MatM* S_j[kMaxModes];
      for (int j = 0; j < count_; ++j) {
        ok[j] = can[j];
        ll[j] = -std::numeric_limits<double>::infinity();
        nus[j].setZero();
        Ss[j].setZero();
        if (ok[j]) {
          MeasVec r = m.value.head(M) - pm[j].z;
          wrap_residual(m.frame, r);
          const double nis = llt[j].matrixL().solve(r).squaredNorm();
          ll[j] = imm::log_likelihood_from_log_det(M, nis, pm[j].log_det_S);
          nus[j] = r;
          Ss[j] = pm[j].S;
        } else {
          count(kModeRefused);
        }
        nu_j[j] = &nus[j];
        S_j[j] = &Ss[j];
      }
      double q[kMaxModes];
      if (!imm::candidate_mode_weights(st_.c, ll, ok, count_, q)) continue;  // no mode could use it: dropped
      for (int j = 0; j < count_; ++j) {
        const double w = b * q[j];
        if (ok[j]) {
          weights_[static_cast<std::size_t>(j) * n + k] = w;
          W[j] += w;
        } else {
          kept[j] += w;
        }
      }
      used += b;
      VecM nu;
      MatM S;
      imm::innovation_mixture<M>(st_.c, ok, count_, nu_j, S_j, nu, S);
      nu_bar += b * nu;
      if (!have_S) S_published = S;
      have_S = true;
    }
    if (!(used > 0.0)) {
      warn("no mode could use any candidate detection at t=" + std::to_string(time()) + " s; none used");
      return false;  // nothing changed: the prediction, mode probabilities as before
    }
    const double total = none + used;
    double mu[kMaxModes];
    for (int j = 0; j < count_; ++j) {
      const double prediction = none * st_.c[j] + kept[j];
      const double a = prediction + W[j];  // total * mu_j
      mu[j] = a / total;
      if (!(a > 0.0) || !(W[j] > 0.0)) continue;  // mu_j = 0, or all of it on the prediction: nothing to update
      const std::span<double> w(weights_.data() + static_cast<std::size_t>(j) * n, n);
      for (double& v : w) v /= a;
      enter(j);
      if (!mode(j).update_weighted(detections.first(n), w, prediction / a, M)) count(kModeRefused);
      pass_warnings(j);
    }
    std::copy(mu, mu + count_, st_.mu);
    imm::normalise(st_.mu, count_);
    mixed_ = false;
    publish_probabilities();
    nu_bar /= total;
    double nis = 0.0;
    if (!imm::quadratic_form<M>(S_published, nu_bar, nis)) nis = 0.0;
    accept_update<M>(nu_bar, S_published, nis);
    return true;
  }

  template <int M>
  void publish_innovation(const bool* used) {
    Eigen::Matrix<double, M, 1> nus[kMaxModes];
    Eigen::Matrix<double, M, M> Ss[kMaxModes];
    const Eigen::Matrix<double, M, 1>* nu_j[kMaxModes];
    const Eigen::Matrix<double, M, M>* S_j[kMaxModes];
    for (int j = 0; j < count_; ++j) {
      if (used[j]) {
        nus[j] = st_.outcome[j].innovation.template head<M>();
        Ss[j] = st_.outcome[j].innovation_covariance.template topLeftCorner<M, M>();
      } else {
        nus[j].setZero();
        Ss[j].setZero();
      }
      nu_j[j] = &nus[j];
      S_j[j] = &Ss[j];
    }
    Eigen::Matrix<double, M, 1> nu;
    Eigen::Matrix<double, M, M> S;
    imm::innovation_mixture<M>(st_.c, used, count_, nu_j, S_j, nu, S);
    double nis = 0.0;
    if (!imm::quadratic_form<M>(S, nu, nis)) nis = 0.0;  // a mixture of PD matrices is PD
    accept_update<M>(nu, S, nis);
  }

  void publish_probabilities() {
    for (int j = 0; j < count_; ++j) annotate(j, st_.mu[j]);
  }

  void fill(Estimate& e) const override {
    imm::combine(view(), st_.mu, x0_, P0_);
    imm::publish(x0_, P0_, any_acceleration_, e);
  }

  void scale_covariance(double k) override {
    for (int j = 0; j < count_; ++j) mode(j).scale_covariance(k);
  }

  int count_ = 0;
  bool any_acceleration_ = false, mixed_ = false;
  // Everything a copy takes as it is (the modes cloned; rebind() points them at the copy's tracks).
  struct State {
    std::string names[kMaxModes];
    int dim[kMaxModes] = {};
    int common[kMaxModes][kMaxStateDim] = {};
    bool has_acceleration[kMaxModes] = {};
    OwnedEstimator modes[kMaxModes];
    ModeTrack tracks[kMaxModes];
    Estimate outcome[kMaxModes];  // each mode's accepted innovation
    double pi[kMaxModes * kMaxModes] = {};  // row i: from mode i
    double mu0[kMaxModes] = {}, mu[kMaxModes] = {}, c[kMaxModes] = {};
    double w[kMaxModes][kMaxModes] = {};
    imm::VecC x0s[kMaxModes];  // mixed starts
    imm::MatC P0s[kMaxModes];
  } st_;
  std::vector<double> weights_;  // update_weighted's w_jk / mu_j, mode by mode (grown, reused)
  // Scratch (fill is const: what it forms is no state of the filter).
  mutable Estimate scratch_[kMaxModes];
  mutable imm::CommonEstimate common_[kMaxModes];
  mutable imm::ModeView view_;
  mutable imm::VecC x0_ = imm::VecC::Zero();
  mutable imm::MatC P0_ = imm::MatC::Zero();
};

void ModeTrack::count(int counter) {
  if (imm) imm->count(first_counter + counter);
}

// The mode name in the annotations: <type without "filter.">_<cv|ca|singer> when the type has a
// motion choice, else the short type; on a clash <index>_<short type>.
std::string component_mode_name(const NestedComponent& nc, int index, const std::vector<EstimatorMode>& before) {
  const std::string shortname = nc.type.rfind("filter.", 0) == 0 ? nc.type.substr(7) : nc.type;
  std::string name = shortname;
  if (nc.params.has("motion")) {
    const std::string& w = nc.params.choice_word("motion");
    name += "_" + std::string(w == "constant_velocity" ? "cv" : w == "constant_acceleration" ? "ca" : w);
  }
  for (const EstimatorMode& m : before)
    if (m.name == name) return std::to_string(index + 1) + "_" + shortname;
  return name;
}

// Each nested mode's estimator, checked to be one an IMM can mix: spherical measurements with the
// same range-rate use as the others, a Cartesian position/velocity(/acceleration) layout, assign().
ComponentImmConfig make_component_config(const Params& p) {
  ComponentImmConfig c;
  const std::vector<NestedComponent>& nested = p.components("modes");
  if (p.given("zenith"))
    throw p.error("zenith", "with modes given as components, set zenith in each mode (filter.ekf, filter.ukf take it)");
  for (size_t k = 0; k < nested.size(); ++k) {
    const NestedComponent& nc = nested[k];
    const std::string label = "mode " + std::to_string(k + 1) + " (" + nc.type + ")";
    auto refuse = [&](const std::string& why) { return ConfigError(label + ": " + why, nc.type_where, p.node()); };
    std::unique_ptr<Estimator> e = nc.create_estimator();
    const MeasurementSpec& spec = e->measurement_spec();
    if (!(spec.frames & mask(Frame::Spherical)))
      throw refuse("it measures in another frame; an IMM's modes take spherical [r, az, el(, rdot)] measurements");
    if (k == 0) {
      c.range_rate = spec.range_rate;
    } else if (spec.range_rate != c.range_rate) {
      throw ConfigError(label + ": range_rate " + to_string(spec.range_rate) + ", but mode 1 has " +
                            to_string(c.range_rate) + "; every mode must accept the same measurements",
                        nc.params.given("range_rate") ? nc.params.where("range_rate") : nc.type_where, p.node());
    }
    c.tilted_sensors = c.tilted_sensors && spec.tilted_sensors;
    EstimatorMode m;
    const StateLayout L = e->layout();
    m.dim = L.dim;
    int found[imm::kC];
    std::fill(found, found + imm::kC, -1);
    for (int r = 0; r < L.dim; ++r) {
      int at = -1;
      for (int i = 0; i < imm::kC; ++i)
        if (L.components[r].name && std::string(L.components[r].name) == kCommonNames[i]) at = i;
      if (at < 0 || found[at] >= 0)
        throw refuse(std::string("its state component '") + (L.components[r].name ? L.components[r].name : "?") +
                     "' is not one of the common Cartesian state [x vx ax y vy ay z vz az]");
      found[at] = r;
      m.common[r] = at;
    }
    int accelerations = 0;
    for (int i = 0; i < imm::kC; ++i) {
      if (!imm::is_acceleration(i) && found[i] < 0)
        throw refuse(std::string("its state has no '") + kCommonNames[i] + "'; an IMM mode needs the ENU position and velocity");
      if (imm::is_acceleration(i) && found[i] >= 0) ++accelerations;
    }
    if (accelerations != 0 && accelerations != 3) throw refuse("its state has acceleration on some axes only");
    m.has_acceleration = accelerations == 3;
    // A probe: the estimator must take a mixed start.
    std::unique_ptr<Estimator> probe = e->clone();
    if (!probe->assign(StateVec::Zero(m.dim), StateCov::Identity(m.dim, m.dim)))
      throw refuse("'" + nc.type + "' cannot be an IMM mode: its estimator does not take a mixed state (Estimator::assign)");
    m.name = component_mode_name(nc, static_cast<int>(k), c.modes);
    m.prototype = std::shared_ptr<const Estimator>(std::move(e));
    c.modes.push_back(std::move(m));
  }
  if (p.given("range_rate") && p.choice<RangeRateUse>("range_rate") != c.range_rate)
    throw p.error("range_rate", std::string("the modes use range_rate ") + to_string(c.range_rate) +
                                    "; with modes given as components, set it in each mode");
  return c;
}

std::vector<ParamSpec> mode_fields() {
  std::vector<ParamSpec> f = {ParamSpec::string("name", "mode name in the annotations (p_<name>); default cv, ca or singer")};
  for (ParamSpec& s : transition_param_specs()) f.push_back(std::move(s));
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

// The transition matrix and the initial mode probabilities of n modes (both forms).
void read_probabilities(const Params& p, int n, std::vector<double>& transition, std::vector<double>& initial) {
  transition = p.reals("transition");
  if (std::string why = imm::check_transition(transition, n); !why.empty()) throw p.error("transition", why);
  if (p.has("initial_probabilities")) {
    initial = p.reals("initial_probabilities");
    double sum = 0.0;
    for (double v : initial) sum += v;
    if (static_cast<int>(initial.size()) != n || std::fabs(sum - 1.0) > 1e-9)
      throw p.error("initial_probabilities", "give one probability per mode (" + std::to_string(n) +
                                                 "), summing to 1 (they sum to " + std::to_string(sum) + ")");
    for (double v : initial)
      if (!(v >= 0.0)) throw p.error("initial_probabilities", "probabilities cannot be negative");
  } else {
    initial.assign(static_cast<size_t>(n), 1.0 / n);
  }
}

void check_mode_count(const Params& p, size_t n) {
  if (n < 2 || n > static_cast<size_t>(kMaxModes))
    throw p.error("modes", "an IMM takes 2 to " + std::to_string(kMaxModes) + " modes (got " + std::to_string(n) + ")");
}

// The estimator of one track from the node's parameters, record form (the node and a tracker take it alike).
ImmEstimator make_estimator(const Params& p) {
  ImmConfig c;
  c.node = p.node();
  c.range_rate = p.choice<RangeRateUse>("range_rate");
  const auto zenith = p.choice<Settings::Zenith>("zenith");
  const std::vector<Params>& records = p.records("modes");
  check_mode_count(p, records.size());
  for (const Params& r : records) {
    Settings s;
    s.type = "filter.imm";
    s.node = c.node;
    static_cast<TransitionModel&>(s) = parse_transition(r);
    s.range_rate = c.range_rate;
    s.zenith = zenith;
    s.init = Settings::Init::TwoPoint;
    if (s.motion == Settings::Motion::ConstantVelocity && r.given("initial_sigma_acceleration"))
      throw r.error("initial_sigma_acceleration", "the constant_velocity state has no acceleration");
    s.sa0 = r.real_or("initial_sigma_acceleration", s.motion == Settings::Motion::Singer ? s.intensity : 50.0);
    Mode m;
    m.name = r.has("name") ? r.text("name") : default_name(s.motion);
    // The name becomes a CSV column (p_<name>) and a chart label: the node-id rule (names.hpp).
    if (!is_plain_name(m.name))
      throw r.error("name", std::string("a mode name must be ") + kPlainNameRule +
                                " (it names the annotation p_<name>, a CSV column and a chart label)");
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
  read_probabilities(p, static_cast<int>(c.modes.size()), c.transition, c.initial);
  return ImmEstimator(c);
}

// The component form's estimator: modes created by the host from their nested declarations.
ComponentImmEstimator make_component_estimator(const Params& p) {
  check_mode_count(p, p.components("modes").size());
  ComponentImmConfig c = make_component_config(p);
  read_probabilities(p, static_cast<int>(c.modes.size()), c.transition, c.initial);
  return ComponentImmEstimator(c);
}

bool component_form(const Params& p) { return !p.components("modes").empty(); }

std::unique_ptr<Component> create(const Params& p) {
  if (component_form(p)) return make_single_track_filter("filter.imm", p.node(), make_component_estimator(p));
  return make_single_track_filter("filter.imm", p.node(), make_estimator(p));
}

std::unique_ptr<Estimator> create_estimator(const Params& p) {
  if (component_form(p)) return std::make_unique<ComponentImmEstimator>(make_component_estimator(p));
  return std::make_unique<ImmEstimator>(make_estimator(p));
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.imm";
  d.kind = ComponentKind::Filter;
  d.summary = "Interacting multiple model filter: 2-4 Cartesian EKF modes (CV, CA, Singer) or nested filters "
              "(filter.ekf, filter.ukf) on spherical [r, az, el(, rdot)] measurements, mode probabilities as annotations";
  d.doc =
      "Blom & Bar-Shalom (1988) IMM. Each mode is filter.ekf's Cartesian ENU EKF with its own motion model and "
      "noise (modes: a list of records with filter.ekf's motion parameters), or each mode is a nested filter "
      "component ({type: filter.ekf or filter.ukf, <its parameters>}, validated against that type's declaration) "
      "whose per-track estimator takes the mixed state (Estimator::assign); all modes must accept the same "
      "measurements (spherical, the same range_rate). Per measurement: mixing of the mode "
      "estimates with the Markov transition matrix (transition: row-major, row i = the probabilities of going from "
      "mode i to each mode; rows sum to 1) on the common state [x vx ax y vy ay z vz az]; a mode without "
      "acceleration (CV) borrows the receiving mode's acceleration, uncorrelated (unbiased mixing, Granstrom, "
      "Willett & Bar-Shalom 2015); each mode's exact prediction and EKF update; mode probabilities from the "
      "Gaussian innovation likelihoods in the log domain; the published estimate is the moment-matched mixture (9 "
      "states if any mode has acceleration). Annotations <id>.p_<mode name>: the mode probabilities after each "
      "update. Initialised by two-point differencing (all modes alike). Adapters may replace R (not the modes' "
      "process noise). Under a probabilistic associator (assoc.pda, assoc.jpda): the IMM-PDA combined update "
      "(Houles & Bar-Shalom 1989) - joint weights w_jk = beta_k c_j g_jk / sum_i c_i g_ik and w_j0 = beta_0 c_j, mode "
      "probabilities mu_j = w_j0 + sum_k w_jk, each mode's own combined update with w_jk / mu_j (component modes "
      "must take weighted updates, as filter.ekf and filter.ukf do). See docs/filters.md.";
  d.accepts = mask(ItemKind::Measurement);
  d.produces = mask(ItemKind::Estimate);
  d.accepts_frames = mask(Frame::Spherical);
  d.params = {
      ParamSpec::records("modes", mode_fields(),
                         "the mode filters (2 to 4): records of filter.ekf's motion model and noise each, or "
                         "components {type: filter.ekf or filter.ukf, <its parameters>} (any filter whose estimator "
                         "takes a mixed Cartesian state); the annotation of a component mode is p_<type>_<motion>, "
                         "e.g. p_ukf_ca (p_<index>_<type> on a clash)")
          .or_components({ComponentKind::Filter})
          .with_prefix("filter.")
          .req(),
      ParamSpec::real_list("transition", dim::none,
                           "Markov transition matrix, row-major (modes x modes): row i = P(next mode | mode i), rows "
                           "sum to 1")
          .req(),
      ParamSpec::real_list("initial_probabilities", dim::none, "mode probabilities at the start (default: uniform)"),
      range_rate_param(),
      cartesian_filter::zenith_param(),
  };
  d.params[d.params.size() - 2].doc += " (component modes: set in each mode; given here, it must match theirs)";
  d.params.back().doc += " (record form; component modes take their own)";
  d.create = create;
  d.create_estimator = create_estimator;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.imm", trackflow::register_components)
