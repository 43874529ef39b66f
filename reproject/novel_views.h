#pragma once
// What `parallax render` works with: the source views of a workspace (SfM frame, estimated
// depth) or of a scene folder (ground-truth cameras and depth), loaded only when a target
// uses them; the target cameras (a COLMAP model, or a path spec); one render per target.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/scene_folder.h"
#include "reproject/render.h"
#include "reproject/source_selection.h"
#include "reproject/view.h"

namespace parallax {

// The sources of a workspace (<ws>/sparse, images, depth; depth maps may still be missing)
// or of a scene folder (its training set). Throws BadInputError naming the folder when it is
// neither.
ViewSetPaths SourcePathsFor(const std::filesystem::path& workspace_or_scene);

struct NamedCamera {
  std::string name;  // Output file stem.
  PosedCamera camera;
};

// Every image of a COLMAP model (text or binary), named by the image's stem.
std::vector<NamedCamera> CamerasFromModel(const std::filesystem::path& model_dir);

// Cameras along a path, with the intrinsics of the first source:
//   orbit:N          N cameras on a circle around the point the sources look at, at their
//                    mean height and distance, starting at the first source;
//   between:A,B,N    N cameras from source image A to B (pose interpolation, both included).
// Throws BadInputError for a malformed spec or unknown image names.
std::vector<NamedCamera> CamerasAlongPath(const std::string& spec,
                                          const std::vector<PosedCamera>& sources,
                                          const std::vector<std::string>& source_names);

// Source cameras up front; each view's photo and depth read from disk on first use only.
class SourceLibrary {
 public:
  explicit SourceLibrary(ViewSetPaths paths);
  const std::vector<PosedCamera>& Cameras() const { return cameras_; }
  const std::vector<std::string>& Names() const { return names_; }
  // Throws BadInputError naming the file for a missing or corrupt photo or depth map.
  const SourceView& Load(int index);
  int LoadedCount() const;
  // Gives depth to the pixels of each loaded view's depth map that have none, from a model of
  // the whole scene (`parallax render` passes the workspace's mesh): returns how many it
  // filled. Estimated depth maps leave holes where matching failed (~12% of the courtyard's
  // photos); warped, those are holes in every novel view. Call before any Load.
  using DepthCompletion = std::function<int(const PosedCamera& camera, DepthMap* depth)>;
  void SetDepthCompletion(DepthCompletion completion) { completion_ = std::move(completion); }
  // Pixels filled by the completion so far, and all pixels of the views loaded.
  long CompletedPixels() const { return completed_pixels_; }
  long LoadedPixels() const { return loaded_pixels_; }
  // Leaves out the views without a depth map on disk (their depth could not be estimated, e.g.
  // no stereo partner); returns their names. Call before any Load.
  std::vector<std::string> DropViewsWithoutDepth();

 private:
  ViewSetPaths paths_;
  std::vector<PosedCamera> cameras_;
  std::vector<std::string> names_;
  std::vector<std::unique_ptr<SourceView>> loaded_;
  DepthCompletion completion_;
  long completed_pixels_ = 0;
  long loaded_pixels_ = 0;
};

struct NovelView {
  RenderResult result;
  std::vector<std::string> sources;  // The views it was rendered from, best first.
  double ms = 0;                     // Selection, warping, blending, classification, filling.
};

// World points of a render's hole pixels (every other pixel of every other row) at the depth
// the fill gave them: the background side of each hole, what the sources did not see.
std::vector<Eigen::Vector3d> HolePoints(const RenderResult& result, const PosedCamera& target);

// Selects up to `selection.num_sources` sources for `target`, loads them, renders; then, while
// holes cover 0.1% of the image or more, adds up to `selection.hole_sources` more, one at a
// time, each the source that sees most of HolePoints (SourceSeeingMost), kept when it closes a
// tenth of the holes at least. Throws BadInputError when no source can contribute to the
// target.
NovelView RenderNovelView(SourceLibrary& library, const NamedCamera& target,
                          const SourceSelectionOptions& selection, const RenderOptions& options);

// Writes <dir>/<name>.png (sRGB, after filling), <name>.holes.png (8-bit mask, 255 where a
// crack or disocclusion was before filling) and <name>.depth.exr (0 where unknown or
// background), each atomically.
void WriteNovelView(const std::filesystem::path& dir, const std::string& name,
                    const RenderResult& result);

}  // namespace parallax
