#include "geometry/robust_bounds.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

namespace parallax {

Eigen::AlignedBox3f RobustBounds(const std::vector<Eigen::Vector3f>& points, float outlier_fraction) {
  if (!(outlier_fraction >= 0 && outlier_fraction < 0.5f)) {
    throw InternalError("RobustBounds: outlier_fraction must be in [0, 0.5), got " +
                        std::to_string(outlier_fraction));
  }
  Eigen::AlignedBox3f box;
  if (points.empty()) return box;
  const size_t n = points.size();
  const size_t low = static_cast<size_t>(std::floor(static_cast<double>(outlier_fraction) * static_cast<double>(n - 1)));
  const size_t high = n - 1 - low;
  const float widen = outlier_fraction / (1 - 2 * outlier_fraction);
  std::vector<float> values(n);
  for (int axis = 0; axis < 3; ++axis) {
    for (size_t i = 0; i < n; ++i) values[i] = points[i][axis];
    // nth_element: linear time, the cloud can hold millions of points.
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(low), values.end());
    const float lo = values[low];
    const float min = *std::min_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(low) + 1);
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(high), values.end());
    const float hi = values[high];
    const float max = *std::max_element(values.begin() + static_cast<std::ptrdiff_t>(high), values.end());
    const float margin = widen * (hi - lo);
    box.min()[axis] = std::max(min, lo - margin);
    box.max()[axis] = std::min(max, hi + margin);
  }
  return box;
}

}  // namespace parallax
