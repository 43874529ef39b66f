#pragma once
// Inputs of depth-image-based rendering: posed cameras and source views.
//
// Common principles of reproject/:
//  - Poses are cam_from_world (x_cam = R * x_world + t); the camera frame is x right, y down,
//    z forward; pixel centres lie at integer + 0.5; depth is z-depth, 0 = no value.
//  - Cameras are pinhole (PINHOLE or SIMPLE_PINHOLE, or a distortion model whose distortion
//    parameters are all 0): workspace images are undistorted. Anything else throws
//    InternalError; RenderNovelView renders a target with distortion in a pinhole
//    camera and resamples it (distorted_target.h).
//  - Colors are linear-light float RGB in memory; callers convert sRGB with core/image.h.
//  - No NaN or Inf ever leaves a function: divisions are guarded and results checked finite.
#include <cstdint>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/depth_map.h"
#include "core/image.h"
#include "core/pose.h"

namespace parallax {

// A camera and its pose: the target of a render, or a source before its images are loaded.
struct PosedCamera {
  Camera camera;
  Rigid3d cam_from_world;
};
using TargetCamera = PosedCamera;

// One source photo with its depth.
struct SourceView {
  std::string name;
  Camera camera;
  Rigid3d cam_from_world;
  Image color;     // Linear RGB, 3 channels, camera size.
  DepthMap depth;  // z-depth in scene units, 0 = no value; camera size.
  // Made once per source by PrepareSource (forward_warp.h), after the depth and color are
  // final, instead of by every warp; when empty (or made with another step, or for another
  // size), ForwardWarp makes its own.
  // Which depth-0 pixels are background at infinity: MarkBackground of depth and color with
  // background_step.
  std::vector<uint8_t> background;
  float background_step = 0;
  // The color as the warp samples it: four half floats per pixel (R, G, B, 0), 8 bytes to
  // stream instead of 12 (the warps wait on this memory), one aligned load per tap.
  std::vector<uint16_t> texture;

  PosedCamera Posed() const { return {camera, cam_from_world}; }
};

// Pinhole intrinsics in the form the per-pixel loops use.
struct Pinhole {
  int width = 0;
  int height = 0;
  double fx = 1;
  double fy = 1;
  double cx = 0;
  double cy = 0;

  // Throws InternalError naming the camera id for distortion, a projection the
  // pinhole model cannot express, a size beyond int, or a non-positive focal length.
  static Pinhole From(const Camera& camera);

  // The ray (x', y', 1) through the centre of pixel (x, y), in the camera frame.
  Eigen::Vector3d PixelRay(int x, int y) const {
    return Eigen::Vector3d((x + 0.5 - cx) / fx, (y + 0.5 - cy) / fy, 1);
  }
};

// Throws InternalError naming the view when the camera is not pinhole, the color is
// not 3-channel, or color, depth and camera sizes differ.
void CheckSourceView(const SourceView& view);

}  // namespace parallax
