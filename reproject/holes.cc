#include "reproject/holes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace parallax {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct DepthRange {
  double near = kInf;
  double far = 0;
  bool background = false;

  void Merge(const DepthRange& other) {
    near = std::min(near, other.near);
    far = std::max(far, other.far);
    background = background || other.background;
  }
  bool HasSurface() const { return near <= far; }
};

// One source as the frustum test sees it: the target ray at depth z lands at
// point(z) = origin + z * R * ray_in_target, in the source frame.
struct SourceFrustum {
  Pinhole pinhole;
  Eigen::Matrix3d rotation;  // source_from_target.
  Eigen::Vector3d origin;    // Target centre in the source frame.
};

// Whether some z in [near, far] (far may be infinite; near == far == inf tests the
// direction) puts the point inside the source image and in front of it. Each constraint is
// c . point(z) >= 0, linear in z.
bool SegmentInFrustum(const SourceFrustum& s, const Eigen::Vector3d& ray, double near,
                      double far) {
  const Eigen::Vector3d dir = s.rotation * ray;
  const double w = s.pinhole.width, h = s.pinhole.height;
  const std::array<Eigen::Vector3d, 5> constraints = {
      Eigen::Vector3d(0, 0, 1),
      Eigen::Vector3d(s.pinhole.fx, 0, s.pinhole.cx),
      Eigen::Vector3d(-s.pinhole.fx, 0, w - s.pinhole.cx),
      Eigen::Vector3d(0, s.pinhole.fy, s.pinhole.cy),
      Eigen::Vector3d(0, -s.pinhole.fy, h - s.pinhole.cy)};
  double lo = near, hi = far;
  for (const Eigen::Vector3d& c : constraints) {
    const double alpha = c.dot(s.origin), beta = c.dot(dir);
    if (beta > 0) {
      lo = std::max(lo, -alpha / beta);
    } else if (beta < 0) {
      hi = std::min(hi, -alpha / beta);
    } else if (alpha < 0) {
      return false;
    }
    if (!(lo <= hi)) return false;
  }
  return true;
}

std::vector<DepthRange> RowDepthRanges(const BlendResult& blend) {
  const int width = blend.color.Width(), height = blend.color.Height();
  std::vector<DepthRange> rows(static_cast<size_t>(height));
  tbb::parallel_for(0, height, [&](int y) {
    DepthRange& range = rows[static_cast<size_t>(y)];
    for (int x = 0; x < width; ++x) {
      const SampleKind kind = blend.Kind(x, y);
      if (kind == SampleKind::kBackground) range.background = true;
      if (kind != SampleKind::kSurface) continue;
      const double depth = blend.depth.At(x, y);
      range.near = std::min(range.near, depth);
      range.far = std::max(range.far, depth);
    }
  });
  return rows;
}

// Whether every (all) or some (!all) pixel of the square of side 2 * radius + 1 around
// (x, y) is set; outside the image counts as not set.
bool SquareTest(const std::vector<uint8_t>& mask, int width, int height, int x, int y,
                int radius, bool all) {
  for (int ny = y - radius; ny <= y + radius; ++ny) {
    for (int nx = x - radius; nx <= x + radius; ++nx) {
      const bool set = nx >= 0 && ny >= 0 && nx < width && ny < height &&
                       mask[static_cast<size_t>(ny) * static_cast<size_t>(width) +
                            static_cast<size_t>(nx)] != 0;
      if (all && !set) return false;
      if (!all && set) return true;
    }
  }
  return all;
}

// Marks as cracks the hole pixels a morphological opening (erosion, then dilation, with the
// same square) removes. Both steps only look at hole pixels: holes are sparse.
void MarkCracks(const std::vector<uint8_t>& hole, int width, int height, int radius,
                ClassMap* map) {
  std::vector<uint8_t> eroded(hole.size(), 0);
  const auto for_holes = [&](const auto& body) {
    tbb::parallel_for(0, height, [&](int y) {
      for (int x = 0; x < width; ++x) {
        const size_t i = static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
        if (hole[i] != 0) body(x, y, i);
      }
    });
  };
  for_holes([&](int x, int y, size_t i) {
    eroded[i] = SquareTest(hole, width, height, x, y, radius, true) ? 1 : 0;
  });
  for_holes([&](int x, int y, size_t i) {
    if (!SquareTest(eroded, width, height, x, y, radius, false)) map->classes[i] = PixelClass::kCrack;
  });
}

}  // namespace

void HoleOptions::Check() const {
  if (crack_opening_px < 1 || crack_opening_px % 2 == 0) {
    throw std::invalid_argument("HoleOptions.crack_opening_px = " +
                                std::to_string(crack_opening_px) + ": expected odd and >= 1");
  }
  if (depth_range_rows < 0) {
    throw std::invalid_argument("HoleOptions.depth_range_rows = " +
                                std::to_string(depth_range_rows) + ": expected >= 0");
  }
}

