// Purpose: the state layout of filter.refraction_ekf (paper 004's 13-state augmented model): each component's index, name and unit, shared by the filter and by sink.elevation_error, which reads the bias estimate.
#pragma once

#include <trackflow/items.hpp>

namespace trackflow::refraction_ekf {

inline constexpr int kN = 13;

// State order (paper 004 eq 7, with the previous velocity that its dynamics use):
// [x, vx, vx_prev, y, vy, vy_prev, z, vz, vz_prev, range, azimuth, elevation, b]; x, y, z from the
// radar in the ENU axes (m), velocities m/s, angles rad. kBias is what sink.elevation_error reads
// from Estimate::state.
enum Index : int { kX = 0, kY = 3, kZ = 6, kRange = 9, kAzimuth = 10, kElevation = 11, kBias = 12 };
inline constexpr int kVel = 1, kPrev = 2;  // offsets within an axis block
inline int pos(int axis) { return 3 * axis; }
inline int vel(int axis) { return 3 * axis + kVel; }
inline int prev(int axis) { return 3 * axis + kPrev; }

// Names and units of the state, in order (the filter's state_layout()).
inline constexpr StateComponent kLayout[kN] = {
    {"x", "m"},         {"vx", "m/s"},  {"vx_prev", "m/s"}, {"y", "m"},         {"vy", "m/s"},
    {"vy_prev", "m/s"}, {"z", "m"},     {"vz", "m/s"},      {"vz_prev", "m/s"}, {"range", "m"},
    {"azimuth", "rad"}, {"elevation", "rad"}, {"bias", "rad"}};

}  // namespace trackflow::refraction_ekf
