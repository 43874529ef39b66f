#pragma once
// The steady clock in seconds: the time spent since an instant, which stages, renders and frames
// report, and the time now, which the viewer's auto exposure adapts over.
#include <chrono>

namespace parallax {

inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

inline double MsSince(std::chrono::steady_clock::time_point start) { return 1000 * SecondsSince(start); }

// Seconds on the steady clock: the viewer's frame clock unless it is given another.
inline double SteadySeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace parallax
