// Purpose: validation of trajectory segment records and exact propagation of CV, CA, coordinated-turn and launch pieces.
#include "flight_plan.hpp"

#include "geodetic_launch.hpp"
#include "launch_profile.hpp"

#include <trackflow/number_text.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace trackflow::sim {
namespace {

// sin(x)/x without the 0/0 at x = 0; the series error at the switch is ~x^4/120 < 1e-18.
double sinc(double x) { return std::abs(x) < 1e-4 ? 1.0 - x * x / 6.0 : std::sin(x) / x; }

// Below this speed the direction of a velocity (its heading or climb) is taken as undefined.
constexpr double kStillSpeed = 1e-9;  // m/s

struct SegmentRule {
  SegmentType type;
  std::vector<std::string> allowed;   // besides `type`
  std::vector<std::string> required;
};

const std::vector<SegmentRule>& segment_rules() {
  static const std::vector<SegmentRule> rules = {
      {SegmentType::ConstantVelocity, {"duration"}, {"duration"}},
      {SegmentType::ConstantAcceleration, {"duration", "acceleration"}, {"duration", "acceleration"}},
      {SegmentType::Turn, {"duration", "turn_rate"}, {"duration", "turn_rate"}},
      {SegmentType::VelocityChange, {"velocity", "speed", "heading", "climb"}, {}},
  };
  return rules;
}

std::string quoted_list(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "'" : ", '") + n + "'";
  return s.empty() ? "none" : s;
}

void check_fields(const Params& rec, const std::string& label) {
  const SegmentType type = rec.choice<SegmentType>("type");
  const auto& rules = segment_rules();
  const auto rule = std::find_if(rules.begin(), rules.end(), [&](const SegmentRule& r) { return type == r.type; });
  for (const auto& [field, value] : rec.values()) {
    if (field == "type" || value.from_default) continue;
    if (std::find(rule->allowed.begin(), rule->allowed.end(), field) == rule->allowed.end())
      throw rec.error(field, label + ": '" + field + "' does not belong to a " + rec.choice_word("type") +
                                 " segment (its fields: " + quoted_list(rule->allowed) + ")");
  }
  for (const auto& field : rule->required)
    if (!rec.given(field)) throw rec.error(field, label + ": a " + rec.choice_word("type") + " segment needs '" + field + "'");
  if (type == SegmentType::VelocityChange) {
    const bool by_vector = rec.given("velocity");
    const bool by_parts = rec.given("speed") || rec.given("heading") || rec.given("climb");
    if (by_vector && by_parts) {
      const char* extra = rec.given("speed") ? "speed" : rec.given("heading") ? "heading" : "climb";
      throw rec.error(extra, label + ": give either 'velocity' or any of 'speed', 'heading', 'climb', not both");
    }
    if (!by_vector && !by_parts)
      throw rec.error("velocity", label + ": a velocity_change needs 'velocity' or any of 'speed', 'heading', 'climb'");
  }
}

// New velocity of a velocity_change record applied to the current velocity v. Whatever is not
// given is kept from v; keeping a direction of a zero (or, for heading, vertical) velocity is an error.
Vec3 changed_velocity(const Params& rec, const Vec3& v, const std::string& label) {
  if (rec.given("velocity")) return rec.vec3("velocity");
  const double horizontal = std::hypot(v.x(), v.y());
  const double speed = rec.given("speed") ? rec.real("speed") : v.norm();
  if (speed <= 0.0) return Vec3::Zero();
  double climb = 0.0;
  if (rec.given("climb"))
    climb = rec.real("climb");
  else if (v.norm() > kStillSpeed)
    climb = std::atan2(v.z(), horizontal);
  else
    throw rec.error("climb", label + ": the velocity before this change is zero, so there is no climb angle to "
                                     "keep; give 'climb'");
  const double cos_climb = std::cos(climb);
  double heading = 0.0;
  if (rec.given("heading"))
    heading = rec.real("heading");
  else if (horizontal > kStillSpeed)
    heading = std::atan2(v.x(), v.y());  // compass: from north, clockwise
  else if (std::abs(cos_climb) > 1e-12)  // a vertical new velocity needs no heading
    throw rec.error("heading", label + ": the velocity before this change is vertical or zero, so there is no "
                                       "heading to keep; give 'heading'");
  return speed * Vec3(cos_climb * std::sin(heading), cos_climb * std::cos(heading), std::sin(climb));
}

}  // namespace

