// Purpose: site records, their lookup by name, and the ENU frame at a site, on GeographicLib's WGS-84.
#include "geodesy.hpp"

#include <GeographicLib/Geocentric.hpp>

#include <cmath>
#include <numbers>

namespace trackflow::sim {

std::vector<ParamSpec> site_fields() {
  return {
      ParamSpec::string("name", "the site's name (the key of the pipeline's sites: map)").req(),
      ParamSpec::real("latitude", dim::angle, "geodetic latitude on WGS-84, + north")
          .req()
          .at_least(-std::numbers::pi / 2)
          .at_most(std::numbers::pi / 2),
      ParamSpec::real("longitude", dim::angle, "longitude, + east").req().at_least(-2 * std::numbers::pi).at_most(
          2 * std::numbers::pi),
      // -11 km (the deepest ocean floor) to 100 km (the Karman line): a site carries a radar, a pad or
      // the frame's origin on or above the earth; past 100 km it is a spacecraft, which the
      // stationary-sensor ENU model does not describe (issue 27: a radar 1e8 m up, accepted before,
      // gave an EKF RMSE of 2 109 km with exit 0).
      ParamSpec::real("height", dim::length,
                      "height above the WGS-84 ellipsoid, -11 km (ocean floor) to 100 km (the Karman line: above it "
                      "the sensor is a spacecraft, not a site)")
          .def("0 m")
          .at_least(-11e3)
          .at_most(100e3),
  };
}

ParamSpec sites_param() {
  return ParamSpec::records("sites", site_fields(),
                            "geodetic sites {name, latitude, longitude, height} (WGS-84); normally the pipeline's "
                            "top-level sites: map, handed to this node");
}

ParamSpec frame_origin_param() {
  return ParamSpec::string("frame_origin",
                           "the site the pipeline's ENU frame is anchored at; normally pipeline.frame_origin, handed "
                           "to this node");
}

std::vector<Site> read_sites(const Params& p) {
  std::vector<Site> out;
  if (!p.has("sites")) return out;
  for (const Params& r : p.records("sites"))
    out.push_back({r.text("name"), {r.real("latitude"), r.real("longitude"), r.real("height")}});
  return out;
}

Site find_site(const Params& p, const std::vector<Site>& sites, std::string_view name_param) {
  const std::string& name = p.text(name_param);
  std::string names;
  for (const Site& s : sites) {
    if (s.name == name) return s;
    names += (names.empty() ? "" : ", ") + s.name;
  }
  if (sites.empty())
    throw p.error(name_param, "names site '" + name + "', but there are no sites: add a top-level 'sites:' map");
  throw p.error(name_param, "'" + name + "' is not a site; sites: " + names);
}

EnuFrame::EnuFrame(const GeodeticPoint& origin)
    : origin_(origin), local_(origin.latitude * kRadToDeg, origin.longitude * kRadToDeg, origin.height) {
  origin_ecef_ = ecef(origin);
  const double sl = std::sin(origin.latitude), cl = std::cos(origin.latitude);
  const double so = std::sin(origin.longitude), co = std::cos(origin.longitude);
  ecef_to_enu_ << -so, co, 0.0,  //
      -sl * co, -sl * so, cl,     //
      cl * co, cl * so, sl;
}

EnuFrame EnuFrame::from_params(const Params& p, const std::vector<Site>& sites, std::string_view needed_by) {
  if (!p.has("frame_origin"))
    throw p.error(needed_by, "needs the pipeline's ENU frame anchored at a site: add 'frame_origin: <site>' to the "
                             "pipeline: section");
  return EnuFrame(find_site(p, sites, "frame_origin").where);
}

Vec3 EnuFrame::ecef(const GeodeticPoint& g) const {
  Vec3 x;
  GeographicLib::Geocentric::WGS84().Forward(g.latitude * kRadToDeg, g.longitude * kRadToDeg, g.height, x.x(), x.y(),
                                             x.z());
  return x;
}

Vec3 EnuFrame::ecef_to_enu(const Vec3& e) const { return ecef_to_enu_ * (e - origin_ecef_); }

Vec3 EnuFrame::to_enu(const GeodeticPoint& g) const { return ecef_to_enu(ecef(g)); }

GeodeticPoint EnuFrame::to_geodetic(const Vec3& enu) const {
  GeodeticPoint g;
  local_.Reverse(enu.x(), enu.y(), enu.z(), g.latitude, g.longitude, g.height);
  g.latitude /= kRadToDeg;
  g.longitude /= kRadToDeg;
  return g;
}

Vec3 EnuFrame::up_at(const GeodeticPoint& g) const {
  const double cl = std::cos(g.latitude);
  return ecef_to_enu_ * Vec3(cl * std::cos(g.longitude), cl * std::sin(g.longitude), std::sin(g.latitude));
}

Mat3 EnuFrame::axes_at(const GeodeticPoint& g) const {
  const double sl = std::sin(g.latitude), cl = std::cos(g.latitude);
  const double so = std::sin(g.longitude), co = std::cos(g.longitude);
  Mat3 local;  // columns: east, north, up at g, in ECEF
  local.col(0) = Vec3(-so, co, 0.0);
  local.col(1) = Vec3(-sl * co, -sl * so, cl);
  local.col(2) = Vec3(cl * co, cl * so, sl);
  return ecef_to_enu_ * local;
}

}  // namespace trackflow::sim
