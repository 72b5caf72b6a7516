// Design: the one home of angle-unit conversions. Names say what the number is:
// `angle_deg * kRadPerDeg` is in radians, `angle_rad * kDegPerRad` in degrees.
#pragma once

#include <numbers>

namespace mocap {

inline constexpr double kRadPerDeg = std::numbers::pi / 180.0;
inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;

}  // namespace mocap
