// Purpose: the per-track estimator contract — initiate from detections, predict, predict the measurement (z, S, log det S) without updating, update, fill an Estimate, name the state, expose the noise, clone — that single-track filter nodes and trackers run.
#pragma once

#include <trackflow/common_params.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/items.hpp>
#include <trackflow/noise.hpp>
#include <trackflow/transition_model.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace trackflow {

struct Summary;

// What an estimator measures with; the host checks each detection against it before the
// estimator sees one (frame, number of values, range rate, a tilted sensor).
struct MeasurementSpec {
  // The frames it takes (a mask of Frame bits, e.g. Spherical | Polar): a detection of another
  // frame is refused before the estimator sees it.
  FrameMask frames = mask(Frame::Spherical);
  // Spherical estimators: use the range rate when present (Auto), always (Use) or never (Ignore).
  // Cartesian estimators take the three position values: Ignore.
  RangeRateUse range_rate = RangeRateUse::Ignore;
  // Estimator-specific events counted per run and reported in the summary (Estimator::count).
  std::vector<std::string> counters;
  // Whether the measurement function turns into the sensor's own axes (SensorFrame::sensor_axes);
  // otherwise a tilted sensor's detection is refused before the estimator sees it.
  bool tilted_sensors = false;
};

// The track an estimator runs for, implemented by whoever runs it (a single-track filter node, a
// tracker's track): where its warnings, counts and annotations go, the time of the detection being
// processed, and the estimate that receives an accepted update's innovation.
class TrackContext {
 public:
  virtual void warn(const std::string& message) = 0;
  virtual void count(int counter) = 0;
  virtual void annotate(int index, double value) = 0;
  double time = 0.0;
  Estimate* estimate = nullptr;
  std::string who;  // "filter.kalman (node 'kf')", for messages

 protected:
  // Declared so that a derived context (a tracker's track slot) moves without copying `who`: a
  // user-declared destructor alone would suppress the implicit moves.
  TrackContext() = default;
  TrackContext(const TrackContext&) = default;
  TrackContext(TrackContext&&) noexcept = default;
  TrackContext& operator=(const TrackContext&) = default;
  TrackContext& operator=(TrackContext&&) noexcept = default;
  ~TrackContext() = default;
};

// A track's predicted measurement for a sensor: z^, S = H P H' + R and log det S, for gating and
// likelihoods. An angle in z^ lies in (-pi, pi]; a residual against it is wrapped by whoever forms it.
struct PredictedMeasurement {
  MeasVec z;
  MeasCov S;
  double log_det_S = 0.0;
};

// Sets p.log_det_S from p.S by Cholesky; false (and log_det_S = NaN) when S is not positive definite.
inline bool set_log_det(PredictedMeasurement& p) {
  const Eigen::LLT<MeasCov> llt(p.S);
  if (llt.info() != Eigen::Success) {
    p.log_det_S = std::numeric_limits<double>::quiet_NaN();
    return false;
  }
  p.log_det_S = 2.0 * llt.matrixLLT().diagonal().array().log().sum();
  return std::isfinite(p.log_det_S);
}

// One track's state estimator. The host calls reset() at the start of each run (and when the
// track restarts), initiate() with usable measurements until it returns true, then predict(T)
// (T > 0 s) and update() per measurement, fill() when the estimate is published. A measurement is
// one detection with its sensor frame and time (items.hpp); a tracker assembles one per detection
// it assigns. Measurements reach the estimator valid, finite, in one of its frames and of the
// declared dimension `dim` (position_values(frame): 3, or 2 for Polar and Planar; one more with
// range rate); R_ holds the detection's covariance, or what an adapter put there. A concrete estimator should be `final`: the single-track node then calls it without a
// virtual call.
class Estimator {
 public:
  virtual ~Estimator() = default;

  virtual bool reset() = 0;  // true: initialised at once (explicit initial state)
  virtual bool initiate(const Measurement& m, int dim) = 0;
  virtual void predict(double T) = 0;
  // The predicted measurement from the current (predicted) state for a detection of sensor `s`
  // with noise R (its size is the measurement dimension); false when there is none (a predicted
  // position at the sensor). Changes nothing.
  virtual bool predict_measurement(const SensorFrame& s, const MeasCov& R, PredictedMeasurement& p) const = 0;
  // On success call accept_update(); false: the measurement is not used (warn() why).
  virtual bool update(const Measurement& m, int dim) = 0;
  // State, covariance (layout() order) and the ENU position/velocity block.
  virtual void fill(Estimate& e) const = 0;
  virtual void scale_covariance(double k) = 0;  // P <- k P in the estimator's own representation
  virtual StateLayout layout() const = 0;
  // The noise adapters may read and overwrite (noise.hpp), this track's own.
  virtual NoiseHandles noise() = 0;
  // A copy of this track's estimator, state included (a tracker starts tracks from a prototype);
  // it reports to the same TrackContext until bind() gives it its own.
  virtual std::unique_ptr<Estimator> clone() const = 0;

