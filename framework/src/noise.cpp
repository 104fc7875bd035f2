// Purpose: the typed filter–adapter contract: descriptions, the compatibility check, and conversions between noise spaces.
#include <trackflow/geometry.hpp>
#include <trackflow/noise.hpp>

#include <string>

namespace trackflow {

const char* to_string(NoiseKind k) {
  return k == NoiseKind::SpectralDensity ? "spectral density" : "standard deviation";
}

const char* to_string(NoiseAxes a) {
  switch (a) {
    case NoiseAxes::Common: return "one value on every ENU axis";
    case NoiseAxes::Enu: return "per ENU axis (east, north, up)";
    case NoiseAxes::LineOfSight: return "per line-of-sight channel (radial, horizontal, vertical cross-range)";
  }
  return "?";
}

const char* to_string(MeasurementSpace s) {
  switch (s) {
    case MeasurementSpace::None: return "none";
    case MeasurementSpace::CartesianPosition: return "cartesian_position";
    case MeasurementSpace::Spherical: return "spherical";
  }
  return "?";
}

std::string describe(MeasurementSpace s) {
  switch (s) {
    case MeasurementSpace::None: return "no measurement noise R";
    case MeasurementSpace::CartesianPosition: return "R of Cartesian positions [x, y, z] in m";
    case MeasurementSpace::Spherical: return "R of [range m, azimuth rad, elevation rad(, range rate m/s)]";
  }
  return "?";
}

namespace {

std::string plural_kind(NoiseKind k, int count) {
  std::string s = to_string(k);
  if (count == 1) return s;
  return k == NoiseKind::SpectralDensity ? "spectral densities" : "standard deviations";
}

std::string axes_list(NoiseAxesMask m) {
  std::string s;
  for (NoiseAxes a : {NoiseAxes::Common, NoiseAxes::Enu, NoiseAxes::LineOfSight}) {
    if (!(m & mask(a))) continue;
    if (!s.empty()) s += " or ";
    s += to_string(a);
  }
  return s.empty() ? "no axes" : s;
}

}  // namespace

std::string describe(const ProcessNoiseHandle& h) {
  if (!h) return "no process noise";
  return std::to_string(h.count) + " " + plural_kind(h.kind, h.count) + " in " + h.dimension.str() + ", " +
         to_string(h.axes);
}

std::string describe_needs(const NoiseNeeds& n) {
  std::string s;
  auto add = [&](const std::string& part) { s += (s.empty() ? "" : "; ") + part; };
  if (n.measurement != MeasurementSpace::None) add(describe(n.measurement));
  if (n.process)
    add(std::string(n.process_kind == NoiseKind::SpectralDensity ? "spectral densities" : "standard deviations") +
        " in " + n.process_dimension.str() + ", " + axes_list(n.process_axes));
  if (n.covariance) add("access to the state covariance");
  return s.empty() ? "nothing" : s;
}

std::string noise_mismatch(const NoiseNeeds& needs, const NoiseHandles& offered, bool offers_covariance) {
  std::string why;
  auto add = [&](const std::string& part) { why += (why.empty() ? "" : "; ") + part; };
  if (needs.measurement != MeasurementSpace::None) {
    const std::string wants = "the adapter writes " + describe(needs.measurement) + " (space '" +
                              to_string(needs.measurement) + "')";
    if (!offered.measurement)
      add(wants + ", but the filter exposes no measurement noise");
    else if (offered.measurement.space != needs.measurement)
      add(wants + ", but the filter's R is " + describe(offered.measurement.space) + " (space '" +
          to_string(offered.measurement.space) + "')");
  }
  if (needs.process) {
    const ProcessNoiseHandle& q = offered.process;
    const std::string wants = "the adapter writes process noise as " + describe_needs({MeasurementSpace::None, true,
                                                                                       needs.process_kind,
                                                                                       needs.process_dimension,
                                                                                       needs.process_axes, false});
    if (!q)
      add(wants + ", but the filter exposes no process noise");
    else if (q.kind != needs.process_kind || !(q.dimension == needs.process_dimension) ||
             !(needs.process_axes & mask(q.axes)))
      add(wants + ", but the filter's process noise is " + describe(q));
  }
  if (needs.covariance && !offers_covariance)
    add("the adapter reads or rescales the state covariance, which the filter does not expose");
  return why;
}

Vec3 line_of_sight_psd(const ChannelPsd& q, double r, double el) {
  const double rh = r * std::cos(el);
  return {q.range, rh * rh * q.azimuth, r * r * q.elevation};
}

Vec3 enu_axis_psd(const ChannelPsd& q, double r, double az, double el, AzimuthConvention c) {
  const Mat3 J = spherical_to_enu_jacobian(r, az, el, c);
  return J.cwiseAbs2() * Vec3(q.range, q.azimuth, q.elevation);
}

}  // namespace trackflow