ClassMap ClassifyPixels(const BlendResult& blend, const std::vector<PosedCamera>& sources,
                        const PosedCamera& target, const HoleOptions& options) {
  options.Check();
  const Pinhole pinhole = Pinhole::From(target.camera);
  const int width = pinhole.width, height = pinhole.height;
  if (blend.color.Width() != width || blend.color.Height() != height) {
    throw std::invalid_argument("ClassifyPixels: blend " + std::to_string(blend.color.Width()) +
                                "x" + std::to_string(blend.color.Height()) +
                                " does not match the target camera " + std::to_string(width) +
                                "x" + std::to_string(height));
  }
  std::vector<SourceFrustum> frustums;
  for (const PosedCamera& source : sources) {
    const Rigid3d source_from_target = RelativePose(target.cam_from_world, source.cam_from_world);
    frustums.push_back({Pinhole::From(source.camera),
                        source_from_target.rotation.toRotationMatrix(),
                        source_from_target.translation});
  }
  const std::vector<DepthRange> rows = RowDepthRanges(blend);
  DepthRange global;
  for (const DepthRange& row : rows) global.Merge(row);

  ClassMap map{width, height, std::vector<PixelClass>(blend.kind.size())};
  std::vector<uint8_t> hole(blend.kind.size(), 0);
  tbb::parallel_for(0, height, [&](int y) {
    DepthRange range;
    for (int r = std::max(0, y - options.depth_range_rows);
         r <= std::min(height - 1, y + options.depth_range_rows); ++r) {
      range.Merge(rows[static_cast<size_t>(r)]);
    }
    if (!range.HasSurface()) range = global;
    // No surface anywhere: only the direction (infinite depth) can be tested.
    const double near = range.HasSurface() ? range.near : kInf;
    const double far = range.background || !range.HasSurface() ? kInf : range.far;
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
      const SampleKind kind = blend.kind[i];
      if (kind == SampleKind::kSurface) {
        map.classes[i] = PixelClass::kCovered;
        continue;
      }
      if (kind == SampleKind::kBackground) {
        map.classes[i] = PixelClass::kBackground;
        continue;
      }
      const Eigen::Vector3d ray((x + 0.5 - pinhole.cx) / pinhole.fx,
                                (y + 0.5 - pinhole.cy) / pinhole.fy, 1.0);
      const bool in_view = std::any_of(frustums.begin(), frustums.end(), [&](const SourceFrustum& s) {
        return SegmentInFrustum(s, ray, near, far);
      });
      map.classes[i] = in_view ? PixelClass::kDisocclusion : PixelClass::kOutOfView;
      hole[i] = in_view ? 1 : 0;
    }
  });

  // Holes an opening removes are thin: cracks between samples, not hidden surface.
  MarkCracks(hole, width, height, options.crack_opening_px / 2, &map);
  return map;
}

HoleMetrics ComputeHoleMetrics(const ClassMap& classes) {
  HoleMetrics metrics;
  const size_t count = classes.classes.size();
  if (count == 0) return metrics;
  std::array<size_t, 5> histogram{};
  for (PixelClass c : classes.classes) ++histogram[static_cast<size_t>(c)];
  const double total = static_cast<double>(count);
  metrics.covered_ratio = static_cast<double>(histogram[0]) / total;
  metrics.background_ratio = static_cast<double>(histogram[1]) / total;
  metrics.out_of_view_ratio = static_cast<double>(histogram[2]) / total;
  metrics.crack_ratio = static_cast<double>(histogram[3]) / total;
  metrics.disocclusion_ratio = static_cast<double>(histogram[4]) / total;
  metrics.hole_ratio = metrics.crack_ratio + metrics.disocclusion_ratio;

  // 8-connected components by flood fill; each pixel is pushed once, so the stack never
  // outgrows the image.
  const int width = classes.width, height = classes.height;
  std::vector<uint8_t> seen(count, 0);
  std::vector<size_t> stack;
  stack.reserve(count);
  for (size_t start = 0; start < count; ++start) {
    if (seen[start] != 0 || !IsHole(classes.classes[start])) continue;
    seen[start] = 1;
    stack.push_back(start);
    int size = 0;
    while (!stack.empty()) {
      const size_t i = stack.back();
      stack.pop_back();
      ++size;
      const int x = static_cast<int>(i % static_cast<size_t>(width));
      const int y = static_cast<int>(i / static_cast<size_t>(width));
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
          const size_t j = static_cast<size_t>(ny) * static_cast<size_t>(width) + static_cast<size_t>(nx);
          if (seen[j] != 0 || !IsHole(classes.classes[j])) continue;
          seen[j] = 1;
          stack.push_back(j);
        }
      }
    }
    ++metrics.hole_count;
    metrics.largest_hole_px = std::max(metrics.largest_hole_px, size);
  }
  return metrics;
}

Image ClassMask(const ClassMap& classes, PixelClass pixel_class) {
  Image mask(classes.width, classes.height, 1);
  for (size_t i = 0; i < classes.classes.size(); ++i) {
    mask.Pixels()[i] = classes.classes[i] == pixel_class ? 1.0f : 0.0f;
  }
  return mask;
}

}  // namespace parallax
