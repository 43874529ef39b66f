#pragma once
// The depth-aware hole filler (FillMethod::kDepthAware of FillHoles, fill.h): a hole takes the
// colors of the background side of what lies around it, and sky nothing saw continues a sky
// model fitted to the background that landed.
#include "reproject/blend.h"
#include "reproject/fill.h"
#include "reproject/holes.h"
#include "reproject/view.h"

namespace parallax {

// Fills the pixels of `blend` that ShouldFill, seen through the target camera `camera`, as
// FillHoles describes for kDepthAware; returns how many received a color. FillHoles checks the
// options and the sizes first.
int FillDepthAware(const ClassMap& classes, const Pinhole& camera, const FillOptions& options,
                   BlendResult* blend);

}  // namespace parallax
