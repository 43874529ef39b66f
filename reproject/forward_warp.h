#pragma once
// Forward warp of one source view into a target camera with a z-buffer (nearest wins).
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <memory>
#include <vector>

#include "core/color_gains.h"
#include "reproject/view.h"

namespace parallax {

enum class WarpMethod {
  kSplat,  // Each source pixel drawn as a square footprint sized by its local magnification.
  kMesh,   // Two triangles per 2x2 quad of source pixel centres, perspective-correct; flat
           // 8x8, 4x4 or 2x2 blocks of one surface (or of background) as one quad through the
           // projective map of its corners, the color sampled from the source at the mapped
           // source position (TextureFilter).
};

enum class TextureFilter { kAuto, kBicubic };  // See ForwardWarpOptions::texture_filter.

struct ForwardWarpOptions {
  WarpMethod method = WarpMethod::kMesh;
  // Mesh: neighbouring samples belong to one surface while that surface's normal is within
  // this angle of the source ray (degrees, in (0, 90)). Steeper "surfaces" are depth
  // discontinuities: their triangles are dropped (a hole, not a rubber sheet). In pixels this
  // is a depth ratio of 1 + tan(max_slant) * sqrt(2) / focal_px across a triangle.
  double max_slant_deg = 86;
  // Splat: footprints are at most this many target pixels across (>= 1).
  double max_splat_px = 3;
  // Splat: footprints are enlarged by this factor (>= 1) so neighbouring ones overlap and no
  // pixel centre falls between them.
  double splat_overlap = 1.1;
  // Points are dropped when their target z is below this share of their distance from the
  // target centre (at or behind the camera plane, or projecting absurdly far out); in (0, 1).
  double min_view_cos = 1e-6;
  // Depth-0 source pixels connected to the border through smooth color (MarkBackground) are
  // warped as directions and land as background at infinity; when false every depth-0 pixel
  // is unknown.
  bool background_at_infinity = true;
  // MarkBackground's color test: the largest relative step between neighbouring background
  // pixels (>= 1: no test). The sky's steps are well below 1%; textured ground the depth
  // stage missed has larger ones and stays unknown instead of being warped to infinity.
  double background_max_step = 0.05;
  // Mesh: color sampling of the source. kAuto: Catmull-Rom where the target magnifies the source
  // (more than 1.5 target pixels per source pixel), bilinear elsewhere. kBicubic: Catmull-Rom
  // everywhere, sharper where a sample falls between source pixels, at some extra warp time.
  TextureFilter texture_filter = TextureFilter::kAuto;
  // Added to the ray angle in the sample's blend weight (WarpBuffer::Weight), so a source that
  // sees the point exactly along the target ray gets a large, finite weight (radians, > 0).
  double angle_epsilon_rad = 0.01;
  // Mesh: added to the ray angle of samples on a silhouette (a surface pixel beside a depth
  // edge, sky or unknown depth; radians, >= 0): the photo mixes the two sides there, and a
  // source that sees the point away from its silhouettes has its pure color. 0 turns it off.
  double silhouette_angle_rad = 0.5;
  // Mesh: a surface sample on the near side of a depth edge (beside a farther surface, sky or
  // unknown depth) is splatted at this share of its footprint, and one on the far side at
  // 2 - share, so the two still meet (unless one sample wide: then 1); in (0, 1]. The true
  // outline lies anywhere between the two samples, and a target pixel takes the front-most
  // surface of all its sources, so full footprints fatten every occluder by the largest
  // overshoot of K sources.
  double outline_splat_share = 0.6;

  void Check() const;  // Throws UsageError naming the field and value.
};

// A per-pixel array of the warp (see Allocate in forward_warp.cc), freed with std::free.
struct FreeDeleter {
  void operator()(void* memory) const noexcept { std::free(memory); }
};
template <typename T>
using PixelArray = std::unique_ptr<T[], FreeDeleter>;

// One source warped into the target, target-sized, struct of arrays, index y * width + x.
class WarpBuffer {
 public:
  // Depth value of a background-at-infinity sample. Internal to the warp and blend: it never
  // reaches a DepthMap or a file.
  static constexpr float kBackground = std::numeric_limits<float>::infinity();

  // Sizes the buffer and marks every pixel empty; keeps the memory when it is large enough.
  void Reset(int width, int height);

