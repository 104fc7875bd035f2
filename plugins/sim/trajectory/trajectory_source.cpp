// Purpose: sim.trajectory — a truth generator that flies a list of CV / CA / turn / velocity-change segments exactly.
#include "flight_plan.hpp"

#include <trackflow/plugin.hpp>

#include <cmath>
#include <limits>
#include <numbers>

namespace trackflow {
namespace {

using sim::MotionPiece;

// Boundary times are sums of durations and may differ from k / rate by rounding; a sample
// this close to a velocity change counts as at it (and the last sample as at the end).
constexpr double kTimeTolerance = 1e-9;  // s

class TrajectorySource final : public Generator {
 public:
  explicit TrajectorySource(const Params& params)
      : pieces_(sim::build_flight_plan(params)),
        rate_(params.real("rate")),
        start_(params.real("start_time")) {
    truth_.target = static_cast<std::uint32_t>(params.integer("target"));
    const double span = (pieces_.back().end - start_) * rate_;
    if (span > 1e10) throw params.error("rate", "gives more than 1e10 samples over the trajectory; lower it");
    sample_count_ = static_cast<long long>(std::floor(span + kTimeTolerance * rate_)) + 1;
  }

  void start_run(const RunContext&) override {
    next_sample_ = 0;
    piece_ = 0;
  }

  double next_time() const override {
    return next_sample_ < sample_count_ ? sample_time(next_sample_) : std::numeric_limits<double>::infinity();
  }

  void emit_next() override {
    const double t = sample_time(next_sample_++);
    // Samples only move forward, so the current piece only moves forward too.
    while (piece_ + 1 < pieces_.size() && pieces_[piece_ + 1].start <= t + kTimeTolerance) ++piece_;
    const sim::Kinematics k = sim::evaluate(pieces_[piece_], t);
    truth_.time = t;
    truth_.position = k.position;
    truth_.velocity = k.velocity;
    truth_.acceleration = k.acceleration;
    out.emit(truth_);
  }

 private:
  // Computed, not accumulated, so times are exact multiples of the period whatever the run length.
  double sample_time(long long k) const { return start_ + static_cast<double>(k) / rate_; }

  std::vector<MotionPiece> pieces_;
  double rate_, start_;
  long long sample_count_ = 0;
  long long next_sample_ = 0;
  size_t piece_ = 0;
  Truth truth_;
};

std::vector<ParamSpec> segment_fields() {
  return {
      ParamSpec::choice("type", {"constant_velocity", "constant_acceleration", "turn", "velocity_change"},
                        "kind of motion over this segment")
          .req(),
      ParamSpec::real("duration", dim::time, "length of the segment (all types except velocity_change, which is instantaneous)")
          .positive(),
      ParamSpec::real_list("acceleration", dim::acceleration, "constant_acceleration: ENU acceleration [ax, ay, az]", 3),
      ParamSpec::real("turn_rate", dim::angular_rate,
                      "turn: horizontal turn rate about the vertical, + = counter-clockwise from above, a left turn (radius v/rate)"),
      ParamSpec::real_list("velocity", dim::velocity, "velocity_change: new ENU velocity [vx, vy, vz]", 3),
      ParamSpec::real("speed", dim::velocity, "velocity_change: new speed (default: keep)").at_least(0),
      ParamSpec::real("heading", dim::angle, "velocity_change: compass heading, from north clockwise (default: keep)"),
      ParamSpec::real("climb", dim::angle, "velocity_change: flight-path angle above the horizontal (default: keep)")
          .at_least(-std::numbers::pi / 2)
          .at_most(std::numbers::pi / 2),
  };
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sim.trajectory";
  d.kind = ComponentKind::Source;
  d.summary = "Simulated target truth (ENU) flying constant-velocity, constant-acceleration, turn and velocity-change segments";
  d.doc = "Each segment is propagated in closed form from where the previous one ended (no numerical integration). "
          "A turn is a horizontal coordinated turn at constant rate that keeps the vertical velocity. A "
          "velocity_change is instantaneous: a sample at its time already shows the new velocity. Truth "
          "(position, velocity, acceleration) is emitted at start_time + k/rate up to and including the end of the "
          "last segment. Example (paper 002, circle R = 1500 m at 200 m/s): initial_position: [0, 0, 150 m], "
          "initial_velocity: [200 m/s, 0, 0], segments: [{type: turn, turn_rate: 0.13333 rad/s, duration: 47.124 s}].";
  d.params = {
      ParamSpec::real("rate", dim::frequency, "sample rate of the truth").def("10 Hz").positive(),
      ParamSpec::real("start_time", dim::time, "time of the first sample and of the start of the first segment").def("0 s"),
      ParamSpec::real_list("initial_position", dim::length, "ENU position at start_time [x east, y north, z up]", 3).req(),
      ParamSpec::real_list("initial_velocity", dim::velocity, "ENU velocity at start_time", 3).def("[0, 0, 0]"),
      ParamSpec::integer("target", "target id written into each Truth item").def("0").at_least(0).at_most(4294967295.0),
      ParamSpec::records("segments", segment_fields(), "the flight, in order (at least one)").req(),
  };
  d.accepts = 0;
  d.min_inputs = 0;
  d.max_inputs = 0;
  d.produces = mask(ItemKind::Truth);
  d.create = [](const Params& p) { return std::make_unique<TrajectorySource>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sim.trajectory", trackflow::register_components)
