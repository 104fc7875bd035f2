// Purpose: typed filter–adapter contract: what each noise number a filter exposes is (kind, unit, space), what an adapter needs, and the helpers that convert between spaces.
#pragma once

#include <trackflow/items.hpp>
#include <trackflow/units.hpp>

#include <cstdint>
#include <string>

namespace trackflow {

// What a process-noise number means: a spectral density q of a white noise (m²/s³ for white
// acceleration, m²/s⁵ for white jerk) or a standard deviation (σ of a discrete white-noise
// acceleration, Singer's σ_m).
enum class NoiseKind : std::uint8_t { SpectralDensity, StandardDeviation };

// The axes the values apply to, one value each:
//   Common       one value on every ENU axis (count 1)
//   Enu          east, north, up (count 3)
//   LineOfSight  radial, horizontal cross-range, vertical cross-range at the target (count 3),
//                linear quantities (m, not rad), as filter.ekf_spherical's q_r, q_h, q_v
enum class NoiseAxes : std::uint8_t { Common = 1, Enu = 2, LineOfSight = 4 };
using NoiseAxesMask = std::uint8_t;
constexpr NoiseAxesMask mask(NoiseAxes a) { return static_cast<NoiseAxesMask>(a); }

// The space R is expressed in. Units of its components:
//   CartesianPosition  [x, y, z] in m (ENU)
//   Spherical          [range m, azimuth rad, elevation rad(, range rate m/s)]
enum class MeasurementSpace : std::uint8_t { None, CartesianPosition, Spherical };

const char* to_string(NoiseKind k);
const char* to_string(NoiseAxes a);
const char* to_string(MeasurementSpace s);

// Process noise a filter lets adapters overwrite between steps. The filter reads `values` at
// every prediction, so a write takes effect at the next step. The engine restores the values a
// filter had when it was built at the start of every run.
struct ProcessNoiseHandle {
  double* values = nullptr;
  int count = 0;
  NoiseKind kind = NoiseKind::SpectralDensity;
  Dimension dimension;
  NoiseAxes axes = NoiseAxes::Common;
  explicit operator bool() const { return values != nullptr && count > 0; }
};

// The measurement noise R the filter will use for the current measurement. The filter fills it
// from the measurement's own covariance before the adapters' before_update, so an adapter
// replaces it for this step.
struct MeasurementNoiseHandle {
  MeasCov* R = nullptr;
  MeasurementSpace space = MeasurementSpace::None;
  explicit operator bool() const { return R != nullptr && space != MeasurementSpace::None; }
};

struct NoiseHandles {
  MeasurementNoiseHandle measurement;
  ProcessNoiseHandle process;
};

// What an adapter reads and writes, in the same terms. Checked against the filter when the
// pipeline is built; a mismatch is a configuration error at the adapter's `attach_to:` line.
struct NoiseNeeds {
  MeasurementSpace measurement = MeasurementSpace::None;  // None: R is not touched
  bool process = false;
  NoiseKind process_kind = NoiseKind::SpectralDensity;
  Dimension process_dimension;
  NoiseAxesMask process_axes = 0;  // the axis layouts the adapter can write (it converts itself)
  bool covariance = false;         // reads or rescales the state covariance
};

// "3 spectral densities in m2/s5, per ENU axis (east, north, up)".
std::string describe(const ProcessNoiseHandle& h);
// "R of [range m, azimuth rad, elevation rad(, range rate m/s)]".
std::string describe(MeasurementSpace s);
std::string describe_needs(const NoiseNeeds& n);

// Empty when the filter offers what the adapter needs; otherwise one sentence per mismatch,
// each naming what the filter has and what the adapter needs.
std::string noise_mismatch(const NoiseNeeds& needs, const NoiseHandles& offered, bool offers_covariance);

// --- conversions between spaces, for adapters that hold noise per radar channel ---

// White-jerk (or white-acceleration) spectral densities per measurement channel: range in
// m²/s^k, azimuth and elevation in rad²/s^k.
struct ChannelPsd {
  double range = 0.0, azimuth = 0.0, elevation = 0.0;
};

// Linear PSDs along the local spherical basis at (r, el): radial, horizontal cross-range (an
// angular rate of the azimuth moves the target by r cos(el) per radian) and vertical cross-range
// (r per radian of elevation). This is NoiseAxes::LineOfSight.
Vec3 line_of_sight_psd(const ChannelPsd& q, double r, double el);

// The same noise as an ENU PSD is J diag(q) Jᵀ with J = ∂(x, y, z)/∂(r, az, el), a full 3×3 matrix
// unless the line of sight lies along an axis. A filter with one intensity per ENU axis can only
// take its diagonal, Σ_i J_ei² q_i: the trace (total power) is kept, the orientation of the
// noise ellipsoid is lost off the axes. This is NoiseAxes::Enu.
Vec3 enu_axis_psd(const ChannelPsd& q, double r, double az, double el, AzimuthConvention c);

}  // namespace trackflow
