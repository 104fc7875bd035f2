// Purpose: WGS-84 geodetic sites (latitude, longitude, height) and the pipeline's ENU frame anchored at one of them, through GeographicLib; shared by sim.trajectory and sim.radar.
#pragma once

#include <trackflow/items.hpp>
#include <trackflow/params.hpp>

#include <GeographicLib/LocalCartesian.hpp>

#include <string>
#include <string_view>
#include <vector>

namespace trackflow::sim {

// A point on or above the WGS-84 ellipsoid: geodetic latitude and longitude in rad, height above
// the ellipsoid in m.
struct GeodeticPoint {
  double latitude = 0.0, longitude = 0.0, height = 0.0;
};

struct Site {
  std::string name;
  GeodeticPoint where;
};

// The fields of one site record and the two parameters a geodetic component declares. The
// pipeline's top-level `sites:` map and `pipeline.frame_origin` are handed to every node that
// declares `sites` / `frame_origin` (docs/pipeline-yaml.md), so a node rarely sets them itself.
std::vector<ParamSpec> site_fields();
ParamSpec sites_param();
ParamSpec frame_origin_param();

// The sites of the node's `sites` parameter (empty when it has none).
std::vector<Site> read_sites(const Params& p);
// The site named by the string parameter `name_param`; a ConfigError at that parameter when the
// name is not a site (with a suggestion) or there are no sites.
Site find_site(const Params& p, const std::vector<Site>& sites, std::string_view name_param);

// The pipeline's local ENU frame: east, north, up at the origin site, its origin at that site.
// Geodetic <-> ECEF is GeographicLib's (Geocentric, WGS-84); ECEF -> ENU is the rotation into the
// origin's east/north/up axes; ENU -> geodetic is GeographicLib's LocalCartesian::Reverse.
class EnuFrame {
 public:
  explicit EnuFrame(const GeodeticPoint& origin);
  // The frame named by `frame_origin` among `sites`; ConfigError when either is missing.
  static EnuFrame from_params(const Params& p, const std::vector<Site>& sites, std::string_view needed_by);

  Vec3 to_enu(const GeodeticPoint& g) const;  // through ECEF
  GeodeticPoint to_geodetic(const Vec3& enu) const;
  Vec3 ecef(const GeodeticPoint& g) const;
  Vec3 ecef_to_enu(const Vec3& ecef) const;
  // Unit vector of the local vertical (ellipsoid normal) at g, in this frame's axes.
  Vec3 up_at(const GeodeticPoint& g) const;
  // The local east, north and up unit vectors at g (columns), in this frame's axes: a sensor
  // there measures its angles in them (Measurement::sensor_axes).
  Mat3 axes_at(const GeodeticPoint& g) const;
  const GeodeticPoint& origin() const { return origin_; }
  const GeographicLib::LocalCartesian& local() const { return local_; }

 private:
  GeodeticPoint origin_;
  GeographicLib::LocalCartesian local_;
  Vec3 origin_ecef_ = Vec3::Zero();
  Mat3 ecef_to_enu_ = Mat3::Identity();  // rows: east, north, up at the origin, in ECEF
};

inline constexpr double kRadToDeg = 57.29577951308232;

}  // namespace trackflow::sim
