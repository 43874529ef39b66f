#include "reproject/holes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "reproject/simd.h"
#include "core/check.h"

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

// One source as the classification sees it: the target ray at depth z lands at
// point(z) = origin + z * R * ray_in_target, in the source frame.
struct SourceFrustum {
  Pinhole pinhole;
  Eigen::Matrix3d rotation;  // source_from_target.
  Eigen::Vector3d origin;    // Target centre in the source frame.
  const DepthMap* depth = nullptr;
  const uint8_t* background = nullptr;  // Null: no background.
};

// The sub-interval of [near, far] (far may be infinite; near == far == inf tests the
// direction) whose points lie inside the source image and in front of it, or false. Each
// constraint is c . point(z) >= 0, linear in z.
bool SegmentInFrustum(const SourceFrustum& s, const Eigen::Vector3d& dir, double near,
                      double far, double* lo_out = nullptr, double* hi_out = nullptr) {
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
  if (lo_out != nullptr) *lo_out = lo;
  if (hi_out != nullptr) *hi_out = hi;
  return true;
}

enum class PointView { kOutside, kFree, kHidden, kUnknown };

// What source `s` knows of the point at inverse depth `inv_depth` (0: the direction) on the
// target ray whose source-frame direction is `dir`: outside its image, empty space (its depth
// there is larger, or background), hidden (its depth is not larger), or unknown (depth 0 that
// is not background: the source saw something there, at a depth nobody knows). Inline: with
// two callers GCC stopped inlining it into RayIsHole's loop.
inline PointView ViewOfPoint(const SourceFrustum& s, const Eigen::Vector3d& dir,
                             double inv_depth, double tolerance) {
  // The point scaled by inv_depth: the same pixel, and z / depth = p.z().
  const Eigen::Vector3d p = s.origin * inv_depth + dir;
  if (!(p.z() > 0)) return PointView::kOutside;
  const double u = s.pinhole.fx * p.x() / p.z() + s.pinhole.cx;
  const double v = s.pinhole.fy * p.y() / p.z() + s.pinhole.cy;
  if (!(u >= 0 && v >= 0 && u < s.pinhole.width && v < s.pinhole.height)) {
    return PointView::kOutside;
  }
  const int x = static_cast<int>(u), y = static_cast<int>(v);
  const size_t i = static_cast<size_t>(y) * static_cast<size_t>(s.pinhole.width) +
                   static_cast<size_t>(x);
  const double depth = s.depth->Values()[i];
  if (depth == 0) {
    // Background is among the depth-0 pixels (MarkBackground): its mask is read only there,
    // not for every sample.
    return s.background != nullptr && s.background[i] != 0 ? PointView::kFree : PointView::kUnknown;
  }
  // depth > z * (1 + tolerance) with z = p.z() / inv_depth; at infinity nothing finite is
  // farther.
  return depth * inv_depth > p.z() * (1 + tolerance) ? PointView::kFree : PointView::kHidden;
}

