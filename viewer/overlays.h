#pragma once
// What the viewer draws besides the surfaces, as vertices for the GPU: the fused cloud's
// points, each source camera's frustum, and a grid on the ground; and the pass that draws the
// frusta and the grid as lines over the frame (OverlayPass, needs a current GL context).
#include <vector>

#include <Eigen/Core>

#include "viewer/frame_context.h"
#include "viewer/gl.h"
#include "viewer/gpu_resources.h"
#include "viewer/viewer_scene.h"

namespace parallax {

// Line vertices per camera in FrustumLines: a pyramid from the centre to the image corners,
// and a tick on its top edge.
constexpr int kFrustumVertices = 18;

std::vector<gpu::Vertex> PointVertices(const std::vector<ColoredPoint>& points);

// Each source camera as a pyramid from its centre to its image corners at `depth`, with a
// tick on the top edge so "up" is visible: kFrustumVertices line vertices per camera, in order.
std::vector<gpu::Vertex> FrustumLines(const std::vector<ViewerSource>& sources, double depth);

// How deep the frusta are drawn: 4% of the scene's robust size, but no more than the median
// spacing of neighbouring cameras, so a dense rig does not turn into a tangle of lines.
double FrustumDepth(const ViewerScene& scene);

// A square grid with round steps on the ground (or, without one, under the scene, normal to
// `up`), covering the footprint of the robust extent: outliers do not stretch it.
std::vector<gpu::Vertex> GridLines(const ViewerScene& scene);

// The ground grid and the source cameras' frusta, drawn as colored lines.
class OverlayPass {
 public:
  // Uploads the lines. Throws std::runtime_error if the program does not compile.
  explicit OverlayPass(const ViewerScene& scene);

  // Draws what the settings show of the grid and the frusta, depth-tested against the frame.
  void Draw(const FrameContext& frame) const;

 private:
  // The frusta but those of cameras within three frustum depths of the eye: the one looked
  // through, or one just in front of the eye, would cross the whole image.
  void DrawFrusta(const Eigen::Vector3d& eye_centre) const;

  GlProgram program_;
  gpu::Drawable frusta_, grid_;
  double frustum_depth_ = 0;  // Scene units.
  std::vector<Eigen::Vector3d> source_centres_;
};

}  // namespace parallax
