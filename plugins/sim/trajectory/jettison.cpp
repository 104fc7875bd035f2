// Purpose: a jettisoned body's free fall from its parent's state at separation (sim.trajectory jettison_time).
#include "jettison.hpp"

#include <cmath>
#include <string>

namespace trackflow::sim {

std::vector<MotionPiece> jettisoned_flight(const std::vector<MotionPiece>& parent, double separation_time, const Vec3& delta_v,
                                           double gravity, double ground_height) {
  std::size_t i = 0;
  while (i + 1 < parent.size() && parent[i + 1].start <= separation_time) ++i;
  const Kinematics k = evaluate(parent[i], separation_time);
  MotionPiece fall;
  fall.motion = Motion::ConstantAcceleration;
  fall.start = separation_time;
  fall.position = k.position;
  fall.velocity = k.velocity + delta_v;
  fall.acceleration = Vec3(0.0, 0.0, -gravity);
  fall.end = parent.back().end;
  // Ground contact: z0 + vz tau - g tau^2 / 2 = ground, the later root (the body starts above it).
  const double h = fall.position.z() - ground_height, vz = fall.velocity.z();
  if (gravity > 0.0 && h >= 0.0) {
    const double tau = (vz + std::sqrt(vz * vz + 2.0 * gravity * h)) / gravity;
    if (separation_time + tau < fall.end) fall.end = separation_time + tau;
  }
  return {fall};
}

std::vector<MotionPiece> apply_jettison(const Params& params, std::vector<MotionPiece> pieces) {
  if (!params.given("jettison_time")) {
    for (const char* name : {"jettison_velocity", "gravity"})
      if (params.given(name)) throw params.error(name, "applies to a jettisoned body only: give jettison_time");
    return pieces;
  }
  const double t = params.real("jettison_time");
  if (params.choice<Earth>("earth") != Earth::Flat)
    throw params.error("jettison_time", "the free fall after a jettison is on a flat earth only (earth: flat)");
  if (!(t >= pieces.front().start && t < pieces.back().end))
    throw params.error("jettison_time", "must lie within the flight (" + std::to_string(pieces.front().start) + " s to " +
                                            std::to_string(pieces.back().end) + " s)");
  const double ground = evaluate(pieces.front(), pieces.front().start).position.z();
  return jettisoned_flight(pieces, t, params.vec3("jettison_velocity"), params.real("gravity"), ground);
}

}  // namespace trackflow::sim