// Whether the ray is a hole between inverse depths inv_near >= inv_far: a sampled point
// inside some source and seen as empty space by none (the ray reaches something hidden)
// beyond a point some source sees as empty space (the ray passed into the sources' view in
// the open), or a point some source saw without knowing its depth. A ray whose first points
// in any view are already hidden runs under a surface no source saw, from outside every view:
// the ground below the sources' frames, not a hole. Sampling starts at half the near depth,
// so a surface at the near end counts, or at half `inv_nearest` (the nearest surface anywhere
// in the target) where that is nearer: an occluder outside the nearby rows' depth range (a
// disocclusion strip taller than depth_range_rows under a much nearer surface) must still be
// passed in free space.
bool RayIsHole(const std::vector<SourceFrustum>& sources, const std::vector<Eigen::Vector3d>& dirs,
               double inv_nearest, double inv_near, double inv_far, const HoleOptions& options) {
  const int samples = inv_near > inv_far ? options.free_space_samples : 1;
  const double inv_start = samples == 1 ? inv_near : 2 * std::max(inv_near, inv_nearest);
  const auto inv_depth_at = [&](int k) {
    return samples == 1 ? inv_far : inv_start + (inv_far - inv_start) * k / (samples - 1);
  };
  struct Seen {
    bool inside = false, free = false, unknown = false;
  };
  // Sources after one that sees the point as free are not asked: it is not hidden.
  const auto look = [&](double inv_depth) {
    Seen seen;
    for (size_t j = 0; j < sources.size() && !seen.free; ++j) {
      const PointView view = ViewOfPoint(sources[j], dirs[j], inv_depth,
                                         options.free_space_tolerance);
      seen.inside = seen.inside || view != PointView::kOutside;
      seen.free = view == PointView::kFree;
      seen.unknown = seen.unknown || view == PointView::kUnknown;
    }
    return seen;
  };
  // In order up to the first point seen as free: before it only a point some source saw
  // without knowing its depth makes a hole.
  int first_free = samples;
  const bool passed_free = samples == 1;
  for (int k = 0; k < samples; ++k) {
    const double inv_depth = inv_depth_at(k);
    const Seen seen = look(inv_depth);
    if (seen.inside && !seen.free && (passed_free || seen.unknown) && inv_depth <= inv_near) {
      return true;
    }
    if (seen.free) {
      first_free = k;
      break;
    }
  }
  // Beyond it any hidden point up to the near end does. A hole's ray has passed under what
  // the sources saw by its far end, so the points are looked at from there back: the same
  // answer after a few points instead of most of them.
  for (int k = samples - 1; k > first_free; --k) {
    const double inv_depth = inv_depth_at(k);
    const Seen seen = look(inv_depth);
    if (seen.inside && !seen.free && inv_depth <= inv_near) return true;
  }
  return false;
}

// Whether the sky may lie behind what the sources saw in the ray's direction: no source that
// contains the direction saw it without knowing its depth (depth 0 that is not background,
// such as ground whose estimate failed: a surface, not sky).
bool OpenToSky(const std::vector<SourceFrustum>& sources, const std::vector<Eigen::Vector3d>& dirs,
               const HoleOptions& options) {
  for (size_t j = 0; j < sources.size(); ++j) {
    if (ViewOfPoint(sources[j], dirs[j], 0, options.free_space_tolerance) == PointView::kUnknown) {
      return false;
    }
  }
  return true;
}

