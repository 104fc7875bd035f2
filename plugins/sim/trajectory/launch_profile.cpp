// Purpose: the KSLV-I profile table, its shape-preserving interpolation and placement at the pad (flat or spherical earth).
#include "launch_profile.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

namespace trackflow::sim {

const ProfileTable& kslv1_table() {
  // Paper 000 Table 16 (source: www.kari.re.kr): flight time s / altitude km / downrange km.
  // The -3.8 s ignition-command row is before lift-off and not part of the flight.
  static const ProfileTable table = [] {
    const double rows[][3] = {{0, 0.1, 0},     {0.2, 0.1, 0},   {54, 7.2, 0.8},     {215, 177, 245},    {229, 193, 303},
                              {232, 196, 316}, {395, 303, 1052}, {453, 304, 1390}, {540, 302, 2054}};
    ProfileTable t;
    for (const auto& r : rows) {
      t.time.push_back(r[0]);
      t.altitude.push_back(r[1] * 1e3);
      t.downrange.push_back(r[2] * 1e3);
    }
    return t;
  }();
  return table;
}

LaunchPath::LaunchPath(const ProfileTable& table, const LaunchSite& site)
    : altitude_(table.time, table.altitude, SplineEnd::clamped_to(0.0), SplineEnd::natural()),
      downrange_(table.time, table.downrange, SplineEnd::clamped_to(0.0), SplineEnd::natural()),
      altitude0_(table.altitude.front()),
      duration_(table.time.back() - table.time.front()),
      site_(site) {
  const Vec3 compass(std::sin(site.azimuth), std::cos(site.azimuth), 0.0);
  if (!site.spherical) {
    along_ = compass;
    return;
  }
  centre_ = Vec3(0.0, 0.0, -kEarthRadius);
  const Vec3 radial = site.pad - centre_;
  pad_radius_ = radial.norm();
  up_ = radial / pad_radius_;
  // The frame's compass direction carried to the pad: projected into the pad's horizontal plane.
  const Vec3 horizontal = compass - compass.dot(up_) * up_;
  if (horizontal.norm() < 1e-9) throw std::invalid_argument("the launch azimuth is vertical at the pad");
  along_ = horizontal.normalized();
}

Kinematics LaunchPath::at(double tau) const {
  const SplinePoint h = altitude_.at(tau);
  const SplinePoint d = downrange_.at(tau);
  if (!site_.spherical) {
    const Vec3 up = Vec3::UnitZ();
    return {site_.pad + d.value * along_ + (h.value - altitude0_) * up, d.first * along_ + h.first * up,
            d.second * along_ + h.second * up};
  }
  // Polar coordinates in the launch plane: radius rho from the earth's centre, arc angle theta
  // from the pad. P = C + rho e_r, V = rho' e_r + rho theta' e_t, A = (rho'' - rho theta'^2) e_r
  // + (rho theta'' + 2 rho' theta') e_t, with e_r = cos(theta) up + sin(theta) along, e_t = de_r/dtheta.
  const double rho = pad_radius_ + h.value - altitude0_;
  const double theta = d.value / kEarthRadius, theta1 = d.first / kEarthRadius, theta2 = d.second / kEarthRadius;
  const double c = std::cos(theta), s = std::sin(theta);
  const Vec3 e_r = c * up_ + s * along_;
  const Vec3 e_t = -s * up_ + c * along_;
  return {centre_ + rho * e_r, h.first * e_r + rho * theta1 * e_t,
          (h.second - rho * theta1 * theta1) * e_r + (rho * theta2 + 2 * h.first * theta1) * e_t};
}

void refuse_launch_params(const Params& params) {
  for (const char* name : {"pad_position", "launch_azimuth", "earth", "profile_duration"})
    if (params.given(name)) throw params.error(name, "applies to a launch profile only; add 'profile: kslv1' or remove it");
}

void time_launch_piece(const Params& params, const std::string& profile, double table_duration,
                       const Kinematics& initial, MotionPiece& piece) {
  double duration = table_duration;
  if (params.has("profile_duration")) {
    const double wanted = params.real("profile_duration");
    if (wanted > duration + 1e-9)
      throw params.error("profile_duration", "is longer than the " + profile + " table (" +
                                                 std::to_string(static_cast<int>(duration)) + " s)");
    duration = std::min(wanted, duration);
  }
  piece.start = params.real("start_time");
  piece.end = piece.start + duration;
  piece.position = initial.position;
  piece.velocity = initial.velocity;
  piece.acceleration = initial.acceleration;
}

std::vector<MotionPiece> build_launch_plan(const Params& params) {
  const std::string& profile = params.choice_word("profile");
  for (const char* name : {"segments", "initial_position", "initial_velocity"})
    if (params.given(name))
      throw params.error(name, "is not used with 'profile: " + profile + "' (the profile gives the whole flight); remove it");
  for (const char* name : {"pad_position", "launch_azimuth"})
    if (!params.has(name)) throw params.error(name, std::string("is required with 'profile: ") + profile + "'");
  const ProfileTable& table = kslv1_table();
  LaunchSite site;
  site.pad = params.vec3("pad_position");
  site.azimuth = params.real("launch_azimuth");
  site.spherical = params.choice<Earth>("earth") == Earth::Spherical;
  MotionPiece piece;
  piece.motion = Motion::Launch;
  try {
    piece.launch = std::make_shared<const LaunchPath>(table, site);
  } catch (const std::invalid_argument& e) {
    throw params.error("launch_azimuth", e.what());
  }
  time_launch_piece(params, profile, piece.launch->duration(), piece.launch->at(0.0), piece);
  return {piece};
}

}  // namespace trackflow::sim
