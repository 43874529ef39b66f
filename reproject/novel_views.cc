#include "reproject/novel_views.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>
#include <vector>

#include "core/depth_map.h"
#include "core/elapsed.h"
#include "core/error.h"
#include "reproject/distorted_target.h"
#include "core/image.h"
#include "core/pose.h"
#include "core/sparse_model.h"
#include "geometry/scene_frame.h"
#include "reproject/forward_warp.h"
#include "reproject/scene_views.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

std::string FrameName(const std::string& prefix, int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "%s_%04d", prefix.c_str(), index);
  return name;
}

int ParseCount(const std::string& text, const std::string& spec) {
  try {
    size_t used = 0;
    const int count = std::stoi(text, &used);
    if (used == text.size() && count >= 1 && count <= 100000) return count;
  } catch (const std::exception&) {
  }
  throw BadInputError("--path " + spec + ": '" + text + "' is not a frame count in 1..100000");
}

// The frame `parallax view` fits to the same scene (viewer/viewer_scene.h): the mesh and the
// cloud it shows, and the cameras it shows.
SceneFrame ReadSceneFrame(const SceneFiles& files, const std::vector<PosedCamera>& sources) {
  const SceneGeometry geometry = ReadSceneGeometry(files);
  std::vector<FrameCamera> cameras;
  for (const PosedCamera& source : sources) {
    if (IsProjectionSupported(source.camera.model)) cameras.push_back({source.camera, source.cam_from_world});
  }
  return FitSceneFrame(geometry.mesh, geometry.cloud.vertices, cameras);
}

// A rig whose cameras leave a gap wider than this (degrees of azimuth) does not surround the
// scene: an orbit beyond its arc would look where no photo did.
constexpr double kMaxGapAroundDeg = 90;

// The azimuth of frame i of n: 360 i / n around the scene, or, when the photos were taken
// from an arc of it only, evenly from one end of that arc to the other.
double OrbitAzimuth(const SceneFrame& frame, int i, int n) {
  if (!frame.rig || frame.rig->arc_span_deg >= 360 - kMaxGapAroundDeg) return 360.0 * i / n;
  const double share = n > 1 ? static_cast<double>(i) / (n - 1) : 0.5;
  return frame.rig->arc_start_deg + share * frame.rig->arc_span_deg;
}

// Frame i on the DefaultOrbit for the first source's intrinsics, at OrbitAzimuth: where
// `parallax view --orbit` stands at that azimuth with that camera's size and field of view.
std::vector<NamedCamera> OrbitCameras(int frames, const SceneFiles& scene, const std::vector<PosedCamera>& sources) {
  const SceneFrame frame = ReadSceneFrame(scene, sources);
  const Camera& camera = sources.front().camera;
  std::vector<NamedCamera> cameras;
  for (int i = 0; i < frames; ++i) {
    const double azimuth_deg = OrbitAzimuth(frame, i, frames);
    cameras.push_back({FrameName("orbit", i), {camera, DefaultOrbitPose(frame, azimuth_deg, std::nullopt, camera)}});
  }
  return cameras;
}

// The sources in the order a tour visits them: by azimuth along the rig's arc (from its
// start) when the cameras look in at a point, else by name (the order they were taken in).
std::vector<size_t> TourOrder(const SceneFrame& frame, const std::vector<PosedCamera>& sources,
                              const std::vector<std::string>& names) {
  std::vector<double> keys(sources.size());
  for (size_t i = 0; frame.rig && i < sources.size(); ++i) {
    const double from_start =
        AzimuthDeg(CameraCenter(sources[i].cam_from_world) - frame.rig->target, frame.up) - frame.rig->arc_start_deg;
    keys[i] = from_start < 0 ? from_start + 360 : from_start;
  }
  std::vector<size_t> order(sources.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return frame.rig ? keys[a] < keys[b] : names[a] < names[b];
  });
  return order;
}

