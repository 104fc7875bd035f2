// Purpose: sim.trajectory — a truth generator that flies CV / CA / turn / velocity-change segments or a launch profile exactly, optionally with white-noise acceleration or jerk.
#include "flight_plan.hpp"
#include "geodetic_launch.hpp"
#include "jettison.hpp"
#include "launch_profile.hpp"
#include "process_noise.hpp"

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

// Segments, or the profile on a flat, spherical or WGS-84 earth. pad_site belongs to the last only.
std::vector<MotionPiece> build_pieces(const Params& params) {
  const bool wgs84 = params.choice<sim::Earth>("earth") == sim::Earth::Wgs84;
  if (params.given("pad_site") && !(wgs84 && params.choice<sim::Profile>("profile") != sim::Profile::None))
    throw params.error("pad_site", "applies to a launch profile on 'earth: wgs84' only (flat and spherical earths take "
                                   "pad_position)");
  if (params.choice<sim::Profile>("profile") == sim::Profile::None) return sim::apply_jettison(params, sim::build_flight_plan(params));
  return sim::apply_jettison(params, wgs84 ? sim::build_geodetic_launch_plan(params) : sim::build_launch_plan(params));
}

class TrajectorySource final : public Generator {
 public:
  explicit TrajectorySource(const Params& params)
      : pieces_(build_pieces(params)),
        rate_(params.real("rate")),
        start_(params.real("start_time")),
        noise_(sim::process_noise_q(params), 1.0 / rate_),
        jerk_(sim::process_noise_q_jerk(params), 1.0 / rate_) {
    truth_.target = static_cast<std::uint32_t>(params.integer("target"));
    const double span = (pieces_.back().end - start_) * rate_;
    if (span > 1e10) throw params.error("rate", "gives more than 1e10 samples over the trajectory; lower it");
    sample_count_ = static_cast<long long>(std::floor(span + kTimeTolerance * rate_)) + 1;
    // A jettisoned body exists from the separation on, sampled on the same grid start_time + k/rate
    // as its parent, so a radar sees both in one look.
    first_sample_ = static_cast<long long>(std::ceil((pieces_.front().start - start_) * rate_ - kTimeTolerance * rate_));
    if (first_sample_ < 0) first_sample_ = 0;
  }

  void start_run(const RunContext& ctx) override {
    next_sample_ = first_sample_;
    piece_ = 0;
    if (noise_.enabled()) noise_.reset(ctx.seed);
    if (jerk_.enabled()) jerk_.reset(ctx.seed);
  }

  double next_time() const override {
    return next_sample_ < sample_count_ ? sample_time(next_sample_) : std::numeric_limits<double>::infinity();
  }

  void emit_next() override {
    const bool first = next_sample_ == first_sample_;
    const double t = sample_time(next_sample_++);
    // Samples only move forward, so the current piece only moves forward too.
    while (piece_ + 1 < pieces_.size() && pieces_[piece_ + 1].start <= t + kTimeTolerance) ++piece_;
    const sim::Kinematics k = sim::evaluate(pieces_[piece_], t);
    truth_.time = t;
    truth_.position = k.position;
    truth_.velocity = k.velocity;
    truth_.acceleration = k.acceleration;
    // Skipped entirely when off, so the profile's values (signed zeros included) pass unchanged.
    if (noise_.enabled()) {
      if (!first) noise_.step();
      truth_.position += noise_.position();
      truth_.velocity += noise_.velocity();
      truth_.acceleration += noise_.acceleration();
    }
    if (jerk_.enabled()) {  // at most one of the two is enabled (process_noise_q_jerk refuses both)
      if (!first) jerk_.step();
      truth_.position += jerk_.position();
      truth_.velocity += jerk_.velocity();
      truth_.acceleration += jerk_.acceleration();
    }
    out.emit(truth_);
  }

 private:
  // Computed, not accumulated, so times are exact multiples of the period whatever the run length.
  double sample_time(long long k) const { return start_ + static_cast<double>(k) / rate_; }

  std::vector<MotionPiece> pieces_;
  double rate_, start_;
  long long sample_count_ = 0;
  long long next_sample_ = 0;
  long long first_sample_ = 0;
  size_t piece_ = 0;
  sim::WhiteAccelerationNoise noise_;
  sim::WhiteJerkNoise jerk_;
  Truth truth_;
};

