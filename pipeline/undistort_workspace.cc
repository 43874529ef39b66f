#include "pipeline/undistort_workspace.h"

#include <string>

#include "core/atomic_file.h"
#include "sfm/undistort.h"

namespace parallax {
namespace fs = std::filesystem;

void WritePinholeWorkspace(const SparseModel& model, const fs::path& photos_dir, const Workspace& out) {
  fs::create_directories(out.Images());
  fs::create_directories(out.StereoDepthMaps());
  fs::create_directories(out.StereoNormalMaps());
  fs::create_directories(out.StereoConsistencyGraphs());
  SparseModel pinhole;
  for (const Camera& camera : model.Cameras()) pinhole.AddCamera(PinholeOf(camera));
  std::string patch_match, fusion;
  for (const SparseImage& image : model.Images()) {
    pinhole.AddImage(image);
    fs::create_directories(out.Image(image.name).parent_path());
    const Camera& camera = model.CameraById(image.camera_id);
    if (camera.HasDistortion()) {
      UndistortPhoto(camera, photos_dir / image.name, out.Image(image.name));
    } else {
      fs::copy_file(photos_dir / image.name, out.Image(image.name),
                    fs::copy_options::overwrite_existing);
    }
    patch_match += image.name + "\n__auto__, 20\n";
    fusion += image.name + "\n";
  }
  for (const Point3D& point : model.Points3D()) pinhole.AddPoint3D(point);
  WriteSparseModel(pinhole, out.Sparse(), SparseFormat::kBinary);
  WriteFileAtomically(out.StereoConfig("patch-match.cfg"), patch_match);
  WriteFileAtomically(out.StereoConfig("fusion.cfg"), fusion);
}

}  // namespace parallax
