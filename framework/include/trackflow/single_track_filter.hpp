// Purpose: the single-track filter node over any estimator (estimator.hpp) — validity, frame, well-formedness, time order, range rate, R, adapter hooks, non-finite checks (measurement in, state out), initiate/predict/update/publish — with its counted skips.
#pragma once

#include <trackflow/chi_square.hpp>
#include <trackflow/component.hpp>
#include <trackflow/error.hpp>
#include <trackflow/estimator.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/run_result_codec.hpp>

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace trackflow {

// Counts of one run, summed in run order into the node's summary.
struct SingleTrackRunResult final : RunResult {
  static constexpr int kMaxCounters = 12;  // an IMM of four modes with two counters each, and its own
  std::uint64_t updates = 0;     // measurements used
  std::uint64_t coasted = 0;     // invalid measurements: predicted through
  std::uint64_t non_finite = 0;  // flagged valid but non-finite (value or R): predicted through
  std::uint64_t rejected = 0;    // the filter refused the update (it said why in a warning)
  std::uint64_t counters[kMaxCounters] = {};
  std::uint64_t refused_non_finite = 0;  // steps whose state came out non-finite: not published, track restarted
  std::uint64_t other_target = 0;  // usable measurements whose origin is another truth target than the track's
  // Per input port (one sensor's stream each when a filter takes several): updates, the sum of
  // their NIS and of their dimensions (the NIS sum's degrees of freedom).
  static constexpr int kMaxPorts = 8;
  std::uint64_t port_updates[kMaxPorts] = {};
  double port_nis[kMaxPorts] = {};
  std::uint64_t port_dof[kMaxPorts] = {};
  // Its codec under mpirun (run_result_codec.hpp): one list, written and read in this order.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.updates, r.coasted, r.non_finite, r.rejected, r.counters, r.refused_non_finite, r.other_target, r.port_updates,
      r.port_nis, r.port_dof);
  }
};

// One track of one estimator E behind the measurement front end every filter node shares: a
// filter plugin writes its estimator (estimator.hpp) and makes its node with
// `std::make_unique<SingleTrackFilter<MyEstimator>>("filter.mine", node, MyEstimator(...))`.
// E should be `final`: its calls are then direct (and inlined), not virtual.
template <class E>
class SingleTrackFilter final : public Filter, public FieldListCodec<SingleTrackRunResult>, private TrackContext {
  static_assert(std::is_base_of_v<Estimator, E>, "SingleTrackFilter<E>: E derives from trackflow::Estimator");

 public:
  // Two measurements closer than this (seconds) do not start a track by differencing.
  static constexpr double kMinStartInterval = 1e-6;

  SingleTrackFilter(std::string type, std::string node, E estimator)
      : type_(std::move(type)), node_(std::move(node)), estimator_(std::move(estimator)) {
    TrackContext::who = type_ + " (node '" + node_ + "')";
    TrackContext::estimate = &estimate_;
    estimator_.bind(*this);  // public in Estimator
    if (est().measurement_spec().counters.size() > static_cast<size_t>(SingleTrackRunResult::kMaxCounters))
      throw std::length_error(TrackContext::who + " declares " + std::to_string(est().measurement_spec().counters.size()) +
                              " counters; a single-track node counts at most " +
                              std::to_string(SingleTrackRunResult::kMaxCounters) + " (a bug in that plugin)");
    const int n = est().layout().dim;
    estimate_.state = StateVec::Zero(n);
    estimate_.covariance = StateCov::Zero(n, n);
  }
  SingleTrackFilter(const SingleTrackFilter&) = delete;
  SingleTrackFilter& operator=(const SingleTrackFilter&) = delete;

  NoiseHandles noise() override { return est().noise(); }
  StateLayout state_layout() const override { return est().layout(); }
  const TransitionModel* transition_model() const override { return est().transition_model(); }
  std::vector<std::string> annotation_names() const override { return est().annotation_names(); }
  const E& estimator() const { return estimator_; }

  void start_run(const RunContext& ctx) override {
    diag_ = ctx.diagnostics;
    has_time_ = false;
    non_finite_reported_ = false;
    refusal_reported_ = false;
    has_origin_ = false;
    other_target_reported_ = false;
    estimate_.target = 0;
    run_ = SingleTrackRunResult{};
    clear_innovation();
    initialised_ = est().reset();
  }

