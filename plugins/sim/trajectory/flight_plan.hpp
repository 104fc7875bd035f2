// Purpose: a trajectory as analytic motion pieces (CV, CA, horizontal turn, launch profile) built from validated segment records.
#pragma once

#include <trackflow/items.hpp>
#include <trackflow/params.hpp>

#include <memory>
#include <vector>

namespace trackflow::sim {

// The words of sim.trajectory's choice parameters, as enums (ParamSpec::choice<E>).
enum class SegmentType { ConstantVelocity, ConstantAcceleration, Turn, VelocityChange };
enum class Profile { None, Kslv1 };
enum class Earth { Flat, Spherical, Wgs84 };

class LaunchPath;
class GeodeticLaunchPath;

enum class Motion { ConstantVelocity, ConstantAcceleration, Turn, Launch, GeodeticLaunch };

// One interval of closed-form motion. Velocity changes are not pieces: they are folded into
// the initial velocity of the piece that follows them.
struct MotionPiece {
  Motion motion = Motion::ConstantVelocity;
  double start = 0.0, end = 0.0;  // absolute times, s
  Vec3 position = Vec3::Zero();   // state at `start`
  Vec3 velocity = Vec3::Zero();
  Vec3 acceleration = Vec3::Zero();  // ConstantAcceleration only
  double turn_rate = 0.0;            // Turn only, rad/s, positive counter-clockwise seen from above
  std::shared_ptr<const LaunchPath> launch;  // Launch only: the path, its time 0 at `start`
  std::shared_ptr<const GeodeticLaunchPath> geodetic_launch;  // GeodeticLaunch only (earth: wgs84)
};

struct Kinematics {
  Vec3 position, velocity, acceleration;
};

// Exact state of `piece` at time t (t may lie slightly outside the piece: it extrapolates).
Kinematics evaluate(const MotionPiece& piece, double t);

// Validates the `segments` records of `params` (fields that do not belong to a segment's type,
// missing fields, undefined heading/climb) and chains them from the initial state.
// Never empty: a trailing velocity change gets a zero-length piece so it shows in the output.
// `initial_position` and `segments` are required here (the declaration leaves them optional
// because a launch profile replaces them).
std::vector<MotionPiece> build_flight_plan(const Params& params);

}  // namespace trackflow::sim
