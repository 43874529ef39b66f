#pragma once
// Classification of every target pixel after blending, and the hole metrics of DESIGN.md.
#include <cstdint>
#include <vector>

#include "core/image.h"
#include "reproject/blend.h"
#include "reproject/view.h"

namespace parallax {

enum class PixelClass : uint8_t {
  kCovered,       // A surface sample landed.
  kBackground,    // Only background-at-infinity samples landed (sky).
  kOutOfView,     // The pixel's ray, over the scene's depth range, is outside every source.
  kCrack,         // A thin hole (see HoleOptions::crack_opening_px) inside some source's view.
  kDisocclusion,  // A wider hole: surface hidden from every source.
};

inline bool IsHole(PixelClass c) { return c == PixelClass::kCrack || c == PixelClass::kDisocclusion; }

struct HoleOptions {
  // Hole pixels that a morphological opening with a square of this side removes are cracks
  // (so cracks are at most crack_opening_px - 1 pixels wide); odd, >= 1 (1: no cracks).
  int crack_opening_px = 3;
  // The out-of-view test takes the scene's depth range from the covered pixels this many rows
  // above and below the pixel (the whole image where those rows have none); >= 0.
  int depth_range_rows = 2;

  void Check() const;  // Throws std::invalid_argument naming the field and value.
};

struct ClassMap {
  int width = 0;
  int height = 0;
  std::vector<PixelClass> classes;  // Row-major.

  PixelClass At(int x, int y) const {
    return classes[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)];
  }
};

// Shares of all pixels (each in [0, 1]; the five classes sum to 1) before filling.
struct HoleMetrics {
  double covered_ratio = 0;
  double background_ratio = 0;
  double out_of_view_ratio = 0;
  double crack_ratio = 0;
  double disocclusion_ratio = 0;
  double hole_ratio = 0;    // crack_ratio + disocclusion_ratio.
  int hole_count = 0;       // 8-connected components of hole pixels (cracks and disocclusions).
  int largest_hole_px = 0;  // Pixels in the largest of them.
};

// Classifies the pixels of a blend into `target` from `sources`.
// Out of view: a pixel without samples whose ray segment between the nearest and farthest
// covered depth of nearby rows (to infinity where nearby rows hold background) lies outside
// every source's frustum. The test is exact, not sampled: the segment projects into a source
// image where four linear inequalities in the depth (plus z > 0) hold, so it is an interval
// intersection per source. Throws std::invalid_argument for a non-pinhole camera, a size
// mismatch between blend and target, or bad options.
ClassMap ClassifyPixels(const BlendResult& blend, const std::vector<PosedCamera>& sources,
                        const PosedCamera& target, const HoleOptions& options);

HoleMetrics ComputeHoleMetrics(const ClassMap& classes);

// One-channel image, 1 where the pixel has `pixel_class`, else 0.
Image ClassMask(const ClassMap& classes, PixelClass pixel_class);

}  // namespace parallax