// Frames evenly spaced along a Catmull-Rom curve through the sources' centres (in TourOrder),
// each looking as the two sources around it do (rotations slerped), with the first source's
// intrinsics. One source: that camera, `frames` times.
std::vector<NamedCamera> PhotoTourCameras(int frames, const SceneFrame& frame,
                                          const std::vector<PosedCamera>& sources,
                                          const std::vector<std::string>& names) {
  const std::vector<size_t> order = TourOrder(frame, sources, names);
  std::vector<Eigen::Vector3d> keys;
  for (size_t index : order) keys.push_back(CameraCenter(sources[index].cam_from_world));
  const auto key = [&](ptrdiff_t i) {
    return keys[static_cast<size_t>(std::clamp<ptrdiff_t>(i, 0, static_cast<ptrdiff_t>(keys.size()) - 1))];
  };
  // Uniform Catmull-Rom on segment i: through key(i) at t = 0 and key(i + 1) at t = 1, C1 there.
  const auto curve = [&](size_t segment, double t) -> Eigen::Vector3d {
    const auto i = static_cast<ptrdiff_t>(segment);
    return 0.5 * (2 * key(i) + (key(i + 1) - key(i - 1)) * t +
                  (2 * key(i - 1) - 5 * key(i) + 4 * key(i + 1) - key(i + 2)) * t * t +
                  (-key(i - 1) + 3 * key(i) - 3 * key(i + 1) + key(i + 2)) * t * t * t);
  };
  // The curve's length at kSteps points per segment, so frames are spaced by length, not by t.
  constexpr int kSteps = 64;
  const size_t segments = std::max<size_t>(1, keys.size() - 1);
  std::vector<double> length{0};
  for (size_t i = 0; i < segments; ++i) {
    for (int step = 1; step <= kSteps; ++step) {
      length.push_back(length.back() + (curve(i, static_cast<double>(step) / kSteps) -
                                        curve(i, static_cast<double>(step - 1) / kSteps)).norm());
    }
  }
  std::vector<NamedCamera> cameras;
  for (int f = 0; f < frames; ++f) {
    const double wanted = frames == 1 ? 0.5 * length.back() : length.back() * f / (frames - 1);
    const size_t upper = static_cast<size_t>(std::lower_bound(length.begin(), length.end(), wanted) - length.begin());
    const size_t sample = std::clamp<size_t>(upper, 1, length.size() - 1) - 1;
    const double span = length[sample + 1] - length[sample];
    const double part = span > 0 ? std::clamp((wanted - length[sample]) / span, 0.0, 1.0) : 0.0;
    const size_t segment = std::min(sample / kSteps, segments - 1);
    const double t = std::min(1.0, (static_cast<double>(sample - segment * kSteps) + part) / kSteps);
    const Eigen::Vector3d centre = curve(segment, t);
    const Rigid3d& a = sources[order[segment]].cam_from_world;
    const Rigid3d& b = sources[order[std::min(segment + 1, order.size() - 1)]].cam_from_world;
    const Eigen::Quaterniond rotation = InterpolatePose(a, b, t).rotation;
    cameras.push_back({FrameName("photos", f), {sources.front().camera, Rigid3d(rotation, -(rotation * centre))}});
  }
  return cameras;
}

// A camera from a file is rendered only within the image size limit, and only if its
// distortion can be inverted somewhere (distorted_target.h).
void CheckRenderable(const fs::path& model_dir, const NamedCamera& target) {
  const Camera& camera = target.camera.camera;
  const std::string where = model_dir.string() + ": camera " + std::to_string(camera.id) + " of " + target.name;
  if (OverPixelLimit(static_cast<double>(camera.width), static_cast<double>(camera.height))) {
    throw BadInputError(where + " is " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                        ", over " + PixelLimitName(camera.width, camera.height) + " of an image");
  }
  try {
    RenderedCamera(target.camera);
  } catch (const BadInputError& error) {
    throw BadInputError(where + " cannot be rendered: " + error.what());
  }
}

}  // namespace

