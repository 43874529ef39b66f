#pragma once
// Hole filling after blending.
#include <string>

#include "reproject/blend.h"
#include "reproject/holes.h"
#include "reproject/view.h"

namespace parallax {

enum class FillMethod {
  kNone,        // Holes stay black.
  kInpaint,     // OpenCV's Telea inpainting on the 8-bit sRGB image (baseline); depth not filled.
  kDepthAware,  // From the background side: see FillHoles.
};

struct FillOptions {
  FillMethod method = FillMethod::kDepthAware;
  // Also fill out-of-view pixels (the frame border), so the image has no black.
  bool fill_out_of_view = true;
  // kDepthAware: directions scanned from each pixel to the nearest sampled one; 8 or 16.
  int directions = 16;
  // kDepthAware: candidates within this relative depth of the farthest one are the
  // background side and are averaged; in (0, 1). 20% averages the background of a
  // disocclusion over more of its rim (a slanted floor's depth varies along it).
  double background_tolerance = 0.2;
  // kDepthAware: a hole open to the sky (ClassMap::open_to_sky: its direction may lead past
  // what the sources saw) takes the sky where at least this share of the directions find
  // background at infinity, in (0, 1]; other holes take it only where no direction finds a
  // surface. Below 1 a gap between two walls, hidden behind the nearer one, gets the sky; too
  // low a share lets holes in far ground, open to the sky above, take it too.
  double hole_sky_share = 0.5;
  // kDepthAware: holes whose filled surface some source saw without depth take that source's
  // color (FillFromSources, fill_from_sources.h).
  bool from_sources = true;
  // kDepthAware: average the surface fills over windows that grow with the distance to the rim
  // (no streaks fanning out from it).
  bool smooth = true;
  // kInpaint: Telea neighbourhood radius in pixels, > 0.
  double inpaint_radius_px = 3;

  void Check() const;  // Throws UsageError naming the field and value.
};

// Whether FillHoles fills a pixel of class `c`: holes, and out-of-view pixels with
// fill_out_of_view.
inline bool ShouldFill(PixelClass c, const FillOptions& options) {
  return IsHole(c) || (options.fill_out_of_view && c == PixelClass::kOutOfView);
}

struct FillSummary {
  int filled_px = 0;  // Pixels that received a color.
  // Share of all pixels still without color after filling (holes nothing reached, and
  // out-of-view pixels when they are not filled). 0 when everything got a color.
  double hole_ratio_filled = 0;
  // Why filling was left out, when it was (nothing to fill); empty when it ran.
  std::string skipped;
};

// Fills the pixels of `blend` where nothing landed (holes; out-of-view ones too with
// fill_out_of_view). kDepthAware scans `directions` rays from the pixel to the nearest pixel
// with a sample, keeps the candidates whose depth is the farthest (background at infinity
// counts as farthest, except for holes, see hole_sky_share, and for out-of-view pixels below
// the row with half the landed background above it: photos are upright, and beside the
// sources' frames the wall or ground they saw goes on) within background_tolerance, and
// averages their colors weighted by inverse distance; surface fills also get that averaged
// depth. A disocclusion is hidden background, so its color comes from the background side,
// not from the occluder. Where the background side is background at infinity, the color
// comes from a sky model instead: an affine function of the viewing ray through `camera` (the
// target's), fitted to the pixels where background landed, so sky nothing saw continues the
// gradient of the sky around it.
// The sample kinds of `blend` are left as they were. Throws UsageError for bad
// options, InternalError for a non-pinhole camera, or a class map (or its open_to_sky) or
// camera of another size.
FillSummary FillHoles(const ClassMap& classes, const Camera& camera, const FillOptions& options,
                      BlendResult* blend);

}  // namespace parallax
