// Purpose: a jettisoned body (a spent stage) as motion pieces: the parent's flight up to the separation, then a free fall under constant gravity from the parent's state plus a separation velocity, until it reaches the ground.
#pragma once

#include "flight_plan.hpp"

#include <trackflow/params.hpp>

#include <vector>

namespace trackflow::sim {

// The separated body's flight: one ConstantAcceleration piece from `separation_time` with the
// parent's position and velocity there plus `delta_v`, acceleration [0, 0, -gravity] (a flat
// earth, no drag), ending at the parent's end or where it falls back to `ground_height`, whichever
// is first. `parent` must cover separation_time.
std::vector<MotionPiece> jettisoned_flight(const std::vector<MotionPiece>& parent, double separation_time, const Vec3& delta_v,
                                           double gravity, double ground_height);

// jettison_time / jettison_velocity / gravity of sim.trajectory's params applied to `pieces`
// (unchanged without jettison_time); refuses a time outside the flight and a curved earth.
std::vector<MotionPiece> apply_jettison(const Params& params, std::vector<MotionPiece> pieces);

}  // namespace trackflow::sim
