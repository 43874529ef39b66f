#include "reproject/scene_views.h"

#include "core/depth_map.h"
#include "core/image.h"
#include "core/sparse_model.h"
#include "reproject/forward_warp.h"

namespace parallax {
namespace {

Image LinearRgb(const Image& encoded) {
  const Image linear = SrgbToLinear(encoded);
  if (linear.Channels() == 3) return linear;
  Image rgb(linear.Width(), linear.Height(), 3);
  for (int y = 0; y < linear.Height(); ++y) {
    for (int x = 0; x < linear.Width(); ++x) {
      for (int c = 0; c < 3; ++c) {
        // Grey (1 or 2 channels) repeats its only color channel.
        rgb.At(x, y, c) = linear.At(x, y, linear.Channels() >= 3 ? c : 0);
      }
    }
  }
  return rgb;
}

}  // namespace

std::vector<PosedCamera> ReadPosedCameras(const ViewSetPaths& paths,
                                          std::vector<std::string>* names) {
  const SparseModel model = ReadSparseModel(paths.sparse);
  std::vector<PosedCamera> cameras;
  for (const SparseImage& image : model.Images()) {
    cameras.push_back({model.CameraById(image.camera_id), image.cam_from_world});
    if (names != nullptr) names->push_back(image.name);
  }
  return cameras;
}

std::vector<SourceView> ReadSourceViews(const ViewSetPaths& paths) {
  std::vector<std::string> names;
  const std::vector<PosedCamera> cameras = ReadPosedCameras(paths, &names);
  std::vector<SourceView> views;
  for (size_t i = 0; i < cameras.size(); ++i) {
    SourceView view;
    view.name = names[i];
    view.camera = cameras[i].camera;
    view.cam_from_world = cameras[i].cam_from_world;
    view.color = LinearRgb(ReadImage(paths.images / names[i]));
    view.depth = ReadDepthExrAt(paths.DepthFor(names[i]), view.color.Width(), view.color.Height());
    PrepareSource(&view);
    views.push_back(std::move(view));
  }
  return views;
}

}  // namespace parallax