  // Several inputs (one per sensor) are merged by the engine in time order; equal time stamps
  // arrive in the engine's delivery order (docs/architecture.md) and are used one after the other
  // with no prediction between them. The input names label the per-sensor statistics.
  void set_inputs(const std::vector<InputInfo>& inputs) override {
    inputs_.clear();
    for (const InputInfo& in : inputs) inputs_.push_back(in.node);
  }

  void on_measurement(const Measurement& m, int port) override {
    const MeasurementSpec& spec = est().measurement_spec();
    const int n = static_cast<int>(m.value.size());
    const bool well_formed = (spec.frames & mask(m.frame)) && n == position_values(m.frame) + (m.has_range_rate ? 1 : 0) &&
                             m.covariance.rows() == n && m.covariance.cols() == n;
    // An invalid measurement (radar not locked) is coasted through whatever it holds: a converter
    // passes it on unconverted, so neither its frame nor its shape is checked.
    if (m.valid) check_valid(m, n, well_formed);
    if (has_time_ && m.time < last_time()) {
      if (diag_)
        diag_->skip(node_, "measurement at t=" + std::to_string(m.time) + " s is older than the previous one (t=" +
                               std::to_string(last_time()) + " s)");
      return;
    }
    const int dim = dimension(m);
    MeasCov& R = est().measurement_noise();
    if (well_formed && n >= dim) copy_R(m, dim, R);
    before_update(m);  // adapters may replace R and the process noise
    if (m.valid && (R.rows() < dim || R.cols() < dim))
      throw DataError(TrackContext::who + ": an adapter left a " + std::to_string(R.rows()) + "x" +
                      std::to_string(R.cols()) + " R for a " + std::to_string(dim) + "-element measurement");
    const bool usable = m.valid && finite(m, dim, R);
    if (!m.valid) {
      ++run_.coasted;
    } else if (!usable) {
      ++run_.non_finite;
      if (!non_finite_reported_)
        warn("non-finite measurement or R at t=" + std::to_string(m.time) +
             " s treated as invalid (coasted); further ones are counted in the summary");
      non_finite_reported_ = true;
    }
    if (usable) note_origin(m);
    const bool had_time = has_time_;
    const double T = m.time - last_time();
    TrackContext::time = m.time;
    has_time_ = true;
    if (!initialised_) {
      // Differencing two points closer than kMinStartInterval divides by ~0 (1e-170 s apart
      // gives infinities): the later point starts the track afresh instead.
      if (usable && had_time && T > 0.0 && T < kMinStartInterval) initialised_ = est().reset();
      if (!initialised_ && usable && est().initiate(m, dim)) {
        initialised_ = true;
        clear_innovation();
        publish_state(m);
      } else {
        set_uninitialised(estimate_, m.time);
        publish(m, estimate_);
      }
      return;
    }
    if (had_time && T > 0.0) est().predict(T);
    clear_innovation();
    bool used = false;
    if (usable) used = est().update(m, dim);
    if (!publish_state(m)) return;
    if (usable) ++(used ? run_.updates : run_.rejected);
    if (used) {
      const int p = port >= 0 && port < SingleTrackRunResult::kMaxPorts ? port : SingleTrackRunResult::kMaxPorts - 1;
      ++run_.port_updates[p];
      run_.port_nis[p] += estimate_.nis;
      run_.port_dof[p] += static_cast<std::uint64_t>(dim);
    }
  }

  std::unique_ptr<RunResult> end_run() override {
    est().end_run(initialised_);
    return std::make_unique<SingleTrackRunResult>(run_);
  }

  void merge(RunResult& result) override {
    const auto& r = static_cast<const SingleTrackRunResult&>(result);
    total_.updates += r.updates;
    total_.coasted += r.coasted;
    total_.non_finite += r.non_finite;
    total_.rejected += r.rejected;
    total_.refused_non_finite += r.refused_non_finite;
    total_.other_target += r.other_target;
    for (int i = 0; i < SingleTrackRunResult::kMaxCounters; ++i) total_.counters[i] += r.counters[i];
    for (int i = 0; i < SingleTrackRunResult::kMaxPorts; ++i) {
      total_.port_updates[i] += r.port_updates[i];
      total_.port_nis[i] += r.port_nis[i];
      total_.port_dof[i] += r.port_dof[i];
    }
  }

