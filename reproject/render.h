#pragma once
// Novel-view rendering by depth-image-based warping: warp every source, blend, classify the
// pixels nothing reached, fill the holes.
#include <chrono>
#include <vector>

#include "core/depth_map.h"
#include "core/image.h"
#include "reproject/blend.h"
#include "reproject/fill.h"
#include "reproject/forward_warp.h"
#include "reproject/holes.h"
#include "reproject/view.h"

namespace parallax {

struct RenderOptions {
  ForwardWarpOptions warp;
  BlendOptions blend;
  HoleOptions holes;
  FillOptions fill;

  void Check() const;  // Checks every part; throws UsageError naming the field.
};

struct RenderTimings {
  double warp_ms = 0;
  double blend_ms = 0;
  double classify_ms = 0;
  double fill_ms = 0;
  double total_ms = 0;
};

struct RenderResult {
  Image color;       // Linear RGB, target size, after filling.
  DepthMap depth;    // Target z-depth; 0 for background and where nothing is known (depth-aware
                     // fills carry the depth of the background side they copied).
  ClassMap classes;  // Before filling.
  HoleMetrics metrics;  // Before filling.
  FillSummary fill;     // After filling (FillSummary::hole_ratio_filled).
  RenderTimings timings;
};

// Renders frame after frame with the same options, keeping the per-source buffers between
// calls (a camera path; the benchmark): at 640x480 that saves allocating and page-faulting
// ~16 MB per source and frame. Not thread-safe: one Renderer per thread.
class Renderer {
 public:
  explicit Renderer(const RenderOptions& options = {});  // Throws like RenderOptions::Check.

  // As the free function Render below, into *result. Its memory is reused: a caller that
  // passes the same result frame after frame allocates nothing per frame (a fresh 640x480
  // result page-faults ~5 MB). On a throw *result is unchanged.
  void Render(const std::vector<const SourceView*>& sources, const TargetCamera& target,
              RenderResult* result);

  // Renders the last Render's target again with `source` added to its sources: only `source`
  // is warped, the others' warps are kept (blending, classification and filling run again).
  // `source` and the last call's sources must outlive the next call. Throws std::logic_error
  // before any Render, InternalError like Render for a bad source.
  void RenderWithOneMore(const SourceView& source, RenderResult* result);

  const RenderOptions& Options() const { return options_; }

 private:
  // Blends the warped buffers, classifies and fills into *result; `start` is when the render
  // began.
  void Finish(std::chrono::steady_clock::time_point start, double warp_ms, RenderResult* result);

  // Makes at least `count` buffers and scratches; never fewer than before: a novel view that
  // adds hole sources (RenderWithOneMore) and the next view's Render with fewer sources would
  // otherwise free the extra ones and allocate and page-fault them again (~11 MB per source at
  // 640x480).
  void KeepBuffers(size_t count);

  RenderOptions options_;
  // The first sources_.size() hold the last render's warps.
  std::vector<WarpBuffer> buffers_;
  std::vector<WarpScratch> scratch_;
  std::vector<const SourceView*> sources_;  // Of the last render.
  TargetCamera target_;
  // The frame being blended and filled; its color and depth then trade places with the
  // result's, whose memory (the caller's last frame) the next frame is blended into.
  BlendResult blend_;
};

// Renders `target` from `sources` (at least one; each checked with CheckSourceView). Sources
// are warped in parallel, each into its own buffer; blending, classification and filling are
// parallel over rows. No per-pixel heap allocation. Throws InternalError for no
// sources, a null source, a non-pinhole camera or mismatched sizes, UsageError for bad options.
RenderResult Render(const std::vector<const SourceView*>& sources, const TargetCamera& target,
                    const RenderOptions& options = {});

}  // namespace parallax