std::vector<NamedCamera> CamerasOfModel(const SparseModel& model, std::vector<std::string>* image_names) {
  std::vector<NamedCamera> cameras;
  for (const SparseImage& image : model.Images()) {
    cameras.push_back({fs::path(image.name).stem().string(), {model.CameraById(image.camera_id), image.cam_from_world}});
    if (image_names != nullptr) image_names->push_back(image.name);
  }
  return cameras;
}

std::vector<NamedCamera> CamerasFromModel(const fs::path& model_dir) {
  const std::vector<NamedCamera> cameras = CamerasOfModel(ReadSparseModel(model_dir));
  for (const NamedCamera& camera : cameras) CheckRenderable(model_dir, camera);
  if (cameras.empty()) throw BadInputError(model_dir.string() + ": the model has no images");
  return cameras;
}

std::string CameraPath::Spec() const {
  switch (kind) {
    case Kind::kOrbit: return "orbit:" + std::to_string(frames);
    case Kind::kPhotos: return "photos:" + std::to_string(frames);
    case Kind::kBetween: break;
  }
  return "between:" + from + "," + to + "," + std::to_string(frames);
}

CameraPath ParseCameraPath(const std::string& spec) {
  const size_t colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string rest = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (kind == "orbit" && colon != std::string::npos) {
    return {CameraPath::Kind::kOrbit, ParseCount(rest, spec), "", ""};
  }
  if (kind == "photos" && colon != std::string::npos) {
    return {CameraPath::Kind::kPhotos, ParseCount(rest, spec), "", ""};
  }
  if (kind == "between" && colon != std::string::npos) {
    std::vector<std::string> parts;
    std::istringstream words(rest);
    for (std::string part; std::getline(words, part, ',');) parts.push_back(part);
    if (parts.size() != 3) {
      throw BadInputError("--path " + spec + ": expected between:IMAGE_A,IMAGE_B,N");
    }
    return {CameraPath::Kind::kBetween, ParseCount(parts[2], spec), parts[0], parts[1]};
  }
  throw BadInputError("--path " + spec + ": expected orbit:N, photos:N or between:IMAGE_A,IMAGE_B,N");
}

std::vector<NamedCamera> CamerasAlongPath(const CameraPath& path, const SceneFiles& scene,
                                          const std::vector<PosedCamera>& sources,
                                          const std::vector<std::string>& source_names) {
  const std::string spec = path.Spec();
  if (sources.empty()) throw BadInputError("--path " + spec + ": there are no source cameras");
  if (path.kind == CameraPath::Kind::kOrbit) return OrbitCameras(path.frames, scene, sources);
  if (path.kind == CameraPath::Kind::kPhotos) {
    return PhotoTourCameras(path.frames, ReadSceneFrame(scene, sources), sources, source_names);
  }
  auto find = [&](const std::string& name) -> const PosedCamera& {
    for (size_t i = 0; i < source_names.size(); ++i) {
      if (source_names[i] == name || fs::path(source_names[i]).stem() == name) return sources[i];
    }
    throw BadInputError("--path " + spec + ": no source image named '" + name + "'");
  };
  const PosedCamera& a = find(path.from);
  const PosedCamera& b = find(path.to);
  std::vector<NamedCamera> cameras;
  for (int i = 0; i < path.frames; ++i) {
    const double t = path.frames == 1 ? 0.5 : static_cast<double>(i) / (path.frames - 1);
    cameras.push_back({FrameName("between", i),
                       {a.camera, InterpolatePose(a.cam_from_world, b.cam_from_world, t)}});
  }
  return cameras;
}

SourceLibrary::SourceLibrary(ViewSetPaths paths) : paths_(std::move(paths)) {
  cameras_ = ReadPosedCameras(paths_, &names_);
  gains_ = ReadColorGainsIfPresent(paths_.color_gains);
  loaded_.resize(cameras_.size());
}

