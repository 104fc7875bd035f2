// Purpose: the one measurement front end every filter uses — validity, frame, well-formedness, time order, range rate, R, adapter hooks, non-finite checks (measurement in, state out), initialise/predict/update/publish — with its counted skips.
#pragma once

#include <trackflow/chi_square.hpp>
#include <trackflow/component.hpp>
#include <trackflow/error.hpp>
#include <trackflow/common_params.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/run_result_codec.hpp>

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace trackflow {

struct FrontEndSpec {
  std::string type;  // "filter.kalman", for messages
  std::string node;
  Frame frame = Frame::Spherical;  // the measurements the filter works on
  // Spherical filters: use the range rate when present (Auto), always (Use) or never (Ignore).
  // Cartesian filters take the three position values: Ignore.
  RangeRateUse range_rate = RangeRateUse::Ignore;
  // Filter-specific events counted per run and reported in the summary (see count()).
  std::vector<std::string> counters;
  // Whether the filter's measurement function turns into the sensor's own axes
  // (Measurement::sensor_axes); otherwise a tilted sensor's measurement is refused.
  bool tilted_sensors = false;
};

// Counts of one run, summed in run order into the node's summary.
struct FrontEndRunResult final : RunResult {
  static constexpr int kMaxCounters = 4;
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

// The template method of every filter (CRTP: no virtual call on the hot path). Derived provides
//   bool reset_track();                          start of a run: forget the track; return true
//                                                when it starts initialised (explicit state)
//   bool initialise(const Measurement& m, int dim);   a usable measurement while not yet
//                                                initialised; true once the state is formed
//   void predict(double T);                      T > 0 seconds
//   template <int M> bool update(const Measurement& m);   M = 3 or 4 values; on success call
//                                                accept_update(); false: not used (warn() why)
//   void fill_estimate(Estimate& e) const;       state, covariance, enu, enu_covariance
//   void scale_state_covariance(double k);       P <- k P in the filter's own representation
// and may hide (defaults below): check_measurement(m) for further checks on valid measurements,
// on_end_run() for per-run reports.
template <class Derived>
class FilterFrontEnd : public Filter, public RunResultCodec {
 public:
  // Two measurements closer than this (seconds) do not start a track by differencing.
  static constexpr double kMinStartInterval = 1e-6;

  void start_run(const RunContext& ctx) final {
    diag_ = ctx.diagnostics;
    has_time_ = false;
    non_finite_reported_ = false;
    refusal_reported_ = false;
    has_origin_ = false;
    other_target_reported_ = false;
    est_.target = 0;
    run_ = FrontEndRunResult{};
    clear_innovation();
    initialised_ = derived().reset_track();
  }

  // Several inputs (one per sensor) are merged by the engine in time order; equal time stamps
  // arrive in the engine's delivery order (docs/architecture.md) and are used one after the other
  // with no prediction between them. The input names label the per-sensor statistics.
  void set_inputs(const std::vector<InputInfo>& inputs) override {
    inputs_.clear();
    for (const InputInfo& in : inputs) inputs_.push_back(in.node);
  }

  void on_measurement(const Measurement& m, int port) final {
    const int n = static_cast<int>(m.value.size());
    const bool well_formed =
        m.frame == spec_.frame && n == (m.has_range_rate ? 4 : 3) && m.covariance.rows() == n && m.covariance.cols() == n;
    // An invalid measurement (radar not locked) is coasted through whatever it holds: a converter
    // passes it on unconverted, so neither its frame nor its shape is checked.
    if (m.valid) check_valid(m, n, well_formed);
    if (has_time_ && m.time < time_) {
      if (diag_)
        diag_->skip(spec_.node, "measurement at t=" + std::to_string(m.time) + " s is older than the previous one (t=" +
                                    std::to_string(time_) + " s)");
      return;
    }
    const int dim = dimension(m);
    if (well_formed && n >= dim) copy_R(m, dim);
    before_update(m);  // adapters may replace R_ and the process noise
    if (m.valid && (R_.rows() < dim || R_.cols() < dim))
      throw DataError(who() + ": an adapter left a " + std::to_string(R_.rows()) + "x" + std::to_string(R_.cols()) +
                      " R for a " + std::to_string(dim) + "-element measurement");
    const bool usable = m.valid && finite(m, dim);
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
    const double T = m.time - time_;
    time_ = m.time;
    has_time_ = true;
    if (!initialised_) {
      // Differencing two points closer than kMinStartInterval divides by ~0 (1e-170 s apart
      // gives infinities): the later point starts the track afresh instead.
      if (usable && had_time && T > 0.0 && T < kMinStartInterval) initialised_ = derived().reset_track();
      if (!initialised_ && usable && derived().initialise(m, dim)) {
        initialised_ = true;
        clear_innovation();
        publish_state(m);
      } else {
        set_uninitialised(est_, m.time);
        publish(m, est_);
      }
      return;
    }
    if (had_time && T > 0.0) derived().predict(T);
    clear_innovation();
    bool used = false;
    if (usable) used = dim == 4 ? derived().template update<4>(m) : derived().template update<3>(m);
    if (!publish_state(m)) return;
    if (usable) ++(used ? run_.updates : run_.rejected);
    if (used) {
      const int p = port >= 0 && port < FrontEndRunResult::kMaxPorts ? port : FrontEndRunResult::kMaxPorts - 1;
      ++run_.port_updates[p];
      run_.port_nis[p] += est_.nis;
      run_.port_dof[p] += static_cast<std::uint64_t>(dim);
    }
  }

  std::unique_ptr<RunResult> end_run() final {
    derived().on_end_run();
    return std::make_unique<FrontEndRunResult>(run_);
  }

  // Per-run counts cross processes as bytes (mpirun; run_result_codec.hpp) by FrontEndRunResult's
  // field list: FieldListCodec's two functions, called from this class's own `final` overrides so
  // that its base classes (and layout) stay what ABI 4 plugins were built with.
  using Codec = FieldListCodec<FrontEndRunResult>;
  void save_run_result(const RunResult& r, ByteWriter& out) const final { Codec::save_fields(r, out); }
  std::unique_ptr<RunResult> load_run_result(ByteReader& in) const final { return Codec::load_fields(in); }

  void merge(RunResult& result) final {
    const auto& r = static_cast<const FrontEndRunResult&>(result);
    total_.updates += r.updates;
    total_.coasted += r.coasted;
    total_.non_finite += r.non_finite;
    total_.rejected += r.rejected;
    total_.refused_non_finite += r.refused_non_finite;
    total_.other_target += r.other_target;
    for (int i = 0; i < FrontEndRunResult::kMaxCounters; ++i) total_.counters[i] += r.counters[i];
    for (int i = 0; i < FrontEndRunResult::kMaxPorts; ++i) {
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
    for (size_t i = 0; i < spec_.counters.size() && i < FrontEndRunResult::kMaxCounters; ++i)
      s.metric(spec_.counters[i], static_cast<double>(total_.counters[i]));
    if (inputs_.size() > 1) per_sensor_summary(s);
  }

  // Confidence of the per-sensor NIS bands in the summary.
  static constexpr double kNisConfidence = 0.95;

  bool initialised() const { return initialised_; }

  // Covariance access for adapters, the same for every filter: the current state covariance (in
  // state_layout() order), a rescale that the filter applies to whatever representation of P it
  // keeps, a restart.
  bool has_covariance_access() const final { return true; }
  void read_covariance(StateCov& P) const final {
    if (!initialised_) {
      P.resize(0, 0);
      return;
    }
    // fill_estimate may cache intermediate products in the filter: the filter, not the state,
    // changes, so the const of this read is kept for callers.
    scratch_.state.resize(est_.state.size());  // fixed capacity: no heap
    scratch_.covariance.resize(est_.covariance.rows(), est_.covariance.cols());
    const_cast<FilterFrontEnd*>(this)->derived().fill_estimate(scratch_);
    P = scratch_.covariance;
  }
  void scale_covariance(double factor) final {
    if (initialised_ && factor > 0.0 && factor < std::numeric_limits<double>::infinity())
      derived().scale_state_covariance(factor);
  }
  void restart_track() final { initialised_ = derived().reset_track(); }

 protected:
  explicit FilterFrontEnd(FrontEndSpec spec) : spec_(std::move(spec)) { R_ = MeasCov::Zero(3, 3); }

  // Defaults Derived may hide.
  void check_measurement(const Measurement&) {}
  void on_end_run() {}

  const FrontEndSpec& spec() const { return spec_; }
  std::string who() const { return spec_.type + " (node '" + spec_.node + "')"; }
  void warn(const std::string& message) const {
    if (diag_) diag_->warn(spec_.node, message);
  }
  Diagnostics* diagnostics() const { return diag_; }
  // Time of the measurement being processed (predict() runs to it).
  double time() const { return time_; }
  // Whether the interval T to this measurement equals `last_T` to the precision of the time
  // stamps (4 ulps of the current time), so that a motion model computed for last_T may be used
  // again. Fixed-rate data are stamped t0 + k / rate, rounded: their intervals differ in the last
  // bits (by up to ~5e-12 of a 25 ms interval after 540 s), which no model can resolve, and
  // comparing them exactly would recompute F and Q at nearly every step.
  bool same_interval(double T, double last_T) const {
    return std::fabs(T - last_T) <= 4.0 * std::numeric_limits<double>::epsilon() * std::fabs(time_);
  }
  void count(int counter) { ++run_.counters[counter]; }

  template <int M>
  void accept_update(const Eigen::Matrix<double, M, 1>& nu, const Eigen::Matrix<double, M, M>& S, double nis) {
    est_.updated = true;
    est_.innovation.resize(M);
    est_.innovation.template head<M>() = nu;
    est_.innovation_covariance.resize(M, M);
    est_.innovation_covariance.template topLeftCorner<M, M>() = S;
    est_.nis = nis;
  }

  MeasCov R_;  // this step's measurement noise, exposed to adapters through noise()
  Estimate est_;

 private:
  Derived& derived() { return static_cast<Derived&>(*this); }

  // With several inputs: each sensor's updates and mean NIS per measurement element (1 for a
  // consistent filter and a well-calibrated sensor), with its chi-square band over all of that
  // sensor's updates: a station whose bias or noise the filter does not know stands out.
  void per_sensor_summary(Summary& s) const {
    for (size_t i = 0; i < inputs_.size() && i < static_cast<size_t>(FrontEndRunResult::kMaxPorts); ++i) {
      s.metric("updates." + inputs_[i], static_cast<double>(total_.port_updates[i]));
      if (total_.port_dof[i] == 0) continue;
      const double dof = static_cast<double>(total_.port_dof[i]);
      const ChiSquareBand band = chi_square_mean_band(dof, kNisConfidence);
      s.metric_band("nis_mean." + inputs_[i], total_.port_nis[i] / dof, band.lo, band.hi, kNisConfidence);
    }
  }

  void check_valid(const Measurement& m, int n, bool well_formed) {
    if (m.frame != spec_.frame)
      throw DataError(who() + " takes " + to_string(spec_.frame) + " measurements, but the one at t=" +
                      std::to_string(m.time) + " s is " + to_string(m.frame) +
                      (spec_.frame == Frame::Cartesian
                           ? "; put a convert.* node between the radar and it"
                           : "; for Cartesian (converted) measurements use filter.kalman or filter.decoupled"));
    if (!well_formed)
      throw DataError(who() + ": measurement at t=" + std::to_string(m.time) + " s has " + std::to_string(n) +
                      " values and a " + std::to_string(m.covariance.rows()) + "x" +
                      std::to_string(m.covariance.cols()) + " covariance; expected " +
                      (m.has_range_rate ? "4 (with range rate)" : "3") + " values and a matching covariance");
    if (spec_.range_rate == RangeRateUse::Use && !m.has_range_rate)
      throw DataError(who() + ": range_rate: use, but the measurement at t=" + std::to_string(m.time) +
                      " s has no range rate (range_rate: auto accepts both)");
    if (!m.sensor_level && !spec_.tilted_sensors) throw DataError(who() + ": " + tilted_sensor_message(m));
    derived().check_measurement(m);
  }

  // The measurement's R (3x3 or 4x4) and the finiteness of what the update will use, as
  // fixed-size copies and checks (the items are sized at run time).
  void copy_R(const Measurement& m, int dim) {
    R_.resize(dim, dim);
    if (dim == 4)
      R_.template topLeftCorner<4, 4>() = m.covariance.template topLeftCorner<4, 4>();
    else
      R_.template topLeftCorner<3, 3>() = m.covariance.template topLeftCorner<3, 3>();
  }
  bool finite(const Measurement& m, int dim) const {
    if (m.value.size() < dim || R_.rows() < dim || R_.cols() < dim) return false;
    if (dim == 4)
      return m.value.template head<4>().allFinite() && R_.template topLeftCorner<4, 4>().allFinite();
    return m.value.template head<3>().allFinite() && R_.template topLeftCorner<3, 3>().allFinite();
  }

  int dimension(const Measurement& m) const {
    switch (spec_.range_rate) {
      case RangeRateUse::Use: return 4;
      case RangeRateUse::Auto: return m.has_range_rate ? 4 : 3;
      case RangeRateUse::Ignore: break;
    }
    return 3;
  }

  // The track's estimates carry the truth target of its first usable measurement with a known
  // origin (Detection::origin; simulations set it), which sinks score them against. A single-track
  // filter fed by several targets follows none of them: said once per run, counted, not hidden.
  void note_origin(const Detection& d, double t) {
    if (d.origin >= kOriginClutter) return;
    if (!has_origin_) {
      est_.target = d.origin;
      has_origin_ = true;
      return;
    }
    if (d.origin == est_.target) return;
    ++run_.other_target;
    if (!other_target_reported_)
      warn("the measurement at t=" + std::to_string(t) + " s comes from truth target " + std::to_string(d.origin) +
           ", this track's first from target " + std::to_string(est_.target) +
           ": one filter node follows one target, so its estimates are scored against target " +
           std::to_string(est_.target) + "; further ones are counted as other_target_measurements");
    other_target_reported_ = true;
  }
  void note_origin(const Measurement& m) { note_origin(m, m.time); }

  void clear_innovation() {
    est_.updated = false;
    est_.innovation.resize(0);
    est_.innovation_covariance.resize(0, 0);
    est_.nis = 0.0;
  }

  // Publishes the state, unless it came out non-finite (a division by ~0, an overflow): then the
  // step is refused -- counted, reported with the node and time -- and the track restarts, so
  // no NaN or infinity ever leaves a filter. Returns whether it published the state. The
  // published state and covariance are formed only when something sees them (a filter node
  // without consumers and adapters forms nothing, so there is nothing to check either); the
  // filter's own state is the same either way.
  bool publish_state(const Measurement& m) {
    est_.time = m.time;
    est_.initialised = true;
    if (!observed()) {
      publish(m, est_);
      return true;
    }
    derived().fill_estimate(est_);
    if (finite(est_)) {
      publish(m, est_);
      return true;
    }
    ++run_.refused_non_finite;
    if (!refusal_reported_)
      warn("the state at t=" + std::to_string(m.time) +
           " s came out non-finite (NaN or infinity); the step is refused and the track restarted; further ones are "
           "counted as non_finite_state_refused");
    refusal_reported_ = true;
    initialised_ = derived().reset_track();
    clear_innovation();
    set_uninitialised(est_, m.time);
    publish(m, est_);
    return false;
  }

  // One sum per block: NaN or infinity anywhere makes it non-finite (so does a sum beyond 1e308,
  // which is no usable state either). Cheaper than an element-wise test on the hot path.
  static bool finite(const Estimate& e) {
    return std::isfinite(e.state.sum() + e.covariance.sum() + e.enu.sum() + e.enu_covariance.sum() + e.nis +
                         e.innovation.sum() + e.innovation_covariance.sum());
  }

  FrontEndSpec spec_;
  Diagnostics* diag_ = nullptr;
  double time_ = 0.0;
  bool has_time_ = false, initialised_ = false, non_finite_reported_ = false, refusal_reported_ = false;
  bool has_origin_ = false, other_target_reported_ = false;
  FrontEndRunResult run_, total_;
  std::vector<std::string> inputs_;  // upstream node of each input port
  mutable Estimate scratch_;  // read_covariance's, so the published estimate is never touched
};

}  // namespace trackflow