  void finish(Summary& s, const FinishContext&) override {
    s.metric("updates", static_cast<double>(total_.updates));
    s.metric("coasted", static_cast<double>(total_.coasted));
    if (total_.non_finite) s.metric("non_finite_skipped", static_cast<double>(total_.non_finite));
    if (total_.rejected) s.metric("updates_refused", static_cast<double>(total_.rejected));
    if (total_.refused_non_finite) s.metric("non_finite_state_refused", static_cast<double>(total_.refused_non_finite));
    if (total_.other_target) s.metric("other_target_measurements", static_cast<double>(total_.other_target));
    const std::vector<std::string>& counters = est().measurement_spec().counters;
    for (size_t i = 0; i < counters.size() && i < SingleTrackRunResult::kMaxCounters; ++i)
      s.metric(counters[i], static_cast<double>(total_.counters[i]));
    if (inputs_.size() > 1) per_sensor_summary(s);
    est().finish(s);
  }

  // Confidence of the per-sensor NIS bands in the summary.
  static constexpr double kNisConfidence = 0.95;

  bool initialised() const { return initialised_; }

  // Covariance access for adapters, the same for every estimator: the current state covariance
  // (in layout() order), a rescale that the estimator applies to whatever representation of P it
  // keeps, a restart.
  bool has_covariance_access() const override { return true; }
  void read_covariance(StateCov& P) const override {
    if (!initialised_) {
      P.resize(0, 0);
      return;
    }
    scratch_.state.resize(estimate_.state.size());  // fixed capacity: no heap
    scratch_.covariance.resize(estimate_.covariance.rows(), estimate_.covariance.cols());
    est().fill(scratch_);
    P = scratch_.covariance;
  }
  void scale_covariance(double factor) override {
    if (initialised_ && factor > 0.0 && factor < std::numeric_limits<double>::infinity())
      est().scale_covariance(factor);
  }
  void restart_track() override { initialised_ = est().reset(); }

 private:
  // The track's services to its estimator (TrackContext).
  void warn(const std::string& message) override {
    if (diag_) diag_->warn(node_, message);
  }
  void count(int counter) override {
    if (counter >= 0 && counter < SingleTrackRunResult::kMaxCounters) ++run_.counters[counter];
  }
  void annotate(int index, double value) override { annotate_own(index, value); }

  // With several inputs: each sensor's updates and mean NIS per measurement element (1 for a
  // consistent filter and a well-calibrated sensor), with its chi-square band over all of that
  // sensor's updates: a station whose bias or noise the filter does not know stands out.
  void per_sensor_summary(Summary& s) const {
    for (size_t i = 0; i < inputs_.size() && i < static_cast<size_t>(SingleTrackRunResult::kMaxPorts); ++i) {
      s.metric("updates." + inputs_[i], static_cast<double>(total_.port_updates[i]));
      if (total_.port_dof[i] == 0) continue;
      const double dof = static_cast<double>(total_.port_dof[i]);
      const ChiSquareBand band = chi_square_mean_band(dof, kNisConfidence);
      s.metric_band("nis_mean." + inputs_[i], total_.port_nis[i] / dof, band.lo, band.hi, kNisConfidence);
    }
  }