  // Optional: further checks of a valid measurement (throw DataError), names of values the
  // estimator annotates its estimates with (set by annotate()), a report at the end of each run
  // (`initialised`: whether the track was), notes for the summary.
  virtual void check(const Measurement&) {}
  virtual std::vector<std::string> annotation_names() const { return {}; }
  virtual void end_run(bool /*initialised*/) {}
  virtual void finish(Summary&) const {}
  // Optional: replace the state and covariance (layout() order, sizes layout().dim), e.g. with an
  // IMM's mixed start, keeping everything else (motion model, noise, initialisation). false: this
  // estimator cannot take a state from outside (it cannot be a filter.imm mode); nothing changed.
  virtual bool assign(const StateVec& /*x*/, const StateCov& /*P*/) { return false; }
  // Optional: the kinematic model the estimator predicts with, as configured (Filter::transition_model).
  virtual const TransitionModel* transition_model() const { return nullptr; }
  // Optional: a one-point start (after reset()) — position and its covariance from m alone, velocity
  // 0 with standard deviation velocity_sigma per axis (an initiator's prior bounded by a maximum
  // speed), higher derivatives 0 with the estimator's own initial sigmas. starts_from_one_point()
  // says whether it can; false from initiate_one_point: not started (warn() why).
  virtual bool starts_from_one_point() const { return false; }
  virtual bool initiate_one_point(const Measurement& /*m*/, int /*dim*/, double /*velocity_sigma*/) { return false; }

  // Optional: the combined update of probabilistic data association (PDA, JPDA): detections[k] is
  // this track's with probability probability[k], none of them with probability `none` (the sum
  // is 1; each detection valid, of this estimator's frame and of dimension dim). The posterior is the
  // mixture of the predicted state (weight `none`) and of the updates with each detection, matched
  // in its first two moments (Bar-Shalom, Willett & Tian 2011, "Tracking and Data Fusion", eq.
  // 3.4.2-1 to 3.4.2-4 for the PDA; for an update whose gain does not depend on z — Kalman, EKF
  // linearised at the prediction, UKF — that mixture is exactly the PDA's x = x^ + K nu_bar,
  // P = none P^ + (1 - none) P_upd + K (sum_k b_k nu_k nu_k' - nu_bar nu_bar') K'). The default,
  // combined_by_moments, runs update() per detection from the predicted state (restored by assign())
  // and combines; an estimator that can take it says so in takes_weighted_updates(), and one with
  // modes of its own (an IMM) overrides update_weighted. false: no detection could be used (the
  // state is the prediction; warn() why).
  virtual bool takes_weighted_updates() const { return false; }
  virtual bool update_weighted(std::span<const Measurement> detections, std::span<const double> probability, double none,
                               int dim) {
    return combined_by_moments(detections, probability, none, dim);
  }

  // Optional: make this estimator a copy of `other` (the same concrete type, state included) in
  // place, without allocating — a tracker that branches tracks (tracker.tomht) reuses its spare
  // estimators instead of cloning one per branch. Binding (bind()) stays this estimator's. false:
  // another type, or this estimator cannot; the caller clones instead.
  virtual bool copy_from(const Estimator& /*other*/) { return false; }

  const MeasurementSpec& measurement_spec() const { return spec_; }
  void bind(TrackContext& track) { track_ = &track; }
  MeasCov& measurement_noise() { return R_; }

 protected:
  explicit Estimator(MeasurementSpec spec) : spec_(std::move(spec)) { R_ = MeasCov::Zero(3, 3); }
  Estimator(const Estimator&) = default;
  Estimator& operator=(const Estimator&) = default;

  void warn(const std::string& message) const {
    if (track_) track_->warn(message);
  }
  void count(int counter) const {
    if (track_) track_->count(counter);
  }
  void annotate(int index, double value) const {
    if (track_) track_->annotate(index, value);
  }
  double time() const { return track_ ? track_->time : 0.0; }
  std::string who() const { return track_ ? track_->who : std::string("estimator"); }
  // Whether the interval T to this measurement equals `last_T` to the precision of the time
  // stamps (4 ulps of the current time), so that a motion model computed for last_T may be used
  // again. Fixed-rate data are stamped t0 + k / rate, rounded: their intervals differ in the last
  // bits (by up to ~5e-12 of a 25 ms interval after 540 s), which no model can resolve, and
  // comparing them exactly would recompute F and Q at nearly every step.
  bool same_interval(double T, double last_T) const {
    return std::fabs(T - last_T) <= 4.0 * std::numeric_limits<double>::epsilon() * std::fabs(time());
  }
  // The innovation, its covariance and NIS of an accepted update, onto the track's estimate.
  template <int M>
  void accept_update(const Eigen::Matrix<double, M, 1>& nu, const Eigen::Matrix<double, M, M>& S, double nis) {
    if (!track_ || !track_->estimate) return;
    Estimate& e = *track_->estimate;
    e.updated = true;
    e.innovation.resize(M);
    e.innovation.template head<M>() = nu;
    e.innovation_covariance.resize(M, M);
    e.innovation_covariance.template topLeftCorner<M, M>() = S;
    e.nis = nis;
  }