  int Width() const { return width_; }
  int Height() const { return height_; }
  size_t Size() const { return static_cast<size_t>(width_) * static_cast<size_t>(height_); }
  // Target z-depth of the sample, 0 where nothing landed, kBackground for background.
  float Depth(size_t i) const { return depth_[i]; }
  const float* Depths() const { return depth_.get(); }  // Size() of them.
  // Linear RGB of the sample; meaningful only where Depth(i) != 0.
  std::array<float, 3> Color(size_t i) const;
  // The blend's weight of the sample (Unstructured-Lumigraph style), meaningful only where
  // Depth(i) != 0: 1 / ((angle + ForwardWarpOptions::angle_epsilon_rad) * max(1, stretch)),
  // where angle is that at the 3D point between the rays from the source and the target
  // centres, as the chord 2 sin(angle / 2) (within 1% below 28 degrees; 0 for background,
  // whose rays are parallel; plus ForwardWarpOptions::silhouette_angle_rad on the source's
  // silhouettes, fading across a block), and stretch is target pixels per source pixel (area
  // ratio; > 1 where the source is magnified, sampled too sparsely for the target); clamped
  // to [kMinWeight, kMaxHalf]. One number computed by the warp rather than angle and stretch
  // for the blend to combine: less to write and read back.
  float Weight(size_t i) const;
  // Color and weight of each pixel as four IEEE half floats (R, G, B, weight; simd.h's
  // StoreHalf4): 8 bytes per sample instead of 16 in floats. The warps write them and the
  // blend reads them all, and the render core waits on memory (half the bytes to move).
  // A half keeps 11 significant bits, 20 times finer than an 8-bit sRGB step anywhere;
  // color saturates at kMaxHalf.
  const uint16_t* ColorWeights() const { return color_weight_.get(); }  // 4 Size() of them.

  // The relative rounding of a color or weight stored in a half (11 significant bits).
  static constexpr double kHalfRounding = 0x1p-11;
  // The largest finite half float, and the smallest normal one: the weight's clamp, so that
  // it keeps its relative precision and never rounds to 0 or infinity.
  static constexpr float kMaxHalf = 65504.0f;
  static constexpr float kMinWeight = 0x1p-14f;

  float* MutableDepth() { return depth_.get(); }
  uint16_t* MutableColorWeights() { return color_weight_.get(); }

 private:
  int width_ = 0;
  int height_ = 0;
  size_t capacity_ = 0;
  PixelArray<float> depth_;
  PixelArray<uint16_t> color_weight_;
};

// Memory a warp needs (per band: a window of projected rows, per-pixel masks); keeping one
// between calls saves allocating and page-faulting it. One per concurrent warp.
class WarpScratch {
 public:
  WarpScratch();
  ~WarpScratch();
  WarpScratch(WarpScratch&&) noexcept;
  WarpScratch& operator=(WarpScratch&&) noexcept;

  struct Data;  // Defined in forward_warp.cc.
  Data& Get() { return *data_; }
  // MarkBackground of the last warped source's depth and color (the warp's own, or the
  // source's own mask, which lives as long as the source); empty when the warp did not use
  // background at infinity.
  const std::vector<uint8_t>& Background() const;

 private:
  std::unique_ptr<Data> data_;
};

// Makes what every warp of the source would otherwise make again, for the warps to share:
// source->texture, and source->background (MarkBackground of its depth and color, with the
// options' background_max_step) where the options warp background at infinity. With a
// `gain` (core/color_gains.h), the background is marked on the photo as taken and the color is
// then corrected by it, so the correction never moves the background. Call again whenever the
// depth or color changes. Throws InternalError for a source CheckSourceView refuses,
// UsageError for bad options.
void PrepareSource(SourceView* source, const ForwardWarpOptions& options = {}, const RgbGain& gain = {1, 1, 1});

// Warps `source` into `target`, overwriting *buffer (resized to the target). Points at or
// behind the target camera are dropped; source pixels with depth 0 are background (see
// ForwardWarpOptions::background_at_infinity) or unknown (they land nowhere). The source is
// projected row by row as the walk over it reaches each row. With one band (`bands` = 1) the
// warp is serial (for warps that run side by side, one per thread, as Render's do); with
// `bands` > 1 that many bands of target rows are drawn in parallel (TBB), each walking and
// projecting the whole source (more work in all, for a warp that runs alone), with the same
// output bit for bit. Allocation-free with a reused `scratch`. Throws
// InternalError for a non-pinhole camera or mismatched sizes (CheckSourceView), UsageError for
// bad options. `scratch` may be null (then the warp allocates its own).
void ForwardWarp(const SourceView& source, const PosedCamera& target,
                 const ForwardWarpOptions& options, WarpBuffer* buffer,
                 WarpScratch* scratch = nullptr, int bands = 1);

}  // namespace parallax
