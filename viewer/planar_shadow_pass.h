#pragma once
// Planar shadows (ShadowMode::kPlanar): the geometry flattened onto the fitted ground along the
// light marks the stencil, and the ground is drawn again there, unlit. Shadows fall on the
// ground alone, and only where the scene has one. They use the frame's stencil and hold no GPU
// memory of their own. Needs a current GL context.
#include <cstddef>
#include <functional>

#include <Eigen/Core>

#include "viewer/frame_context.h"
#include "viewer/gl.h"

namespace parallax {

class PlanarShadowPass {
 public:
  // Throws std::runtime_error if the program does not compile.
  PlanarShadowPass();

  // Marks the shadowed ground in the stencil, then calls `redraw_unlit` to draw the surfaces
  // again (SurfaceShadow::kPlanarRedraw) where it is marked, with the ground below set.
  // Needs frame.scene.ground.
  void Draw(const FrameContext& frame, const std::function<void()>& redraw_unlit);

  // The ground plane (n, d) and its half thickness the redraw keeps to: set by Draw, zero before.
  const Eigen::Vector4f& Ground() const { return ground_; }
  float GroundTolerance() const { return ground_tolerance_; }
  size_t Bytes() const { return 0; }  // The frame's stencil only.

 private:
  GlProgram program_;
  Eigen::Vector4f ground_ = Eigen::Vector4f::Zero();
  float ground_tolerance_ = 0;
};

}  // namespace parallax
