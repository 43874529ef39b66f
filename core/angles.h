#pragma once
// Options, files and the command line give angles in degrees; trigonometry takes radians.
#include <numbers>

namespace parallax {

constexpr double Radians(double degrees) { return degrees * std::numbers::pi / 180; }

}  // namespace parallax
