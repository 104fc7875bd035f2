// Purpose: parameter declarations several plugins share (azimuth convention, range-rate use, angle-noise plausibility), each with its enum.
#pragma once

#include <trackflow/items.hpp>
#include <trackflow/params.hpp>

#include <cstdint>
#include <string>

namespace trackflow {

// Whether a spherical filter uses the measurement's range rate (the 4th value).
enum class RangeRateUse : std::uint8_t { Auto, Use, Ignore };

// The word range_rate_param() reads as `r`, for messages.
inline const char* to_string(RangeRateUse r) {
  switch (r) {
    case RangeRateUse::Auto: return "auto";
    case RangeRateUse::Use: return "use";
    case RangeRateUse::Ignore: return "ignore";
  }
  return "?";
}

inline ParamSpec range_rate_param() {
  return ParamSpec::choice<RangeRateUse>(
             "range_rate", {{RangeRateUse::Auto, "auto"}, {RangeRateUse::Use, "use"}, {RangeRateUse::Ignore, "ignore"}},
             "use the 4th element (range rate): when present (auto), always (use), never (ignore)")
      .def("auto");
}

inline ParamSpec azimuth_convention_param(std::string doc) {
  return ParamSpec::choice<AzimuthConvention>("azimuth_convention",
                                              {{AzimuthConvention::NorthClockwise, "north_clockwise"},
                                               {AzimuthConvention::XCounterClockwise, "x_counterclockwise"}},
                                              std::move(doc))
      .def("north_clockwise");
}

// An angle noise sigma (azimuth, elevation, bearing): valid above 0.3 rad, but seldom meant
// (issue 26): `sigma_azimuth: 2 rad` written for 2 deg gives a 37 km RMSE at 20 km. Warned about
// at validate, e.g. ParamSpec::real("sigma_azimuth", dim::angle, "...").def("1 mrad").plausible_up_to(
// kPlausibleAngleSigma, kAngleSigmaHint).
inline constexpr double kPlausibleAngleSigma = 0.3;
inline constexpr const char* kAngleSigmaHint =
    "an angle noise sigma above 0.3 rad (17.2 deg) is almost never a radar's; degrees written as radians?";

}  // namespace trackflow
