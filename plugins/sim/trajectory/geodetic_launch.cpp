// Purpose: the KSLV-I profile placed on the WGS-84 ellipsoid from a geodetic pad (GeographicLib geodesic and local frame).
#include "geodetic_launch.hpp"

#include <GeographicLib/Geodesic.hpp>

#include <memory>
#include <string>

namespace trackflow::sim {

GeodeticLaunchPath::GeodeticLaunchPath(const ProfileTable& table, const GeodeticPoint& pad, double azimuth,
                                       const EnuFrame& frame)
    : profile_(table, LaunchSite{Vec3::Zero(), 0.0, false}),
      line_(GeographicLib::Geodesic::WGS84(), pad.latitude * kRadToDeg, pad.longitude * kRadToDeg, azimuth * kRadToDeg),
      frame_(frame),
      pad_height_(pad.height) {}

Vec3 GeodeticLaunchPath::position(double downrange, double height) const {
  double lat = 0.0, lon = 0.0;
  line_.Position(downrange, lat, lon);
  return frame_.to_enu({lat / kRadToDeg, lon / kRadToDeg, height});
}

Kinematics GeodeticLaunchPath::at(double tau) const {
  // Flat profile due north from the origin: y = downrange, z = altitude above lift-off.
  const Kinematics k = profile_.at(tau);
  const double d = k.position.y(), d1 = k.velocity.y(), d2 = k.acceleration.y();
  const double H = pad_height_ + k.position.z(), H1 = k.velocity.z(), H2 = k.acceleration.z();
  const Vec3 P0 = position(d, H), Pp = position(d + kStep, H), Pm = position(d - kStep, H);
  const Vec3 n0 = (position(d, H + kHeightStep) - P0) / kHeightStep;
  const Vec3 np = (position(d + kStep, H + kHeightStep) - Pp) / kHeightStep;
  const Vec3 nm = (position(d - kStep, H + kHeightStep) - Pm) / kHeightStep;
  const Vec3 Pd = (Pp - Pm) / (2 * kStep), Pdd = (Pp - 2 * P0 + Pm) / (kStep * kStep);
  const Vec3 nd = (np - nm) / (2 * kStep);
  return {P0, Pd * d1 + n0 * H1, Pdd * d1 * d1 + Pd * d2 + 2 * nd * d1 * H1 + n0 * H2};
}

std::vector<MotionPiece> build_geodetic_launch_plan(const Params& params) {
  const std::string& profile = params.choice_word("profile");
  for (const char* name : {"segments", "initial_position", "initial_velocity"})
    if (params.given(name))
      throw params.error(name, "is not used with 'profile: " + profile + "' (the profile gives the whole flight); remove it");
  if (params.given("pad_position"))
    throw params.error("pad_position", "is not used with 'earth: wgs84': the pad is a geodetic site (pad_site)");
  for (const char* name : {"pad_site", "launch_azimuth"})
    if (!params.has(name)) throw params.error(name, "is required with 'profile: " + profile + "' and 'earth: wgs84'");
  const std::vector<Site> sites = read_sites(params);
  const Site pad = find_site(params, sites, "pad_site");
  const EnuFrame frame = EnuFrame::from_params(params, sites, "earth");
  MotionPiece piece;
  piece.motion = Motion::GeodeticLaunch;
  piece.geodetic_launch = std::make_shared<const GeodeticLaunchPath>(kslv1_table(), pad.where,
                                                                     params.real("launch_azimuth"), frame);
  time_launch_piece(params, profile, piece.geodetic_launch->duration(), piece.geodetic_launch->at(0.0), piece);
  return {piece};
}

}  // namespace trackflow::sim
