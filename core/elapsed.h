#pragma once
// Time spent since a steady-clock instant: what stages, renders and frames report.
#include <chrono>

namespace parallax {

inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

inline double MsSince(std::chrono::steady_clock::time_point start) { return 1000 * SecondsSince(start); }

}  // namespace parallax