  void check_valid(const Measurement& m, int n, bool well_formed) {
    const MeasurementSpec& spec = est().measurement_spec();
    const std::string& who = TrackContext::who;
    if (!(spec.frames & mask(m.frame)))
      throw DataError(who + " takes " + frame_names(spec.frames) + " measurements, but the one at t=" +
                      std::to_string(m.time) + " s is " + to_string(m.frame) +
                      ((spec.frames & mask(Frame::Cartesian)) && m.frame == Frame::Spherical
                           ? "; put a convert.* node between the radar and it"
                           : (spec.frames & mask(Frame::Spherical)) && m.frame == Frame::Cartesian
                                 ? "; for Cartesian (converted) measurements use filter.kalman or filter.decoupled"
                                 : ""));
    if (!well_formed) {
      const int expected = position_values(m.frame) + (m.has_range_rate ? 1 : 0);
      throw DataError(who + ": " + to_string(m.frame) + " measurement at t=" + std::to_string(m.time) + " s has " +
                      std::to_string(n) + " values and a " + std::to_string(m.covariance.rows()) + "x" +
                      std::to_string(m.covariance.cols()) + " covariance; expected " + std::to_string(expected) +
                      (m.has_range_rate ? " (with range rate)" : "") + " values and a matching covariance");
    }
    if (spec.range_rate == RangeRateUse::Use && !m.has_range_rate)
      throw DataError(who + ": range_rate: use, but the measurement at t=" + std::to_string(m.time) +
                      " s has no range rate (range_rate: auto accepts both)");
    if (!m.sensor_level && !spec.tilted_sensors) throw DataError(who + ": " + tilted_sensor_message(m));
    est().check(m);
  }

  // The measurement's R (2x2 to 4x4) and the finiteness of what the update will use, as
  // fixed-size copies and checks (the items are sized at run time).
  static void copy_R(const Measurement& m, int dim, MeasCov& R) {
    R.resize(dim, dim);
    if (dim == 4)
      R.template topLeftCorner<4, 4>() = m.covariance.template topLeftCorner<4, 4>();
    else if (dim == 3)
      R.template topLeftCorner<3, 3>() = m.covariance.template topLeftCorner<3, 3>();
    else
      R.template topLeftCorner<2, 2>() = m.covariance.template topLeftCorner<2, 2>();
  }
  static bool finite(const Measurement& m, int dim, const MeasCov& R) {
    if (m.value.size() < dim || R.rows() < dim || R.cols() < dim) return false;
    if (dim == 4) return finite_block<4, 1>(m.value) && finite_block<4, 4>(R);
    if (dim == 3) return finite_block<3, 1>(m.value) && finite_block<3, 3>(R);
    return finite_block<2, 1>(m.value) && finite_block<2, 2>(R);
  }
  // Whether the leading Rows x Cols block of `a` is finite, element by element: x * 0 is 0 for a
  // finite x and NaN for an infinity or a NaN, so the products sum to 0 exactly when all are
  // finite. Straight-line code of fixed length; Eigen's allFinite() on a block of a run-time-sized
  // item was an out-of-line generic loop (the quickstart: 320 instructions per measurement).
  template <int Rows, int Cols, class M>
  static bool finite_block(const M& a) {
    double zero = 0.0;
    for (int j = 0; j < Cols; ++j)
      for (int i = 0; i < Rows; ++i) zero += a.coeff(i, j) * 0.0;
    return zero == 0.0;
  }

  int dimension(const Measurement& m) const {
    const int positions = position_values(m.frame);
    switch (est().measurement_spec().range_rate) {
      case RangeRateUse::Use: return positions + 1;
      case RangeRateUse::Auto: return m.has_range_rate ? positions + 1 : positions;
      case RangeRateUse::Ignore: break;
    }
    return positions;
  }

  // The track's estimates carry the truth target of its first usable measurement with a known
  // origin (Detection::origin; simulations set it), which sinks score them against. A single-track
  // filter fed by several targets follows none of them: said once per run, counted, not hidden.
  void note_origin(const Measurement& m) {
    if (m.origin >= kOriginClutter) return;
    if (!has_origin_) {
      estimate_.target = m.origin;
      has_origin_ = true;
      return;
    }
    if (m.origin == estimate_.target) return;
    ++run_.other_target;
    if (!other_target_reported_)
      warn("the measurement at t=" + std::to_string(m.time) + " s comes from truth target " +
           std::to_string(m.origin) + ", this track's first from target " + std::to_string(estimate_.target) +
           ": one filter node follows one target, so its estimates are scored against target " +
           std::to_string(estimate_.target) + "; further ones are counted as other_target_measurements");
    other_target_reported_ = true;
  }

  void clear_innovation() {
    estimate_.updated = false;
    estimate_.innovation.resize(0);
    estimate_.innovation_covariance.resize(0, 0);
    estimate_.nis = 0.0;
  }