const SourceView& SourceLibrary::Load(int index, const ForwardWarpOptions& warp) {
  std::unique_ptr<SourceView>& slot = loaded_.at(static_cast<size_t>(index));
  if (!slot) {
    auto view = std::make_unique<SourceView>();
    const std::string& name = names_[static_cast<size_t>(index)];
    view->name = name;
    view->camera = cameras_[static_cast<size_t>(index)].camera;
    view->cam_from_world = cameras_[static_cast<size_t>(index)].cam_from_world;
    const Image photo = ReadImage(paths_.images / name);
    view->color = SrgbToLinear(photo);
    if (view->color.Channels() != 3) {
      throw BadInputError((paths_.images / name).string() + ": expected an RGB image");
    }
    view->depth = ReadDepthExrAt(paths_.DepthFor(name), view->color.Width(), view->color.Height());
    if (preparation_) prepared_pixels_ += preparation_(view.get());
    loaded_pixels_ += static_cast<long>(view->depth.Values().size());
    PrepareSource(view.get(), warp, gains_.Of(name));
    slot = std::move(view);
  }
  return *slot;
}

std::vector<std::string> SourceLibrary::DropViewsWithoutDepth() {
  std::vector<std::string> dropped;
  std::vector<PosedCamera> cameras;
  std::vector<std::string> names;
  for (size_t i = 0; i < cameras_.size(); ++i) {
    if (fs::exists(paths_.DepthFor(names_[i]))) {
      cameras.push_back(cameras_[i]);
      names.push_back(names_[i]);
    } else {
      dropped.push_back(names_[i]);
    }
  }
  cameras_ = std::move(cameras);
  names_ = std::move(names);
  loaded_.clear();
  loaded_.resize(cameras_.size());
  return dropped;
}

int SourceLibrary::LoadedCount() const {
  int count = 0;
  for (const auto& view : loaded_) count += view != nullptr;
  return count;
}

namespace {

// A view is rendered again with one more source only while its unseen pixels make up this
// share of the image: below it, another warp costs more than the few pixels it could fix.
constexpr double kMinUnseenRatioForMoreSources = 0.001;
// A source is added only when at least this many of the sampled unseen points lie in its frame.
constexpr int kMinUnseenPointsInFrame = 32;
// An added source must leave at most this share of the unseen pixels.
constexpr double kKeptUnseenShare = 0.9;

// Share of the image's pixels that are Unseen.
double UnseenRatio(const RenderResult& result) {
  long count = 0;
  for (int y = 0; y < result.classes.height; ++y) {
    for (int x = 0; x < result.classes.width; ++x) count += Unseen(result, x, y) ? 1 : 0;
  }
  const auto pixels = static_cast<double>(result.classes.classes.size());
  return pixels > 0 ? static_cast<double>(count) / pixels : 0.0;
}

}  // namespace

bool Unseen(const RenderResult& result, int x, int y) {
  const PixelClass c = result.classes.At(x, y);
  return IsHole(c) || (c == PixelClass::kOutOfView && result.depth.At(x, y) > 0);
}

std::vector<Eigen::Vector3d> UnseenPoints(const RenderResult& result, const PosedCamera& target) {
  const Pinhole camera = Pinhole::From(target.camera);
  const Rigid3d world_from_cam = target.cam_from_world.Inverse();
  std::vector<Eigen::Vector3d> points;
  for (int y = 0; y < result.classes.height; y += 2) {
    for (int x = 0; x < result.classes.width; x += 2) {
      const float depth = result.depth.At(x, y);
      if (!Unseen(result, x, y) || !(depth > 0) || !std::isfinite(depth)) continue;
      points.push_back(world_from_cam * (camera.PixelRay(x, y) * static_cast<double>(depth)));
    }
  }
  return points;
}

namespace {

// Sources corrected by their color gains blend without exposure steps, at the exposure common
// to the set; a photo taken at the target would rather have the exposure of the cameras
// nearby (auto exposure follows what is in view): the inverse of the geometric mean of the
// selected sources' gains.
RgbGain ExposureOfSources(const SourceLibrary& library, const std::vector<int>& selected) {
  std::array<double, 3> log_sum{0, 0, 0};
  for (const int index : selected) {
    const RgbGain gain = library.Gain(index);
    for (size_t c = 0; c < 3; ++c) log_sum[c] += std::log(static_cast<double>(gain[c]));
  }
  RgbGain exposure;
  for (size_t c = 0; c < 3; ++c) {
    exposure[c] = static_cast<float>(std::exp(-log_sum[c] / static_cast<double>(std::max<size_t>(1, selected.size()))));
  }
  return exposure;
}

}  // namespace

