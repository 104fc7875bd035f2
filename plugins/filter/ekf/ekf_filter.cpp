// Purpose: filter.ekf — extended Kalman filter with a Cartesian ENU state (CV, CA or Singer motion) on spherical [r, az, el(, rdot)] or 2-D radar [r, az(, rdot)] measurements.
#include "estimation/cartesian_radar_estimator.hpp"
#include "estimation/ekf_polar_update.hpp"
#include "estimation/ekf_radar_update.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/single_track_filter.hpp>

#include <string>

namespace trackflow {
namespace {

// Settings, measurement checks, initialisation, prediction and publishing: cartesian_radar_estimator.hpp.
// This class is the EKF update: h linearised at the predicted state.
template <int Order>
class ExtendedKalmanFilter final
    : public cartesian_filter::CartesianRadarEstimator<Order, ExtendedKalmanFilter<Order>> {
  using Base = cartesian_filter::CartesianRadarEstimator<Order, ExtendedKalmanFilter<Order>>;
  friend Base;
  using Base::N;
  using Base::x_;
  using Base::P_;
  using Base::R_;
  using Base::idx_;
  using Layout = typename Base::Layout;

 public:
  explicit ExtendedKalmanFilter(cartesian_filter::Settings s) : Base(std::move(s)) {}

  static std::vector<std::string> counter_names() { return {"azimuth_dropped", "azimuth_deweighted"}; }
  static constexpr FrameMask kFrames = mask(Frame::Spherical) | mask(Frame::Polar);

  // The update's own linearisation with z = 0 (nu = -h, the zenith conditioning included), so a
  // tracker's gate sees exactly the S the update will use: what Estimator::predicted_by_update
  // gives, without copying the estimator (which allocates) per track and scan.
  bool predict_measurement(const SensorFrame& s, const MeasCov& R, PredictedMeasurement& p) const override {
    const int dim = static_cast<int>(R.rows());
    const int positions = position_values(s.frame);
    if (!(kFrames & mask(s.frame)) || R.cols() != dim || (dim != positions && dim != positions + 1)) return false;
    Measurement m;
    static_cast<SensorFrame&>(m) = s;
    m.time = this->time();
    m.has_range_rate = dim == positions + 1;
    m.value = MeasVec::Zero(dim);
    m.covariance = R;
    if (s.frame == Frame::Polar) return dim == 3 ? predicted<3, true>(m, R, p) : predicted<2, true>(m, R, p);
    return dim == 4 ? predicted<4, false>(m, R, p) : predicted<3, false>(m, R, p);
  }

 private:
  enum Counter { kAzimuthDropped, kAzimuthDeweighted };

  void on_start_run() {
    zenith_reported_ = false;
    relinearised_ = updates_ = 0;
  }
  // Counted per run and reported once at its end rather than at every step.
  void on_end_run_report() {
    if (relinearised_ > 0) this->warn(cartesian_filter::relinearised_text(relinearised_, updates_));
  }

  // The update itself is shared with filter.imm's modes (ekf_radar_update.hpp); this is its
  // reporting: counts, and warnings once per run.
  template <int M>
  bool correct(const Measurement& m) {
    cartesian_filter::EkfInnovation<M> in;
    const bool curvature = this->settings().zenith == cartesian_filter::Settings::Zenith::Curvature;
    const cartesian_filter::EkfOutcome outcome = cartesian_filter::ekf_radar_update<N, M>(
        x_, P_, idx_, m, Eigen::Matrix<double, M, M>(R_.template topLeftCorner<M, M>()), curvature, in);
    return report<M>(m, outcome, in);
  }
  // A 2-D radar's [r, az(, rdot)]: M = 2 or 3 (ekf_polar_update.hpp).
  template <int M>
  bool correct_polar(const Measurement& m) {
    cartesian_filter::EkfInnovation<M> in;
    const cartesian_filter::EkfOutcome outcome = cartesian_filter::ekf_polar_update<N, M>(
        x_, P_, idx_, m, Eigen::Matrix<double, M, M>(R_.template topLeftCorner<M, M>()), in);
    return report<M>(m, outcome, in);
  }
  template <int M, bool Polar>
  bool predicted(const Measurement& m, const MeasCov& R, PredictedMeasurement& p) const {
    cartesian_filter::EkfInnovation<M> in;
    Eigen::Matrix<double, N, M> PHt;
    const Eigen::Matrix<double, M, M> Rm = R.template topLeftCorner<M, M>();
    const bool curvature = this->settings().zenith == cartesian_filter::Settings::Zenith::Curvature;
    cartesian_filter::EkfOutcome outcome;
    if constexpr (Polar)
      outcome = cartesian_filter::ekf_polar_linearise<N, M>(x_, P_, idx_, m, Rm, in, PHt);
    else
      outcome = cartesian_filter::ekf_radar_linearise<N, M>(x_, P_, idx_, m, Rm, curvature, in, PHt);
    if (outcome != cartesian_filter::EkfOutcome::Used) return false;
    p.z = -in.nu;
    wrap_residual(m.frame, p.z);
    p.S = in.S;
    for (int i = 0; i < M; ++i)
      for (int j = i + 1; j < M; ++j) p.S(i, j) = p.S(j, i);  // the lower triangle mirrored, as the update does
    return set_log_det(p);
  }

  template <int M>
  bool report(const Measurement& m, cartesian_filter::EkfOutcome outcome, const cartesian_filter::EkfInnovation<M>& in) {
    if (outcome == cartesian_filter::EkfOutcome::AtSensor) {
      this->warn("predicted position at the sensor at t=" + std::to_string(m.time) +
                 " s: no direction to linearise about; measurement not used");
      return false;
    }
    ++updates_;
    if (in.relinearised) ++relinearised_;
    if (in.azimuth_dropped) this->count(kAzimuthDropped);
    if (in.azimuth_deweighted) this->count(kAzimuthDeweighted);
    if (!zenith_reported_ && (in.azimuth_dropped || in.azimuth_deweighted)) {
      this->warn("target near the zenith at t=" + std::to_string(m.time) + " s: azimuth " +
                 (in.azimuth_dropped ? "not used" : "de-weighted") +
                 " (its linearisation fails over the predicted uncertainty); counted in the summary, reported once "
                 "per run");
      zenith_reported_ = true;
    }
    if (outcome == cartesian_filter::EkfOutcome::Used) {
      this->template accept_update<M>(in.nu, in.S, in.nis);
      return true;
    }
    this->warn("innovation covariance not positive definite at t=" + std::to_string(m.time) +
               " s; measurement not used");
    return false;
  }

  bool zenith_reported_ = false;
  int relinearised_ = 0, updates_ = 0;
};

cartesian_filter::Settings settings(const Params& p) {
  cartesian_filter::Settings s = cartesian_filter::parse_settings(p, "filter.ekf");
  s.zenith = p.choice<cartesian_filter::Settings::Zenith>("zenith");
  return s;
}

std::unique_ptr<Component> create(const Params& p) {
  const cartesian_filter::Settings s = settings(p);
  if (s.order() == 2) return make_single_track_filter(s.type, s.node, ExtendedKalmanFilter<2>(s));
  return make_single_track_filter(s.type, s.node, ExtendedKalmanFilter<3>(s));
}

std::unique_ptr<Estimator> create_estimator(const Params& p) {
  const cartesian_filter::Settings s = settings(p);
  if (s.order() == 2) return std::make_unique<ExtendedKalmanFilter<2>>(s);
  return std::make_unique<ExtendedKalmanFilter<3>>(s);
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.ekf";
  d.kind = ComponentKind::Filter;
  d.summary = "Extended Kalman filter: Cartesian ENU state (CV, CA or Singer) on spherical [r, az, el(, rdot)] "
              "or 2-D radar [r, az(, rdot)] measurements";
  d.doc =
      "State [x vx (ax) y vy (ay) z vz (az)] in ENU; linear prediction, measurement h(x) = [r, az, el(, rdot)] "
      "relative to the (stationary) sensor in its azimuth convention, analytic Jacobian (paper 000 eq 3.22-3.24, "
      "corrected), azimuth innovation wrapped to (-pi, pi], Joseph-form update. Motion: CV (white acceleration, q), "
      "CA (Wiener-process acceleration, q_jerk, paper 000 eq 3.19), sigma_accel for the discrete white-noise "
      "variants, or Singer (alpha, sigma_m; exact discretisation). Near the zenith the angles' curvature variance is "
      "added to R and the azimuth is dropped while the zenith is within 3 sigma (zenith: curvature; zenith: textbook "
      "is the plain EKF); dropped and de-weighted azimuths are counted in the summary. With zenith: curvature, a "
      "prediction whose horizontal variance exceeds 100 times the measurement's (a huge q) and on which either rule "
      "acts is updated by the iterated EKF about the measured position instead (reported at the end of the run). Invalid measurements: predict "
      "only. "
      "R from each measurement in spherical space (adapters may replace it; q per ENU axis). A 2-D surveillance "
      "radar's polar [r, az(, rdot)] measurements: h is the same model's range, azimuth (and range-rate) rows; a "
      "track started from polar points lies in the radar's horizontal plane (z at the radar's height with zero "
      "variance, no z process noise: the predicted range is the ground range); no curvature conditioning, the "
      "azimuth is dropped only straight above the radar; level radars only."
      " Several inputs (up to 8 radars, each at its own site with its own noise, rate and biases): the measurements are used one after another in time order, equal time stamps in the engine's delivery order (the order of the radars' declaration when they share a truth source); a tilted sensor (a geodetic site away from the frame's origin) is measured in its own axes; the summary then gives updates.<input> and nis_mean.<input> (mean NIS per element with its 95 % chi-square band) per sensor. See docs/filters.md.";
  d.accepts = mask(ItemKind::Measurement);
  // Several radars into one track: one input per sensor (docs/filters.md, "Several sensors").
  d.min_inputs = 1;
  d.max_inputs = SingleTrackRunResult::kMaxPorts;
  d.produces = mask(ItemKind::Estimate);
  d.accepts_frames = mask(Frame::Spherical) | mask(Frame::Polar);
  d.params = cartesian_filter::param_specs();
  d.params.push_back(cartesian_filter::zenith_param());
  d.create = create;
  d.create_estimator = create_estimator;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.ekf", trackflow::register_components)