std::vector<DepthRange> RowDepthRanges(const BlendResult& blend) {
  const int width = blend.color.Width(), height = blend.color.Height();
  std::vector<DepthRange> rows(static_cast<size_t>(height));
  tbb::parallel_for(0, height, [&](int y) {
    const size_t row = static_cast<size_t>(y) * static_cast<size_t>(width);
    const SampleKind* kind = blend.kind.data() + row;
    const float* depth = blend.depth.Values().data() + row;
    // In float and without branches (surface depths are positive and finite).
    float near = std::numeric_limits<float>::infinity(), far = 0;
    bool background = false;
    for (int x = 0; x < width; ++x) {
      const bool surface = kind[x] == SampleKind::kSurface;
      near = std::min(near, surface ? depth[x] : std::numeric_limits<float>::infinity());
      far = std::max(far, surface ? depth[x] : 0.0f);
      background = background || kind[x] == SampleKind::kBackground;
    }
    DepthRange& range = rows[static_cast<size_t>(y)];
    if (near <= far) {
      range.near = near;
      range.far = far;
    }
    range.background = background;
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
      const size_t row = static_cast<size_t>(y) * static_cast<size_t>(width);
      simd::ForEachMarked(hole.data() + row, width, [&](int x) { body(x, y, row + static_cast<size_t>(x)); });
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
  RequireOption(crack_opening_px >= 1 && crack_opening_px % 2 == 1, "HoleOptions.crack_opening_px",
                crack_opening_px, "odd and >= 1");
  RequireOption(depth_range_rows >= 0, "HoleOptions.depth_range_rows", depth_range_rows, ">= 0");
  RequireOption(free_space_samples >= 2 && free_space_samples <= 1024, "HoleOptions.free_space_samples",
                free_space_samples, "[2, 1024]");
  RequireOption(free_space_tolerance > 0 && free_space_tolerance < 1, "HoleOptions.free_space_tolerance",
                free_space_tolerance, "(0, 1)");
}

ClassMap ClassifyPixels(const BlendResult& blend, const std::vector<PosedCamera>& sources,
                        const PosedCamera& target, const HoleOptions& options) {
  std::vector<ClassifySource> frustums;
  for (const PosedCamera& source : sources) frustums.push_back({source, nullptr, nullptr});
  return ClassifyPixels(blend, frustums, target, options);
}

namespace {

// Each source's frustum in the target's frame. `*all_depth`: every source has a depth map.
// Throws InternalError for a depth map or mask that does not match its camera.
std::vector<SourceFrustum> MakeFrustums(const std::vector<ClassifySource>& sources,
                                        const PosedCamera& target, bool* all_depth) {
  std::vector<SourceFrustum> frustums;
  *all_depth = !sources.empty();
  for (size_t j = 0; j < sources.size(); ++j) {
    const ClassifySource& source = sources[j];
    const Rigid3d source_from_target =
        RelativePose(target.cam_from_world, source.camera.cam_from_world);
    SourceFrustum frustum{Pinhole::From(source.camera.camera),
                          source_from_target.rotation.toRotationMatrix(),
                          source_from_target.translation, source.depth, nullptr};
    const size_t count = static_cast<size_t>(frustum.pinhole.width) *
                         static_cast<size_t>(frustum.pinhole.height);
    if (source.depth != nullptr &&
        (source.depth->Width() != frustum.pinhole.width ||
         source.depth->Height() != frustum.pinhole.height ||
         (source.background != nullptr && !source.background->empty() &&
          source.background->size() != count))) {
      throw InternalError("ClassifyPixels: source " + std::to_string(j) +
                          ": depth map or background mask does not match its camera");
    }
    if (source.background != nullptr && !source.background->empty()) {
      frustum.background = source.background->data();
    }
    *all_depth = *all_depth && source.depth != nullptr;
    frustums.push_back(frustum);
  }
  return frustums;
}

}  // namespace

ClassMap ClassifyPixels(const BlendResult& blend, const std::vector<ClassifySource>& sources,
                        const PosedCamera& target, const HoleOptions& options) {
  options.Check();
  const Pinhole pinhole = Pinhole::From(target.camera);
  const int width = pinhole.width, height = pinhole.height;
  if (blend.color.Width() != width || blend.color.Height() != height) {
    throw InternalError("ClassifyPixels: blend " + std::to_string(blend.color.Width()) +
                        "x" + std::to_string(blend.color.Height()) +
                        " does not match the target camera " + std::to_string(width) +
                        "x" + std::to_string(height));
  }
  bool all_depth = false;
  const std::vector<SourceFrustum> frustums = MakeFrustums(sources, target, &all_depth);
  const std::vector<DepthRange> rows = RowDepthRanges(blend);
  DepthRange global;
  for (const DepthRange& row : rows) global.Merge(row);
  const double inv_nearest = global.HasSurface() ? 1 / global.near : 0;

  ClassMap map{width, height, std::vector<PixelClass>(blend.kind.size()), {}};
  if (all_depth) map.open_to_sky.assign(blend.kind.size(), 0);
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
    std::vector<Eigen::Vector3d> dirs(frustums.size());
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
      const Eigen::Vector3d ray = pinhole.PixelRay(x, y);
      // The span of depths some source's frustum holds (inverse depths, nearest first).
      double inv_near = 0, inv_far = kInf;
      bool in_view = false;
      for (size_t j = 0; j < frustums.size(); ++j) {
        dirs[j] = frustums[j].rotation * ray;
        double lo = 0, hi = 0;
        if (!SegmentInFrustum(frustums[j], dirs[j], near, far, &lo, &hi)) continue;
        in_view = true;
        inv_near = std::max(inv_near, 1 / lo);
        inv_far = std::min(inv_far, std::isinf(hi) ? 0.0 : 1 / hi);
      }
      if (in_view && all_depth) {
        in_view = RayIsHole(frustums, dirs, inv_nearest, inv_near, inv_far, options);
      }
      map.classes[i] = in_view ? PixelClass::kDisocclusion : PixelClass::kOutOfView;
      hole[i] = in_view ? 1 : 0;
      if (in_view && all_depth) map.open_to_sky[i] = OpenToSky(frustums, dirs, options) ? 1 : 0;
    }
  });

  // Holes an opening removes are thin: cracks between samples, not hidden surface.
  MarkCracks(hole, width, height, options.crack_opening_px / 2, &map);
  return map;
}