std::vector<ParamSpec> segment_fields() {
  return {
      ParamSpec::choice<sim::SegmentType>("type",
                                     {{sim::SegmentType::ConstantVelocity, "constant_velocity"},
                                      {sim::SegmentType::ConstantAcceleration, "constant_acceleration"},
                                      {sim::SegmentType::Turn, "turn"},
                                      {sim::SegmentType::VelocityChange, "velocity_change"}},
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
  d.summary = "Simulated target truth (ENU) flying constant-velocity, constant-acceleration, turn and velocity-change "
              "segments, or the KSLV-I launch profile, optionally perturbed by white-noise acceleration or jerk";
  d.doc = "Each segment is propagated in closed form from where the previous one ended (no numerical integration). "
          "A turn is a horizontal coordinated turn at constant rate that keeps the vertical velocity. A "
          "velocity_change is instantaneous: a sample at its time already shows the new velocity. Truth "
          "(position, velocity, acceleration) is emitted at start_time + k/rate up to and including the end of the "
          "last segment. Example (paper 002, circle R = 1500 m at 200 m/s): initial_position: [0, 0, 150 m], "
          "initial_velocity: [200 m/s, 0, 0], segments: [{type: turn, turn_rate: 0.13333 rad/s, duration: 47.124 s}]. "
          "A landing approach is a velocity_change (speed, heading along the runway, climb = -glide slope) and a "
          "constant_velocity segment aimed at the touchdown point.\n"
          "profile: kslv1 replaces the segments by the KSLV-I ascent of paper 000 Table 16 (time s / altitude km / "
          "downrange km: 0/0.1/0, 0.2/0.1/0, 54/7.2/0.8, 215/177/245, 229/193/303, 232/196/316, 395/303/1052, "
          "453/304/1390, 540/302/2054; paper 003 Table 2 prints the same numbers with the altitude and downrange "
          "labels swapped), lift-off at start_time. Altitude and downrange are each a shape-preserving cubic in time: "
          "the slopes of a C2 spline (clamped to zero velocity at lift-off, natural at burn-out) limited as Hyman 1983 "
          "(Fritsch-Carlson region), so that each is monotone between rows: downrange never decreases, altitude rises "
          "to the 304 km row at 453 s and falls to 302 km at 540 s, never outside the rows either side (the plain "
          "spline swung 254.7 m uprange near 28 s). Velocity is continuous and the exact derivative of the position; "
          "the acceleration is the exact derivative of the velocity but jumps at knots next to a limited slope (up to "
          "9.0 m/s2, at the 395 s row). It passes through every row, reaches about 8.1 km/s at 540 s and about 395 "
          "m/s at Mach 1 (54 s). The track starts "
          "at pad_position (ENU, relative to the frame's origin, e.g. a radar ~100 km away) and runs along the "
          "compass launch_azimuth. earth: flat (default) lays downrange along a straight ground line and altitude "
          "straight up from the pad's height, as paper 000's synthetic trajectory does (its Fig 48 ends ~300 km up); "
          "it ignores the earth's curvature, which at 2054 km downrange puts the real vehicle about 340 km lower "
          "(below a pad radar's horizon). earth: spherical bends the track over a sphere of radius 6371 km whose "
          "surface passes through the frame's origin: downrange is the great-circle arc, altitude is measured from "
          "the pad's radius, and the azimuth is the frame's compass direction carried to the pad. earth: wgs84 flies the "
          "profile over the WGS-84 ellipsoid (GeographicLib): the pad is pad_site, one of the pipeline's geodetic "
          "sites: (latitude, longitude, height), the ENU frame is anchored at pipeline.frame_origin; downrange is the "
          "distance along the geodesic leaving the pad at the compass launch_azimuth, altitude (above lift-off) is added "
          "to the pad's height along the ellipsoid normal; velocity and acceleration follow by the chain rule with "
          "central differences of the geodesic over 100 m of downrange (see docs/papers/004-refraction-bias.md).\n"
          "Process noise (off by default): process_noise_q > 0 (or process_noise_q_enu, one value per ENU axis) adds to "
          "any of the above a deviation driven by continuous white acceleration of that spectral density, the continuous "
          "white noise acceleration (CV) model of Bar-Shalom, Li & Kirubarajan 2001 §6.2.2 (eq 6.2.2-12), discretised "
          "exactly at the sample period T = 1/rate: per axis the deviation [dp, dv] starts at zero at the first sample "
          "and at each later sample becomes [dp + T dv, dv] + w, w ~ N(0, q [[T³/3, T²/2], [T²/2, T]]), drawn with the "
          "closed-form Cholesky factor. The deviation accumulates over the run (position and velocity wander off the "
          "profile like a random walk) and is added to the profile's position and velocity; the reported acceleration "
          "is the profile's plus the mean white acceleration over the step just ended, Δdv/T (zero at the first "
          "sample). A CV filter.kalman with q equal to process_noise_q is then the matched model on a straight "
          "profile. Random draws: per sample after the first, two standard normals per axis (east, north, up), from "
          "the run's seed of this node (independent of every other node's stream, identical for any --threads); with "
          "q = 0 on every axis nothing is drawn and the output is exactly the profile.\n"
          "Instead, process_noise_q_jerk > 0 (or process_noise_q_jerk_enu) drives the deviation [dp, dv, da] by white "
          "jerk of that spectral density, the Wiener-process acceleration model (Bar-Shalom et al. §6.2.3; paper 000 eq "
          "3.19): per sample [dp, dv, da] <- [[1, T, T²/2], [0, 1, T], [0, 0, 1]] [dp, dv, da] + w, w ~ N(0, q [[T⁵/20, "
          "T⁴/8, T³/6], [T⁴/8, T³/3, T²/2], [T³/6, T²/2, T]]); the deviation's acceleration da is added to the reported "
          "acceleration. A constant-acceleration filter.ekf / filter.ukf with q_jerk equal to it is the matched model. "
          "Three standard normals per axis per sample. The deviation grows without bound (velocity sd sqrt(q t³/3), "
          "position sd sqrt(q t⁵/20) after t seconds: 46 m/s and 7.2 km after 400 s at q = 1e-4 m2/s5). The two models "
          "are exclusive.\n"
          "Jettison (off by default): jettison_time makes this node a body that separates from the flight above at "
          "that time (a spent stage): it exists from its first sample at or after jettison_time (on the same grid "
          "start_time + k/rate, so a radar sees it in the parent's looks) and falls freely from the flight's position "
          "and velocity there plus jettison_velocity, p(t) = p0 + v0 τ + a τ²/2 with a = [0, 0, -gravity], τ = t - "
          "jettison_time (flat earth, no drag), until the end of the flight or until it is back at the pad's height, "
          "whichever is first. A second sim.trajectory node with the same flight and no jettison_time is the body that "
          "flies on (give the two different target ids).";
  d.params = {
      ParamSpec::real("rate", dim::frequency, "sample rate of the truth").def("10 Hz").positive(),
      ParamSpec::real("start_time", dim::time, "time of the first sample and of the start of the first segment").def("0 s"),
      ParamSpec::real_list("initial_position", dim::length,
                           "ENU position at start_time [x east, y north, z up] (required without a profile)", 3),
      ParamSpec::real_list("initial_velocity", dim::velocity, "ENU velocity at start_time (segments only)", 3).def("[0, 0, 0]"),
      ParamSpec::integer("target", "target id written into each Truth item").def("0").at_least(0).at_most(4294967295.0),
      ParamSpec::records("segments", segment_fields(), "the flight, in order (at least one; required without a profile)"),
      ParamSpec::choice<sim::Profile>("profile", {{sim::Profile::None, "none"}, {sim::Profile::Kslv1, "kslv1"}},
                                 "fly a tabulated launch profile instead of segments")
          .def("none"),
      ParamSpec::real_list("pad_position", dim::length, "profile: launch pad position in the ENU frame", 3),
      ParamSpec::real("launch_azimuth", dim::angle, "profile: compass direction of the downrange track, from north clockwise"),
      ParamSpec::choice<sim::Earth>("earth",
                                    {{sim::Earth::Flat, "flat"}, {sim::Earth::Spherical, "spherical"}, {sim::Earth::Wgs84, "wgs84"}},
                                    "profile: flat ground line (paper 000), a spherical earth, or the WGS-84 ellipsoid "
                                    "from a geodetic pad_site")
          .def("flat"),
      ParamSpec::string("pad_site", "profile on earth: wgs84: the launch pad, a site of the pipeline's sites: map"),
      sim::sites_param(),
      sim::frame_origin_param(),
      ParamSpec::real("profile_duration", dim::time, "profile: fly only the first part of it (default: the whole table)").positive(),
      ParamSpec::real("jettison_time", dim::time, "a body jettisoned from this flight at this time: free fall from then on"),
      ParamSpec::real_list("jettison_velocity", dim::velocity, "jettison: ENU separation velocity added to the flight's", 3)
          .def("[0, 0, 0]"),
      ParamSpec::real("gravity", dim::acceleration, "jettison: gravitational acceleration of the free fall").def("9.80665 m/s2").at_least(0),
      ParamSpec::real("process_noise_q", dim::accel_psd,
                      "spectral density of white acceleration added to the truth, every ENU axis (0: off)")
          .def("0 m2/s3")
          .at_least(0),
      ParamSpec::real_list("process_noise_q_enu", dim::accel_psd,
                           "instead of process_noise_q: one spectral density per axis [east, north, up]", 3)
          .at_least(0),
      ParamSpec::real("process_noise_q_jerk", dim::jerk_psd,
                      "spectral density of white jerk added to the truth, every ENU axis (0: off; not with process_noise_q)")
          .def("0 m2/s5")
          .at_least(0),
      ParamSpec::real_list("process_noise_q_jerk_enu", dim::jerk_psd,
                           "instead of process_noise_q_jerk: one spectral density per axis [east, north, up]", 3)
          .at_least(0),
  };
  d.accepts = 0;
  d.min_inputs = 0;
  d.max_inputs = 0;
  d.produces = mask(ItemKind::Truth);
  d.time_ordered = true;
  d.create = [](const Params& p) { return std::make_unique<TrajectorySource>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sim.trajectory", trackflow::register_components)
