#pragma once
// Bounds that ignore stray points. Reconstructions carry a few far outliers (a fused cloud
// reaching tens of scene sizes away, a mesh's far ground): framing, the grid and the shadow
// map follow these bounds, while clipping still uses the exact ones.
#include <vector>

#include <Eigen/Geometry>

namespace parallax {

// Per axis, from the `outlier_fraction` quantile to the 1 - `outlier_fraction` quantile of the
// points, widened on each side by outlier_fraction / (1 - 2 outlier_fraction) of that span
// (which gives back the exact bounds of evenly spread points), and never beyond the points'
// own bounds. So up to `outlier_fraction` of the points on each side of each axis, however
// far, do not move the box. Empty without points. Pure. Throws InternalError unless
// 0 <= outlier_fraction < 0.5.
Eigen::AlignedBox3f RobustBounds(const std::vector<Eigen::Vector3f>& points, float outlier_fraction = 0.02f);

}  // namespace parallax
