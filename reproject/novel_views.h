#pragma once
// What `parallax render` works with: the source views of a workspace (SfM frame, estimated
// depth) or of a scene folder (ground-truth cameras and depth), loaded only when a target
// uses them; the target cameras (a COLMAP model, or a path spec); one render per target.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/color_gains.h"
#include "core/scene_folder.h"
#include "core/sparse_model.h"
#include "geometry/scene_frame.h"
#include "reproject/render.h"
#include "reproject/source_selection.h"
#include "reproject/view.h"

namespace parallax {

struct NamedCamera {
  std::string name;  // Output file stem.
  PosedCamera camera;
};

// Every image of `model`, named by the image's stem, in the model's order; with `image_names`,
// each image's file name there too.
std::vector<NamedCamera> CamerasOfModel(const SparseModel& model, std::vector<std::string>* image_names = nullptr);

// Every image of a COLMAP model (text or binary), named by the image's stem.
std::vector<NamedCamera> CamerasFromModel(const std::filesystem::path& model_dir);

// A camera path among the sources, with the intrinsics of the first source:
//   orbit:N          N cameras on the orbit `parallax view --orbit` follows (DefaultOrbit,
//                    geometry/scene_frame.h, of the frame fitted to the workspace's mesh,
//                    cloud and cameras): frame i is `view --orbit` at 360i/N degrees, or, when
//                    the cameras stand on an arc that leaves a gap over 90 degrees, at i/(N-1)
//                    of the way along that arc; with the first source's size and horizontal
//                    field of view. With cameras looking in at a point, the circle about it at
//                    their median distance and elevation; else one around the focus box;
//   between:A,B,N    N cameras from source image A to B (pose interpolation, both included);
//   photos:N         N cameras evenly along a smooth curve through every source camera (in
//                    azimuth order about the point they look at, else in name order), from the
//                    first to the last: a tour that stays where the photos were taken.
struct CameraPath {
  enum class Kind { kOrbit, kBetween, kPhotos };
  Kind kind = Kind::kOrbit;
  int frames = 0;
  std::string from, to;  // kBetween: source image names or stems.
  std::string Spec() const;  // As ParseCameraPath reads it.
};

// Throws BadInputError for a malformed spec (the message shows the forms above).
CameraPath ParseCameraPath(const std::string& spec);

// An orbit or a tour reads the frame's geometry from `scene` (ReadSceneGeometry: a workspace's
// mesh and cloud, the files `parallax view` shows); without either (a scene folder) the cameras
// alone make the frame (FitSceneFrame). Throws BadInputError when there are no sources,
// `path` names an unknown image, or a mesh or cloud file is unreadable.
std::vector<NamedCamera> CamerasAlongPath(const CameraPath& path, const SceneFiles& scene,
                                          const std::vector<PosedCamera>& sources,
                                          const std::vector<std::string>& source_names);

// Source cameras up front; each view's photo and depth read from disk on first use only, the
// photo corrected by its color gain when the paths name a gains file.
class SourceLibrary {
 public:
  explicit SourceLibrary(ViewSetPaths paths);
  const std::vector<PosedCamera>& Cameras() const { return cameras_; }
  const std::vector<std::string>& Names() const { return names_; }
  // On first use prepares the view for warps with `warp` (PrepareSource: its texture, and its
  // background where they warp background at infinity; --warp naive does not). Throws BadInputError
  // naming the file for a missing or corrupt photo or depth map.
  const SourceView& Load(int index, const ForwardWarpOptions& warp);
  int LoadedCount() const;
  // The color gain the view's photo is corrected by as it loads (1 without a gains file).
  RgbGain Gain(int index) const { return gains_.Of(names_.at(static_cast<size_t>(index))); }
  // Runs on each view as it is loaded, before it is warped, to prepare its depth map (for a
  // workspace's estimated depth: specks out, holes from the mesh; see reproject/workspace_depth.h);
  // returns how many pixels it gave depth. Call before any Load.
  using DepthPreparation = std::function<int(SourceView* view)>;
  void SetDepthPreparation(DepthPreparation preparation) { preparation_ = std::move(preparation); }
  // Pixels the preparation gave depth so far, and all pixels of the views loaded.
  long PreparedPixels() const { return prepared_pixels_; }
  long LoadedPixels() const { return loaded_pixels_; }
  // Leaves out the views without a depth map on disk (their depth could not be estimated, e.g.
  // no stereo partner); returns their names. Call before any Load.
  std::vector<std::string> DropViewsWithoutDepth();

 private:
  ViewSetPaths paths_;
  std::vector<PosedCamera> cameras_;
  std::vector<std::string> names_;
  std::vector<std::unique_ptr<SourceView>> loaded_;
  ColorGains gains_;  // From paths_.color_gains: each photo's color as read, times its gain.
  DepthPreparation preparation_;
  long prepared_pixels_ = 0;
  long loaded_pixels_ = 0;
};

struct NovelView {
  RenderResult result;
  std::vector<std::string> sources;  // The views it was rendered from, best first.
  double ms = 0;                     // Selection, warping, blending, classification, filling.
  // RenderNovelView's render with one more source, before it decides whether to keep it (the
  // two trade places when it does): kept here so that its memory, too, serves every view.
  RenderResult with_one_more;
};

// Whether pixel (x, y) of a render is one no source saw that another source might show: a
// hole, or an out-of-view pixel the fill continued a surface into (not sky, which looks the
// same from anywhere). Needs the depth the depth-aware fill gives them.
bool Unseen(const RenderResult& result, int x, int y);

// World points of a render's Unseen pixels (every other pixel of every other row) at the
// depth the fill gave them: the background side of each hole and the surfaces continued past
// the sources' frames, what the sources did not see.
std::vector<Eigen::Vector3d> UnseenPoints(const RenderResult& result, const PosedCamera& target);

// Selects up to `selection.num_sources` sources for `target`, loads them, renders; then, while
// Unseen pixels cover 0.1% of the image or more, adds up to `selection.hole_sources` more, one
// at a time, each the source that sees most of UnseenPoints (SourceSeeingMost); it stops at the
// first that does not show a tenth of them (that one stays loaded, unused). With a fill other
// than the depth-aware one no source is added. The result's timings are those of its last
// render step; NovelView::ms covers them all. Throws BadInputError when no source can
// contribute to the target. One `renderer` and one `view` for all the views of a run keep
// their memory: fresh ones per 640x480 view page-fault ~65 MB.
void RenderNovelView(SourceLibrary& library, const NamedCamera& target,
                     const SourceSelectionOptions& selection, Renderer& renderer, NovelView* view);

// Writes <dir>/<name>.png (sRGB, after filling), <name>.holes.png (8-bit mask, 255 where a
// crack or disocclusion was before filling) and <name>.depth.exr (0 where unknown or
// background), each atomically.
void WriteNovelView(const std::filesystem::path& dir, const std::string& name,
                    const RenderResult& result);

}  // namespace parallax
