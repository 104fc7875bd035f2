// Purpose: the Cartesian-state radar estimators' common part (filter.ekf, filter.ukf): the Cartesian radar state (cartesian_radar_state.hpp) as an SDK estimator, with its noise handles; the derived estimator supplies the update.
#pragma once

#include "cartesian_filter_settings.hpp"
#include "cartesian_radar_state.hpp"

#include <trackflow/estimator.hpp>
#include <trackflow/error.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/motion.hpp>

#include <Eigen/Core>

#include <string>
#include <utility>

namespace trackflow::cartesian_filter {

// A Cartesian radar state (cartesian_radar_state.hpp) as an SDK estimator (estimator.hpp).
// Derived (CRTP, final) provides
//   static std::vector<std::string> counter_names();   its counted events (count(i))
//   void on_start_run();  void on_end_run_report();    its own per-run state and reports
//   template <int M> bool correct(const Measurement&); M = 3 or 4: correct x_ and P_ with the
//       measurement's first M values and R_.topLeftCorner(M, M); call accept_update() on success.
//   static constexpr FrameMask kFrames;                 Spherical, and Polar if it has
//   template <int M> bool correct_polar(const Measurement&); M = 2 or 3 ([r, az(, rdot)]).
template <int Order, class Derived>
class CartesianRadarEstimator : public Estimator, protected CartesianRadarState<Order> {
  using State = CartesianRadarState<Order>;

 public:
  using typename State::Layout;
  using State::N;
  using typename State::StateN;
  using typename State::MatN;

  NoiseHandles noise() override {
    NoiseHandles h;
    h.measurement = {&R_, MeasurementSpace::Spherical};
    h.process.values = this->q_;
    h.process.count = 3;
    h.process.axes = NoiseAxes::Enu;
    switch (this->s_.noise) {
      case Settings::Noise::Continuous:
        h.process.kind = NoiseKind::SpectralDensity;
        h.process.dimension = Order == 3 ? dim::jerk_psd : dim::accel_psd;
        break;
      case Settings::Noise::Discrete:
        h.process.kind = NoiseKind::StandardDeviation;
        h.process.dimension = dim::acceleration;
        break;
      case Settings::Noise::Singer:
        h.process.kind = NoiseKind::StandardDeviation;
        h.process.dimension = dim::acceleration;
        break;
    }
    return h;
  }

  StateLayout layout() const override { return Layout::state_layout(); }
  const TransitionModel* transition_model() const override { return &this->s_; }
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<Derived>(derived()); }

  bool reset() override {
    derived().on_start_run();
    return this->reset_state();
  }
  bool update(const Measurement& m, int dim) override {
    if constexpr ((Derived::kFrames & mask(Frame::Polar)) != 0) {
      if (m.frame == Frame::Polar)
        return dim == 3 ? derived().template correct_polar<3>(m) : derived().template correct_polar<2>(m);
    }
    return dim == 4 ? derived().template correct<4>(m) : derived().template correct<3>(m);
  }
  // A 2-D radar's track lies in its horizontal plane (cartesian_radar_state.hpp): a tilted one has
  // no such plane in the frame.
  void check(const Measurement& m) override {
    if (m.frame == Frame::Polar && !m.sensor_level)
      throw DataError(this->who() + ": " + tilted_sensor_message(m) +
                      " (a 2-D radar's targets are placed in its horizontal plane, which must be the frame's)");
  }
  bool predict_measurement(const SensorFrame& s, const MeasCov& R, PredictedMeasurement& p) const override {
    return predicted_by_update<Derived>(s, R, p);
  }
  void scale_covariance(double k) override { P_ *= k; }
  void end_run(bool) override { derived().on_end_run_report(); }
  void predict(double T) override { this->predict_state(T, same_interval(T, this->last_interval())); }
  bool initiate(const Measurement& m, int) override { return this->add_point(m, R_); }
  bool starts_from_one_point() const override { return true; }
  bool initiate_one_point(const Measurement& m, int, double velocity_sigma) override {
    return this->start_at_rest(m, R_, velocity_sigma);
  }
  void fill(Estimate& e) const override { this->fill_state(e); }
  bool assign(const StateVec& x, const StateCov& P) override {
    if (x.size() != N || P.rows() != N || P.cols() != N) return false;
    x_ = x.template head<N>();
    P_ = P.template topLeftCorner<N, N>();
    return true;
  }
  bool takes_weighted_updates() const override { return true; }
  bool copy_from(const Estimator& other) override { return this->template copy_by_assignment<Derived>(other); }

 protected:
  explicit CartesianRadarEstimator(Settings s)
      : Estimator(MeasurementSpec{Derived::kFrames, s.range_rate, Derived::counter_names(), true}), State(s) {}

  using State::settings;
  using State::x_;
  using State::P_;
  using State::idx_;

 private:
  Derived& derived() { return static_cast<Derived&>(*this); }
  const Derived& derived() const { return static_cast<const Derived&>(*this); }
};

}  // namespace trackflow::cartesian_filter