  // The predicted measurement of an estimator whose update reports its innovation (Self: the
  // concrete estimator): an update of a copy with z = 0 gives nu = -h(x) (the azimuth wrapped)
  // and S. Exact where S does not depend on z (linear and linearised updates, the unscented
  // transform of h); it costs a copy and one update. The copy's warnings and counts go nowhere.
  template <class Self>
  bool predicted_by_update(const SensorFrame& s, const MeasCov& R, PredictedMeasurement& p) const {
    struct Capture final : TrackContext {
      void warn(const std::string&) override {}
      void count(int) override {}
      void annotate(int, double) override {}
    } capture;
    Estimate innovation;
    capture.time = time();
    capture.estimate = &innovation;
    capture.who = who();
    Self copy(static_cast<const Self&>(*this));
    copy.bind(capture);
    const int dim = static_cast<int>(R.rows());
    Measurement m;
    static_cast<SensorFrame&>(m) = s;
    m.time = time();
    m.has_range_rate = dim == position_values(s.frame) + 1;
    m.value = MeasVec::Zero(dim);
    m.covariance = R;
    copy.measurement_noise() = R;
    if (!static_cast<Estimator&>(copy).update(m, dim) || !innovation.updated || innovation.innovation.size() != dim) return false;
    p.z = -innovation.innovation;
    wrap_residual(s.frame, p.z);
    p.S = innovation.innovation_covariance;
    return set_log_det(p);
  }

  // copy_from by the concrete type's copy assignment (Self: the concrete estimator, whose members
  // copy into storage of the same size without allocating: fixed-size Eigen, strings and lists
  // of the same configuration); the track binding is kept.
  template <class Self>
  bool copy_by_assignment(const Estimator& other) {
    const auto* o = dynamic_cast<const Self*>(&other);
    if (!o) return false;
    TrackContext* const keep = track_;
    static_cast<Self&>(*this) = *o;
    track_ = keep;
    return true;
  }

  // The moment-matched mixture of update_weighted through this estimator's own update() and
  // assign(): from the predicted x^, P^ (fill()), each detection k with probability b_k > 0 gives
  // x_k, P_k (update, fill, then assign(x^, P^) back); the posterior is
  //   x = x^ + d,  d = sum_k b_k (x_k - x^),  P = none P^ + sum_k b_k (P_k + (x_k - x^)(x_k - x^)') - d d'
  // (deviations from x^, so the sums do not cancel), symmetrised. A detection the update refuses
  // loses its weight (the rest renormalised). The published innovation is nu_bar = sum_k b_k nu_k
  // with the first used detection's S, NIS = nu_bar' S^-1 nu_bar. Stack storage only (StateVec,
  // StateCov are bounded): nothing is allocated.
  bool combined_by_moments(std::span<const Measurement> detections, std::span<const double> probability, double none,
                           int dim) {
    Estimate predicted, updated;
    fill(predicted);
    const StateVec x0 = predicted.state;
    const StateCov P0 = predicted.covariance;
    const int n = static_cast<int>(x0.size());
    StateVec d = StateVec::Zero(n);
    StateCov M = StateCov::Zero(n, n);
    double weight = 0.0;
    MeasVec nu_bar;
    MeasCov S;
    bool have_innovation = false;
    Estimate* published = track_ ? track_->estimate : nullptr;
    for (std::size_t k = 0; k < detections.size() && k < probability.size(); ++k) {
      const double b = probability[k];
      if (!(b > 0.0)) continue;
      if (weight > 0.0 && !assign(x0, P0)) return false;  // the predicted state again (takes_weighted_updates: it can)
      R_ = detections[k].covariance.topLeftCorner(dim, dim);
      if (published) published->updated = false;
      if (!update(detections[k], dim)) continue;
      fill(updated);
      const StateVec dx = updated.state - x0;
      d += b * dx;
      M += b * (updated.covariance + dx * dx.transpose());
      weight += b;
      if (published && published->updated && published->innovation.size() == dim) {
        if (!have_innovation) {
          nu_bar = MeasVec::Zero(dim);
          S = published->innovation_covariance;
          have_innovation = true;
        }
        nu_bar += b * published->innovation;
      }
    }
    if (!(weight > 0.0)) {
      if (published) published->updated = false;
      return false;  // nothing used: the state stays the prediction (assign restored it, or no update ran)
    }
    // Renormalised over what was used: none keeps its share of the total.
    const double total = none + weight;
    d /= total;
    M /= total;
    nu_bar /= total;
    const double w0 = none / total;
    StateCov P = w0 * P0 + M - d * d.transpose();
    P = 0.5 * (P + P.transpose());
    const StateVec x = x0 + d;
    if (!assign(x, P)) return false;
    if (published && have_innovation) {
      published->updated = true;
      published->innovation = nu_bar;
      published->innovation_covariance = S;
      const Eigen::LLT<MeasCov> llt(S);
      published->nis = llt.info() == Eigen::Success ? llt.matrixL().solve(nu_bar).squaredNorm() : 0.0;
    }
    return true;
  }

  MeasCov R_;  // this update's measurement noise, exposed to adapters through noise()

 private:
  MeasurementSpec spec_;
  TrackContext* track_ = nullptr;
};

}  // namespace trackflow
