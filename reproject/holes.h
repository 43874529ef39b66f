#pragma once
// Classification of every target pixel after blending, and the hole metrics of docs/design.md.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/image.h"
#include "reproject/blend.h"
#include "reproject/view.h"

namespace parallax {

enum class PixelClass : uint8_t {
  kCovered,       // A surface sample landed.
  kBackground,    // Only background-at-infinity samples landed (sky).
  kOutOfView,     // Nothing any source saw lies on the pixel's ray (over the scene's depth
                  // range, each point is outside every source or seen as empty space).
  kCrack,         // A thin hole (see HoleOptions::crack_opening_px) inside some source's view.
  kDisocclusion,  // A wider hole: the ray reaches a point some source contains but every
                  // source that contains it sees something in front of it (or has no depth).
};

inline bool IsHole(PixelClass c) { return c == PixelClass::kCrack || c == PixelClass::kDisocclusion; }

constexpr size_t kPixelClasses = 5;  // kDisocclusion is the last.

// How many pixels have each class.
struct ClassCounts {
  std::array<size_t, kPixelClasses> pixels{};
  size_t operator[](PixelClass c) const { return pixels[static_cast<size_t>(c)]; }
};

struct HoleOptions {
  // Hole pixels that a morphological opening with a square of this side removes are cracks
  // (so cracks are at most crack_opening_px - 1 pixels wide); odd, >= 1 (1: no cracks).
  int crack_opening_px = 3;
  // The out-of-view test takes the scene's depth range from the covered pixels this many rows
  // above and below the pixel (the whole image where those rows have none); >= 0.
  int depth_range_rows = 2;
  // Free-space test: points sampled on the pixel's ray over that depth range, uniformly in
  // inverse depth (the last at infinity when the range reaches it); in [2, 1024].
  int free_space_samples = 48;
  // A source sees a point as empty space when its depth there exceeds the point's depth in
  // that source by more than this share (or it sees background at infinity); in (0, 1).
  double free_space_tolerance = 0.02;

  void Check() const;  // Throws UsageError naming the field and value.
};

struct ClassMap {
  int width = 0;
  int height = 0;
  std::vector<PixelClass> classes;  // Row-major.
  // Row-major, 1 for a hole pixel whose direction no source saw without knowing its depth:
  // each source looking that way saw a surface at a known depth (or sky, or the direction lies
  // outside it), and the sky may lie behind that surface. With ground-truth depth nearly every
  // hole is open; FillOptions::hole_sky_share decides whether the sky is taken. Empty when
  // not known (some source without depth): no hole is open to the sky.
  std::vector<uint8_t> open_to_sky;

  PixelClass At(int x, int y) const { return classes[Index(x, y)]; }
  bool OpenToSky(int x, int y) const {
    return !open_to_sky.empty() && open_to_sky[Index(x, y)] != 0;
  }

 private:
  size_t Index(int x, int y) const {
    return static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
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

// A source as the classification sees it.
struct ClassifySource {
  PosedCamera camera;
  // Its depth map (camera size); null: only its frustum is known (no free-space test).
  const DepthMap* depth = nullptr;
  // MarkBackground of `depth` and the source's color (background at infinity, seen as empty
  // space at every depth; marks where the depth is not 0 are ignored);
  // null or empty: every depth-0 pixel is unknown.
  const std::vector<uint8_t>* background = nullptr;
};

// Classifies the pixels of a blend into `target` from `sources`. A pixel without samples is
// tested along its ray segment between the nearest and farthest covered depth of nearby rows
// (to infinity where nearby rows hold background):
//  - where the segment lies outside every source's frustum it is out of view. This part is
//    exact: the segment projects into a source image where four linear inequalities in the
//    depth (plus z > 0) hold, an interval intersection per source;
//  - else, for sources with depth, free_space_samples points on it are looked up in the
//    sources' depth maps: when every point is outside all sources or seen as empty space by
//    one of them, no source saw anything on the ray, so it is out of view too (a target
//    looking above the sources sees sky nobody photographed, not a hole);
//  - else it is a hole: a crack when thin, else a disocclusion; open to the sky unless some
//    source that contains its direction has depth 0 (not background) there.
// Throws InternalError for a non-pinhole camera, a size mismatch between blend and
// target or between a source's camera and its depth map; UsageError for bad options.
ClassMap ClassifyPixels(const BlendResult& blend, const std::vector<ClassifySource>& sources,
                        const PosedCamera& target, const HoleOptions& options);
// Frustums only: every ray segment inside some source's frustum is a hole.
ClassMap ClassifyPixels(const BlendResult& blend, const std::vector<PosedCamera>& sources,
                        const PosedCamera& target, const HoleOptions& options);

HoleMetrics ComputeHoleMetrics(const ClassMap& classes);

// Counted in parallel.
ClassCounts CountClasses(const ClassMap& classes);

// One-channel image, 1 where the pixel has `pixel_class`, else 0.
Image ClassMask(const ClassMap& classes, PixelClass pixel_class);

}  // namespace parallax
