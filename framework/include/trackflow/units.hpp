// Purpose: physical dimensions and parsing of quantities such as "3 mrad", "1.5 km", "40 Hz", "1 m2/s3".
#pragma once

#include <string>
#include <string_view>

namespace trackflow {

// Exponents of the base dimensions trackflow uses. Angle is kept as its own dimension
// (not dimensionless) so that "sigma_range: 3 mrad" is rejected; decibels likewise.
struct Dimension {
  int length = 0;
  int time = 0;
  int angle = 0;
  int decibel = 0;

  friend bool operator==(const Dimension&, const Dimension&) = default;
  Dimension operator*(const Dimension& o) const {
    return {length + o.length, time + o.time, angle + o.angle, decibel + o.decibel};
  }
  Dimension pow(int k) const { return {length * k, time * k, angle * k, decibel * k}; }
  bool dimensionless() const { return *this == Dimension{}; }
  // Canonical SI spelling, e.g. "m2/s3", "rad/s", "1" for dimensionless.
  std::string str() const;
};

namespace dim {
inline constexpr Dimension none{};
inline constexpr Dimension length{1, 0, 0, 0};
inline constexpr Dimension time{0, 1, 0, 0};
inline constexpr Dimension angle{0, 0, 1, 0};
inline constexpr Dimension decibel{0, 0, 0, 1};
inline constexpr Dimension frequency{0, -1, 0, 0};
inline constexpr Dimension velocity{1, -1, 0, 0};
inline constexpr Dimension acceleration{1, -2, 0, 0};
inline constexpr Dimension angular_rate{0, -1, 1, 0};
// Spectral density of white acceleration noise (q of the CV model).
inline constexpr Dimension accel_psd{2, -3, 0, 0};
// Spectral density of white jerk (q of the Wiener-process-acceleration CA model).
inline constexpr Dimension jerk_psd{2, -5, 0, 0};
}  // namespace dim

struct Quantity {
  double value = 0.0;  // in SI (m, s, rad; dB stays dB)
  Dimension dimension;
  bool had_unit = false;  // false for a bare number
};

// Parses "<number> [unit]". Units: m km cm mm um, s ms us min h, rad mrad urad µrad deg
// arcmin arcsec, Hz kHz MHz GHz, dB, with products/quotients and integer powers:
// "m/s", "m/s2", "m^2/s^3", "deg/s", "m2/s3". Throws std::invalid_argument with a
// readable reason on anything else.
Quantity parse_quantity(std::string_view text);

// Parses only a unit expression ("mrad", "m/s2") into its SI scale and dimension.
struct Unit {
  double scale = 1.0;
  Dimension dimension;
};
Unit parse_unit(std::string_view text);

}  // namespace trackflow