ClassCounts CountClasses(const ClassMap& classes) {
  static_assert(static_cast<size_t>(PixelClass::kDisocclusion) + 1 == kPixelClasses);
  // Blocks counted in parallel, sixteen pixels at a time: per class a vector of sixteen byte
  // counters (a comparison gives -1 per match), emptied before one can overflow.
  using Bytes = uint8_t __attribute__((vector_size(16)));
  constexpr size_t kVectors = 255;  // Per byte counter, at most this many matches.
  constexpr size_t kBlock = 16 * kVectors;
  const size_t count = classes.classes.size();
  const size_t blocks = (count + kBlock - 1) / kBlock;
  const uint8_t* bytes = reinterpret_cast<const uint8_t*>(classes.classes.data());
  std::vector<ClassCounts> per_block(blocks);
  tbb::parallel_for(size_t{0}, blocks, [&](size_t b) {
    const size_t begin = b * kBlock, end = std::min(count, begin + kBlock);
    std::array<size_t, kPixelClasses>& counts = per_block[b].pixels;
    Bytes matches[kPixelClasses] = {};
    size_t i = begin;
    for (; i + 16 <= end; i += 16) {
      Bytes pixels;
      std::memcpy(&pixels, bytes + i, sizeof(pixels));
      for (uint8_t c = 0; c < kPixelClasses; ++c) matches[c] -= reinterpret_cast<Bytes>(pixels == c);
    }
    for (size_t c = 0; c < kPixelClasses; ++c) {
      for (size_t k = 0; k < 16; ++k) counts[c] += matches[c][k];
    }
    for (; i < end; ++i) ++counts[bytes[i]];
  });
  ClassCounts total;
  for (const ClassCounts& block : per_block) {
    for (size_t c = 0; c < kPixelClasses; ++c) total.pixels[c] += block.pixels[c];
  }
  return total;
}

HoleMetrics ComputeHoleMetrics(const ClassMap& classes) {
  HoleMetrics metrics;
  const size_t count = classes.classes.size();
  if (count == 0) return metrics;
  const ClassCounts counts = CountClasses(classes);
  const auto ratio = [&](PixelClass c) {
    return static_cast<double>(counts[c]) / static_cast<double>(count);
  };
  metrics.covered_ratio = ratio(PixelClass::kCovered);
  metrics.background_ratio = ratio(PixelClass::kBackground);
  metrics.out_of_view_ratio = ratio(PixelClass::kOutOfView);
  metrics.crack_ratio = ratio(PixelClass::kCrack);
  metrics.disocclusion_ratio = ratio(PixelClass::kDisocclusion);
  metrics.hole_ratio = metrics.crack_ratio + metrics.disocclusion_ratio;
  if (counts[PixelClass::kCrack] + counts[PixelClass::kDisocclusion] == 0) return metrics;

  // 8-connected components by flood fill; each pixel is pushed once, so the stack never
  // outgrows the image. The search for the next unseen hole pixel skips eight pixels at a time
  // where none is a hole (holes are a few percent of the image).
  static_assert(static_cast<int>(PixelClass::kCrack) == 3 &&
                static_cast<int>(PixelClass::kDisocclusion) == 4);
  const int width = classes.width, height = classes.height;
  const uint8_t* bytes = reinterpret_cast<const uint8_t*>(classes.classes.data());
  std::vector<uint8_t> seen(count, 0);
  std::vector<size_t> stack;
  for (size_t start = 0; start < count; ++start) {
    if (start % 8 == 0 && start + 8 <= count) {
      uint64_t eight;
      std::memcpy(&eight, bytes + start, sizeof(eight));
      // A byte is a hole class (3 or 4, the largest) where adding 125 sets its high bit; the
      // classes are below 128, so no byte carries into the next.
      if (((eight + 0x7D7D7D7D7D7D7D7DULL) & 0x8080808080808080ULL) == 0) {
        start += 7;
        continue;
      }
    }
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
