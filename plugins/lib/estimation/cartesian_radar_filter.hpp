// Purpose: the Cartesian-state radar filters' common part (filter.ekf, filter.ukf): the Cartesian radar state (cartesian_radar_state.hpp) on the SDK front end, with its noise handles; the derived filter supplies the update.
#pragma once

#include "cartesian_filter_settings.hpp"
#include "cartesian_radar_state.hpp"

#include <trackflow/filter_front_end.hpp>
#include <trackflow/error.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/motion.hpp>

#include <Eigen/Core>

#include <string>
#include <utility>

namespace trackflow::cartesian_filter {

// A Cartesian radar state (cartesian_radar_state.hpp) behind the SDK's measurement front end
// (filter_front_end.hpp).
// Derived (CRTP) provides
//   static std::vector<std::string> counter_names();   its counted events (count(i))
//   void on_start_run();  void on_end_run_report();    its own per-run state and reports
//   template <int M> bool correct(const Measurement&); M = 3 or 4: correct x_ and P_ with the
//       measurement's first M values and R_.topLeftCorner(M, M); call accept_update() on success.
template <int Order, class Derived>
class CartesianRadarFilter : public FilterFrontEnd<CartesianRadarFilter<Order, Derived>>,
                             protected CartesianRadarState<Order> {
  using State = CartesianRadarState<Order>;
  using FrontEnd = FilterFrontEnd<CartesianRadarFilter<Order, Derived>>;
  friend FrontEnd;

 public:
  using typename State::Layout;
  using State::N;
  using typename State::StateN;
  using typename State::MatN;

  NoiseHandles noise() override {
    NoiseHandles h;
    h.measurement = {&this->R_, MeasurementSpace::Spherical};
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

  StateLayout state_layout() const override { return Layout::state_layout(); }

 protected:
  explicit CartesianRadarFilter(Settings s)
      : FrontEnd(FrontEndSpec{s.type, s.node, Frame::Spherical, s.range_rate, derived_counters(), true}), State(s) {
    this->est_.state.resize(N);
    this->est_.covariance.resize(N, N);
  }

  using State::settings;
  using State::x_;
  using State::P_;
  using State::idx_;

 private:
  Derived& derived() { return static_cast<Derived&>(*this); }
  static std::vector<std::string> derived_counters() { return Derived::counter_names(); }

  // Front-end hooks.
  bool reset_track() {
    derived().on_start_run();
    return this->reset_state();
  }

  template <int M>
  bool update(const Measurement& m) {
    return derived().template correct<M>(m);
  }

  void scale_state_covariance(double k) { P_ *= k; }

  void on_end_run() { derived().on_end_run_report(); }

  void predict(double T) { this->predict_state(T, this->same_interval(T, this->last_interval())); }
  bool initialise(const Measurement& m, int) { return this->add_point(m, this->R_); }
  void fill_estimate(Estimate& e) const { this->fill_state(e); }
};

}  // namespace trackflow::cartesian_filter
