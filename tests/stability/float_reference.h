#pragma once
// Shared by the float-against-double reference tests (float_reference_test.cc,
// viewer_float_reference_test.cc): float's epsilon and the report of a test's worst error.
#include <cstdio>
#include <limits>
#include <string>

#include <gtest/gtest.h>

namespace parallax::stability_test {

// Float's machine epsilon (2^-23): one rounding moves a value by at most kEps / 2 relative.
inline constexpr double kEps = std::numeric_limits<float>::epsilon();

// Prints the worst error (and its bound, where one is asserted) and records it in the XML.
inline void Report(const std::string& name, double worst, double bound) {
  if (bound > 0) {
    std::printf("[ stability ] %s: worst %.3g, bound %.3g\n", name.c_str(), worst, bound);
  } else {
    std::printf("[ stability ] %s: worst %.3g\n", name.c_str(), worst);
  }
  testing::Test::RecordProperty(name, std::to_string(worst));
}

}  // namespace parallax::stability_test
