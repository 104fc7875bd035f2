// Purpose: a launch trajectory from a (time, altitude, downrange) table: shape-preserving cubics placed at a pad on a flat or spherical earth.
#pragma once

#include "monotone_cubic.hpp"
#include "flight_plan.hpp"

#include <trackflow/params.hpp>

#include <string>
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

// Altitude and downrange are each a shape-preserving cubic in time (MonotoneCubic): the slopes of a
// C² spline clamped to zero velocity at lift-off (the vehicle starts at rest) and natural at the last
// row, limited so that each coordinate is monotone between rows. A plain C² spline through Table 16
// swings 254.7 m uprange near t = 28 s (downrange velocity -12 m/s): the 0.8 km row at 54 s sits
// next to 245 km at 215 s. Limited here: downrange never decreases, altitude rises to the 304 km row
// at 453 s and then falls to 302 km, never outside its neighbouring rows.
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
  MonotoneCubic altitude_, downrange_;
  double altitude0_ = 0.0, duration_ = 0.0;
  LaunchSite site_;
  Vec3 centre_ = Vec3::Zero(), up_ = Vec3::UnitZ(), along_ = Vec3::UnitY();
  double pad_radius_ = 0.0;
};

// What a launch piece (flat, spherical or geodetic placement) takes from its path: start_time,
// the end after the table's duration or the shorter profile_duration (refused if longer), and the
// kinematics at lift-off (`initial`, the path at tau = 0).
void time_launch_piece(const Params& params, const std::string& profile, double table_duration,
                       const Kinematics& initial, MotionPiece& piece);

// The pieces for `profile: kslv1`: one launch piece from start_time over the table (or
// profile_duration). Validates that no segment-mode parameter is given and the launch ones are.
std::vector<MotionPiece> build_launch_plan(const Params& params);

// Refuses launch parameters when no profile is chosen (they would be silently ignored).
void refuse_launch_params(const Params& params);

}  // namespace trackflow::sim
