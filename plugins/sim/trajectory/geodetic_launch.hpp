// Purpose: a launch profile flown over the WGS-84 ellipsoid: downrange along the geodesic from a geodetic pad, altitude along the ellipsoid normal, in the pipeline's ENU frame.
#pragma once

#include "physics/geodesy.hpp"
#include "flight_plan.hpp"
#include "launch_profile.hpp"

#include <trackflow/params.hpp>

#include <GeographicLib/GeodesicLine.hpp>

#include <vector>

namespace trackflow::sim {

// earth: wgs84. The profile's altitude and downrange (and their time derivatives) are the
// interpolant of LaunchPath, read off a flat path from the origin due north (y = downrange,
// z = altitude - altitude(0)), so the interpolation is the same in every earth model. The foot
// point moves `downrange` metres along the geodesic that leaves the pad at the compass
// `azimuth`; the vehicle is `pad height + altitude - altitude(0)` above the ellipsoid there.
// P(d, H) = F(geodesic(d), H) in the pipeline's ENU frame is affine in H (F = f + H n, n the
// ellipsoid normal), so with d(t), H(t):
//   V = P_d d' + n H',   A = P_dd d'^2 + P_d d'' + 2 n_d d' H' + n H''
// P_d, P_dd and n_d are central differences over kStep metres of downrange: P is smooth on the
// scale of the earth's radius, so the truncation error is ~kStep^2 / R^2 (1e-10) and the rounding
// error of GeographicLib's nanometre positions stays below 1e-4 m/s^2 at orbital speed.
class GeodeticLaunchPath {
 public:
  GeodeticLaunchPath(const ProfileTable& table, const GeodeticPoint& pad, double azimuth, const EnuFrame& frame);
  Kinematics at(double tau) const;
  double duration() const { return profile_.duration(); }

  static constexpr double kStep = 100.0;          // m of downrange
  static constexpr double kHeightStep = 1000.0;   // m, for the normal (exact: P is affine in H)

 private:
  Vec3 position(double downrange, double height) const;

  LaunchPath profile_;
  GeographicLib::GeodesicLine line_;
  EnuFrame frame_;
  double pad_height_ = 0.0;
};

// The pieces for `profile: kslv1` with `earth: wgs84`: the pad is `pad_site`, the frame is
// `frame_origin`, both among `sites`. Refuses pad_position (the pad is a site here).
std::vector<MotionPiece> build_geodetic_launch_plan(const Params& params);

}  // namespace trackflow::sim