void RenderNovelView(SourceLibrary& library, const NamedCamera& target,
                     const SourceSelectionOptions& selection, Renderer& renderer, NovelView* view) {
  using Clock = std::chrono::steady_clock;
  const Camera& camera = target.camera.camera;
  if (camera.HasDistortion()) {
    const NamedCamera pinhole{target.name, RenderedCamera(target.camera)};
    RenderNovelView(library, pinhole, selection, renderer, view);
    const auto start = Clock::now();
    ResampleIntoDistorted(camera, pinhole.camera.camera, &view->result);
    view->ms += MsSince(start);
    return;
  }
  const auto select_start = Clock::now();
  std::vector<int> chosen = SelectSources(library.Cameras(), target.camera, selection);
  const auto select_end = Clock::now();
  if (chosen.empty()) {
    throw BadInputError("render " + target.name + ": no source view sees what this camera sees");
  }
  view->sources.clear();
  std::vector<const SourceView*> sources;
  const ForwardWarpOptions& warp = renderer.Options().warp;
  for (int index : chosen) sources.push_back(&library.Load(index, warp));
  const std::vector<int> selected = chosen;
  Clock::duration spent = select_end - select_start;
  // More sources, one at a time, while unseen pixels remain and some source sees them.
  const int hole_sources =
      renderer.Options().fill.method == FillMethod::kDepthAware ? selection.hole_sources : 0;
  auto render_start = Clock::now();
  renderer.Render(sources, target.camera, &view->result);
  double unseen = hole_sources > 0 ? UnseenRatio(view->result) : 0.0;
  spent += Clock::now() - render_start;
  for (int extra = 0; extra < hole_sources; ++extra) {
    if (unseen < kMinUnseenRatioForMoreSources) break;
    const auto pick_start = Clock::now();
    const int pick = SourceSeeingMost(library.Cameras(), target.camera,
                                      UnseenPoints(view->result, target.camera), chosen,
                                      kMinUnseenPointsInFrame, selection);
    spent += Clock::now() - pick_start;
    if (pick < 0) break;
    const SourceView& source = library.Load(pick, warp);
    render_start = Clock::now();
    renderer.RenderWithOneMore(source, &view->with_one_more);
    const double unseen_after = UnseenRatio(view->with_one_more);
    spent += Clock::now() - render_start;
    // Kept only when it shows a tenth of the unseen pixels at least: else it did not see
    // them after all (occluded as well), and the render without it stands.
    if (!(unseen_after < kKeptUnseenShare * unseen)) break;
    chosen.push_back(pick);
    std::swap(view->result, view->with_one_more);
    unseen = unseen_after;
  }
  for (int index : chosen) view->sources.push_back(library.Names()[static_cast<size_t>(index)]);
  ApplyGain(ExposureOfSources(library, selected), view->result.color);
  // Selection and rendering; reading files is left out (the first targets pay for all).
  view->ms = std::chrono::duration<double, std::milli>(spent).count();
}

void WriteNovelView(const fs::path& dir, const std::string& name, const RenderResult& result) {
  fs::create_directories(dir);
  WriteImage(dir / (name + ".png"), LinearToSrgb(result.color), PixelFormat::kUint8);
  Image holes(result.classes.width, result.classes.height, 1);
  for (size_t i = 0; i < result.classes.classes.size(); ++i) {
    holes.Pixels()[i] = IsHole(result.classes.classes[i]) ? 1.0f : 0.0f;
  }
  WriteImage(dir / (name + ".holes.png"), holes, PixelFormat::kUint8);
  WriteDepthExr(dir / (name + ".depth.exr"), result.depth);
}

}  // namespace parallax