Kinematics evaluate(const MotionPiece& p, double t) {
  const double dt = t - p.start;
  switch (p.motion) {
    case Motion::ConstantVelocity:
      return {p.position + dt * p.velocity, p.velocity, Vec3::Zero()};
    case Motion::ConstantAcceleration:
      return {p.position + dt * p.velocity + 0.5 * dt * dt * p.acceleration, p.velocity + dt * p.acceleration,
              p.acceleration};
    case Motion::Turn: {
      // Horizontal velocity rotates by theta = w dt; position gains the integral of that rotation:
      // [[sin(theta)/w, -(1-cos theta)/w], [(1-cos theta)/w, sin(theta)/w]] v_h, written with sinc so
      // that w -> 0 tends to straight flight instead of 0/0.
      const double w = p.turn_rate, theta = w * dt;
      const double c = std::cos(theta), s = std::sin(theta);
      const double a = dt * sinc(theta);                             // sin(theta)/w
      const double b = dt * std::sin(0.5 * theta) * sinc(0.5 * theta);  // (1 - cos theta)/w
      const double vx = p.velocity.x(), vy = p.velocity.y(), vz = p.velocity.z();
      Kinematics k;
      k.position = p.position + Vec3(a * vx - b * vy, b * vx + a * vy, dt * vz);
      k.velocity = Vec3(c * vx - s * vy, s * vx + c * vy, vz);
      k.acceleration = Vec3(-w * k.velocity.y(), w * k.velocity.x(), 0.0);  // w z^ x v: centripetal
      return k;
    }
    case Motion::Launch:
      return p.launch->at(dt);
    case Motion::GeodeticLaunch:
      return p.geodetic_launch->at(dt);
  }
  return {p.position, p.velocity, Vec3::Zero()};
}

namespace {

// A coordinated turn's lateral acceleration is |w| times the horizontal speed; above 30 g no
// aircraft or missile sustains it (issue 26: `turn_rate: 3`, read as 3 rad/s, is 61 g at 200 m/s).
// Valid, so a warning, not an error: the turn_rate declaration cannot say it, it needs the speed.
void warn_if_implausible_turn(const Params& rec, const std::string& label, double turn_rate, const Vec3& v) {
  constexpr double g0 = 9.80665, kMaxPlausible = 30 * g0;
  const double lateral = std::abs(turn_rate) * std::hypot(v.x(), v.y());
  if (!(lateral > kMaxPlausible)) return;
  rec.warn("turn_rate", label + ": " + number_text::general(turn_rate * 180 / std::numbers::pi, 4) + " deg/s at " +
                            number_text::general(std::hypot(v.x(), v.y()), 4) + " m/s horizontal speed is a " +
                            number_text::general(lateral / g0, 3) +
                            " g turn, above the 30 g that no aircraft or missile sustains; a rate in deg/s written as rad/s?");
}

}  // namespace

std::vector<MotionPiece> build_flight_plan(const Params& params) {
  // Worded and located as the validator words a missing required parameter (the declaration
  // cannot mark them required: a launch profile replaces them).
  for (const char* name : {"initial_position", "segments"})
    if (!params.has(name))
      throw ConfigError(std::string("missing required parameter '") + name + "' (needed unless 'profile' is set)",
                        params.where(), params.node());
  refuse_launch_params(params);
  const auto& segments = params.records("segments");
  if (segments.empty()) throw params.error("segments", "needs at least one segment");
  std::vector<MotionPiece> pieces;
  pieces.reserve(segments.size() + 1);
  double t = params.real("start_time");
  Vec3 p = params.vec3("initial_position");
  Vec3 v = params.vec3("initial_velocity");
  bool change_pending = false;
  for (size_t i = 0; i < segments.size(); ++i) {
    const Params& rec = segments[i];
    const std::string label = "segment " + std::to_string(i + 1) + " (" + rec.choice_word("type") + ")";
    check_fields(rec, label);
    const SegmentType type = rec.choice<SegmentType>("type");
    if (type == SegmentType::VelocityChange) {
      v = changed_velocity(rec, v, label);
      change_pending = true;
      continue;
    }
    MotionPiece piece;
    piece.start = t;
    piece.end = t + rec.real("duration");
    piece.position = p;
    piece.velocity = v;
    if (type == SegmentType::ConstantAcceleration) {
      piece.motion = Motion::ConstantAcceleration;
      piece.acceleration = rec.vec3("acceleration");
    } else if (type == SegmentType::Turn) {
      piece.motion = Motion::Turn;
      piece.turn_rate = rec.real("turn_rate");
      warn_if_implausible_turn(rec, label, piece.turn_rate, v);
    }
    const Kinematics end = evaluate(piece, piece.end);
    p = end.position;
    v = end.velocity;
    t = piece.end;
    pieces.push_back(piece);
    change_pending = false;
  }
  if (change_pending || pieces.empty()) {
    MotionPiece last;
    last.start = last.end = t;
    last.position = p;
    last.velocity = v;
    pieces.push_back(last);
  }
  return pieces;
}

}  // namespace trackflow::sim
