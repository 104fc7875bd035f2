// Purpose: a launch trajectory from a (time, altitude, downrange) table: C² splines placed at a pad on a flat or spherical earth.
#pragma once

#include "cubic_spline.hpp"
#include "flight_plan.hpp"

#include <trackflow/params.hpp>

#include <vector>

namespace trackflow::sim {

// A published ascent profile, SI units: time from lift-off (s), altitude above sea level (m),
// downrange distance along the ground (m).
struct ProfileTable {
  std::vector<double> time, altitude, downrange;
};

// KSLV-I (Naro), paper 000 Table 16 (paper 003 Table 2 prints the same numbers with the
// altitude and downrange labels swapped): lift-off, full thrust, Mach 1, fairing separation,
// first-stage cut-off, stage separation, coast, second-stage ignition, burn-out and orbit.
const ProfileTable& kslv1_table();

// Mean earth radius used by the spherical placement.
inline constexpr double kEarthRadius = 6371.0e3;  // m

struct LaunchSite {
  Vec3 pad = Vec3::Zero();  // pad position in the pipeline's ENU frame
  double azimuth = 0.0;     // compass direction of the downrange track at the pad, rad
  bool spherical = false;   // false: flat earth
};

// Altitude and downrange are each a cubic spline in time, clamped to zero velocity at lift-off
// (the vehicle starts at rest) and natural at the last row (zero acceleration at burn-out).
// Flat earth: position = pad + downrange·u + (altitude - altitude(0))·up, u the horizontal unit
// vector at `azimuth`. Spherical earth: the ENU origin is on a sphere of radius kEarthRadius;
// downrange is the great-circle arc from the pad toward `azimuth` (the frame's north carried to the
// pad) and altitude is measured from the pad's radius; velocity and acceleration by the chain rule.
class LaunchPath {
 public:
  LaunchPath(const ProfileTable& table, const LaunchSite& site);
  // State `tau` seconds after lift-off (exact derivatives of the interpolant; no allocation).
  Kinematics at(double tau) const;
  double duration() const { return duration_; }

 private:
  CubicSpline altitude_, downrange_;
  double altitude0_ = 0.0, duration_ = 0.0;
  LaunchSite site_;
  Vec3 centre_ = Vec3::Zero(), up_ = Vec3::UnitZ(), along_ = Vec3::UnitY();
  double pad_radius_ = 0.0;
};

// The pieces for `profile: kslv1`: one launch piece from start_time over the table (or
// profile_duration). Validates that no segment-mode parameter is given and the launch ones are.
std::vector<MotionPiece> build_launch_plan(const Params& params);

// Refuses launch parameters when no profile is chosen (they would be silently ignored).
void refuse_launch_params(const Params& params);

}  // namespace trackflow::sim