  double last_time() const { return TrackContext::time; }

  // Publishes the state, unless it came out non-finite (a division by ~0, an overflow): then the
  // step is refused -- counted, reported with the node and time -- and the track restarts, so
  // no NaN or infinity ever leaves a filter. Returns whether it published the state. The
  // published state and covariance are formed only when something sees them (a filter node
  // without consumers and adapters forms nothing, so there is nothing to check either); the
  // estimator's own state is the same either way.
  bool publish_state(const Measurement& m) {
    estimate_.time = m.time;
    estimate_.initialised = true;
    if (!observed()) {
      publish(m, estimate_);
      return true;
    }
    est().fill(estimate_);
    if (finite(estimate_)) {
      publish(m, estimate_);
      return true;
    }
    ++run_.refused_non_finite;
    if (!refusal_reported_)
      warn("the state at t=" + std::to_string(m.time) +
           " s came out non-finite (NaN or infinity); the step is refused and the track restarted; further ones are "
           "counted as non_finite_state_refused");
    refusal_reported_ = true;
    initialised_ = est().reset();
    clear_innovation();
    set_uninitialised(estimate_, m.time);
    publish(m, estimate_);
    return false;
  }

  // One sum per block: NaN or infinity anywhere makes it non-finite (so does a sum beyond 1e308,
  // which is no usable state either). Cheaper than an element-wise test on the hot path.
  // An estimator that declares its state dimension (`static constexpr int kStateDim`, the size
  // fill() gives Estimate::state) gets the same sums over fixed-size blocks, unrolled, instead of
  // Eigen's generic loops over the run-time-sized items (the quickstart: 250 instructions per
  // estimate); the 3- and 4-element innovations likewise.
  static bool finite(const Estimate& e) {
    if constexpr (requires { E::kStateDim; }) {
      constexpr int N = E::kStateDim;
      if (e.state.size() == N && e.covariance.rows() == N && e.covariance.cols() == N) {
        const int m = static_cast<int>(e.innovation.size());
        double innovation;
        if (m == 0 && e.innovation_covariance.size() == 0)
          innovation = 0.0;
        else if (m == 3 && e.innovation_covariance.rows() == 3 && e.innovation_covariance.cols() == 3)
          innovation = e.innovation.template head<3>().sum() + e.innovation_covariance.template topLeftCorner<3, 3>().sum();
        else if (m == 4 && e.innovation_covariance.rows() == 4 && e.innovation_covariance.cols() == 4)
          innovation = e.innovation.template head<4>().sum() + e.innovation_covariance.template topLeftCorner<4, 4>().sum();
        else
          innovation = e.innovation.sum() + e.innovation_covariance.sum();
        return std::isfinite(e.state.template head<N>().sum() + e.covariance.template topLeftCorner<N, N>().sum() +
                             e.enu.sum() + e.enu_covariance.sum() + e.nis + innovation);
      }
    }
    return std::isfinite(e.state.sum() + e.covariance.sum() + e.enu.sum() + e.enu_covariance.sum() + e.nis +
                         e.innovation.sum() + e.innovation_covariance.sum());
  }

  // The estimator's overrides may be private: they are called through the base, on a member of
  // known exact type, which the compiler calls directly (no virtual dispatch).
  Estimator& est() { return estimator_; }
  const Estimator& est() const { return estimator_; }

  std::string type_, node_;
  E estimator_;
  Estimate estimate_;
  Diagnostics* diag_ = nullptr;
  bool has_time_ = false, initialised_ = false, non_finite_reported_ = false, refusal_reported_ = false;
  bool has_origin_ = false, other_target_reported_ = false;
  SingleTrackRunResult run_, total_;
  std::vector<std::string> inputs_;  // upstream node of each input port
  mutable Estimate scratch_;  // read_covariance's, so the published estimate is never touched
};

// The filter node running estimator `e` (E final) as node `node` of type `type`.
template <class E>
std::unique_ptr<Component> make_single_track_filter(std::string type, std::string node, E e) {
  return std::make_unique<SingleTrackFilter<E>>(std::move(type), std::move(node), std::move(e));
}

}  // namespace trackflow
