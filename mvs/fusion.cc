#include "mvs/fusion.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <cstring>
#include <fstream>
#include <numbers>
#include <stdexcept>
#include <unordered_map>

#include <opencv2/imgproc.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/check.h"
#include "mvs/working_resolution.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

struct FusionView {
  Camera camera;
  Rigid3d cam_from_world;
  Eigen::Matrix3d world_from_cam;
  DepthMap depth;
  DenseArray normals;  // Camera frame, channel-major (COLMAP layout).
  Image color;        // Linear RGB, corrected by the photo's color gain.

  size_t Pixels() const { return static_cast<size_t>(depth.Width()) * depth.Height(); }
  Eigen::Vector3d Normal(int x, int y) const {
    const size_t i = static_cast<size_t>(y) * depth.Width() + x;
    return {normals.values[i], normals.values[Pixels() + i], normals.values[2 * Pixels() + i]};
  }
};

// The camera a view is fused with.
Camera FusionCamera(const Camera& camera, const FusionOptions& options) {
  const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
  return WorkingCamera(camera, WorkingScale(width, height, options.image_scale, options.max_image_size));
}

// `image` resampled to width x height by area averaging (no aliasing).
Image ResampleArea(const Image& image, int width, int height) {
  if (image.Width() == width && image.Height() == height) return image;
  const int type = CV_32FC(image.Channels());
  const cv::Mat full(image.Height(), image.Width(), type, const_cast<float*>(image.Pixels().data()));
  Image small(width, height, image.Channels());
  cv::Mat resampled(height, width, type, small.Pixels().data());
  cv::resize(full, resampled, resampled.size(), 0, 0, cv::INTER_AREA);
  return small;
}

// For each view, the `max_neighbours` others sharing the most sparse points with it (ties: the
// earlier), in view order.
std::vector<std::vector<size_t>> Neighbours(const SparseModel& model, const std::vector<const SparseImage*>& views,
                                            int max_neighbours) {
  std::map<uint32_t, size_t> index_of;
  for (size_t i = 0; i < views.size(); ++i) index_of[views[i]->id] = i;
  std::vector<std::vector<int>> shared(views.size(), std::vector<int>(views.size(), 0));
  for (const Point3D& point : model.Points3D()) {
    for (const TrackElement& a : point.track) {
      for (const TrackElement& b : point.track) {
        const auto ia = index_of.find(a.image_id), ib = index_of.find(b.image_id);
        if (ia != index_of.end() && ib != index_of.end() && ia->second != ib->second) ++shared[ia->second][ib->second];
      }
    }
  }
  std::vector<std::vector<size_t>> neighbours(views.size());
  for (size_t i = 0; i < views.size(); ++i) {
    std::vector<size_t> others;
    for (size_t j = 0; j < views.size(); ++j) {
      if (j != i) others.push_back(j);
    }
    std::stable_sort(others.begin(), others.end(), [&](size_t a, size_t b) { return shared[i][a] > shared[i][b]; });
    others.resize(std::min(others.size(), static_cast<size_t>(max_neighbours)));
    std::sort(others.begin(), others.end());
    neighbours[i] = std::move(others);
  }
  return neighbours;
}

// The views one reference fuses with, loaded as needed and kept while they fit: memory is
// bounded by `capacity` views whatever their number.
class FusionViewCache {
 public:
  FusionViewCache(const SparseModel& model, const std::vector<const SparseImage*>& views, const LoadFusionView& load,
                  const FusionOptions& options)
      : model_(model), views_(views), load_(load), options_(options),
        capacity_(static_cast<size_t>(options.max_neighbours) + 1) {}

  // Every view of `wanted` resident at once; pointers stay valid until the next call.
  std::map<size_t, FusionView*> Acquire(const std::vector<size_t>& wanted) {
    ++tick_;
    const std::set<size_t> keep(wanted.begin(), wanted.end());
    size_t missing = 0;
    for (const size_t index : wanted) missing += resident_.count(index) ? 0 : 1;
    while (resident_.size() + missing > std::max(capacity_, wanted.size()) && EvictOldestOutside(keep)) {
    }
    std::map<size_t, FusionView*> acquired;
    for (const size_t index : wanted) {
      Entry& entry = resident_[index];
      if (!entry.view) entry.view = std::make_unique<FusionView>(Load(*views_[index]));
      entry.last_used = tick_;
      acquired[index] = entry.view.get();
    }
    return acquired;
  }

 private:
  struct Entry {
    std::unique_ptr<FusionView> view;
    uint64_t last_used = 0;
  };

  bool EvictOldestOutside(const std::set<size_t>& keep) {
    auto oldest = resident_.end();
    for (auto it = resident_.begin(); it != resident_.end(); ++it) {
      if (!keep.count(it->first) && (oldest == resident_.end() || it->second.last_used < oldest->second.last_used)) {
        oldest = it;
      }
    }
    if (oldest == resident_.end()) return false;
    resident_.erase(oldest);
    return true;
  }

  FusionView Load(const SparseImage& image) const {
    const Camera& camera = model_.CameraById(image.camera_id);
    const FusionViewMaps maps = load_(image);
    const DepthMap& depth = maps.depth;
    const DenseArray& normals = maps.normals;
    const Image& color = maps.color;
    const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
    const int map_width = depth.Width(), map_height = depth.Height();
    if (map_width > width || map_height > height || normals.width != map_width || normals.height != map_height ||
        normals.channels != 3 || color.Width() != width || color.Height() != height) {
      throw BadInputError("fusion: the depth and normal maps of " + image.name +
                          " differ in size or are larger than its image and camera");
    }
    FusionView view;
    view.camera = FusionCamera(camera, options_);
    view.cam_from_world = image.cam_from_world;
    view.world_from_cam = image.cam_from_world.rotation.conjugate().toRotationMatrix();
    const int working_width = static_cast<int>(view.camera.width);
    const int working_height = static_cast<int>(view.camera.height);
    // Each working pixel reads the maps where the photo's pixel its centre falls in reads
    // them: the maps may be smaller than the photo (the depth stage's working size), and are
    // read at it as ReadDepthExrAt upsamples them, nearest.
    const std::vector<size_t> fine = PixelsAtCentres(width, height, working_width, working_height);
    const size_t map_pixels = static_cast<size_t>(map_width) * static_cast<size_t>(map_height);
    view.depth = DepthMap(working_width, working_height);
    view.normals = {working_width, working_height, 3, std::vector<float>(3 * fine.size())};
    for (size_t i = 0; i < fine.size(); ++i) {
      const int x = static_cast<int>(fine[i] % static_cast<size_t>(width));
      const int y = static_cast<int>(fine[i] / static_cast<size_t>(width));
      const size_t in_map = PixelAtCentre(map_width, map_height, width, height, x, y);
      view.depth.Values()[i] = depth.Values()[in_map];
      for (size_t c = 0; c < 3; ++c) view.normals.values[c * fine.size() + i] = normals.values[c * map_pixels + in_map];
    }
    view.color = ResampleArea(SrgbToLinear(color), working_width, working_height);
    ApplyGain(maps.gain, view.color);
    return view;
  }

  const SparseModel& model_;
  const std::vector<const SparseImage*>& views_;
  const LoadFusionView& load_;
  const FusionOptions& options_;
  const size_t capacity_;
  std::map<size_t, Entry> resident_;
  uint64_t tick_ = 0;
};

// The pixels already merged into a point, one bit each, for every view (small enough to keep
// for all of them).
using UsedPixels = std::vector<std::vector<bool>>;

// The fused points, indexed by the cell of space each lies in. A reference merges only with its
// neighbours' pixels, so a surface that views far apart in the neighbour graph both see would be
// fused once by each, and the cloud would grow with the number of photos. A new point is merged
// instead into the nearest point an earlier reference fused that is the same sample of the same
// surface: facing the same way, within the merge spacing of it along the surface and within the
// depth tolerance across it. The first reference to fuse a surface sets its density, later ones
// only fill the gaps: the cloud follows the surface and the working resolution, not the number
// of photos, and so do fusion's and the mesh's memory.
class FusedCloud {
 public:
  explicit FusedCloud(const FusionOptions& options)
      : min_normal_cos_(std::cos(options.max_merge_normal_angle_deg * std::numbers::pi / 180)),
        max_relative_depth_(options.max_relative_depth),
        merge_spacing_(options.merge_spacing_pixels) {}

  // The reference's own points are never merged with each other: they are one per pixel.
  void BeginReference() { reference_start_ = points_.size(); }

  // `depth`: the point's depth in the fusing view; `footprint`: that pixel's width there.
  void Add(const FusedPoint& point, double depth, double footprint) {
    const int level = static_cast<int>(std::ceil(std::log2(footprint))) + 1;
    const std::optional<Cell> cell = CellOf(point.position, level);
    if (!cell) {
      points_.push_back(point);
      next_in_cell_.push_back(kNone);
      return;
    }
    if (const std::optional<uint32_t> same = SameSample(point, level, depth, merge_spacing_ * footprint)) {
      Merge(point, points_[*same]);
      return;
    }
    const auto index = static_cast<uint32_t>(points_.size());
    points_.push_back(point);
    const auto [head, inserted] = cells_.try_emplace(*cell, index);
    next_in_cell_.push_back(inserted ? kNone : head->second);
    head->second = index;
  }

  FusedPoints Release() && { return std::move(points_); }

 private:
  static constexpr uint32_t kNone = UINT32_MAX;

  // A cube 2^level wide, level chosen so that it is two to four pixels wide.
  struct Cell {
    int32_t x, y, z, level;
    bool operator==(const Cell&) const = default;
  };
  struct CellHash {
    size_t operator()(const Cell& cell) const {
      uint64_t hash = 1469598103934665603ull;  // FNV-1a over the four coordinates.
      for (const int32_t value : {cell.x, cell.y, cell.z, cell.level}) {
        hash = (hash ^ static_cast<uint32_t>(value)) * 1099511628211ull;
      }
      return hash;
    }
  };

  // None when the coordinates would not fit the cell's integers (a point absurdly far away).
  static std::optional<Cell> CellOf(const Eigen::Vector3f& position, int level) {
    const double size = std::ldexp(1.0, level);
    Cell cell{0, 0, 0, level};
    for (int axis = 0; axis < 3; ++axis) {
      const double index = std::floor(static_cast<double>(position[axis]) / size);
      if (!(std::abs(index) < 1e9)) return std::nullopt;
      (&cell.x)[axis] = static_cast<int32_t>(index);
    }
    return cell;
  }

  // The nearest earlier point that `point` samples again, among the 27 cells around it at its
  // own level and at the next finer one (where a closer view's points lie).
  std::optional<uint32_t> SameSample(const FusedPoint& point, int level, double depth, double max_along) const {
    std::optional<uint32_t> nearest;
    double nearest_distance = 0;
    for (const int cell_level : {level, level - 1}) {
      const std::optional<Cell> cell = CellOf(point.position, cell_level);
      if (!cell) continue;
      const double max_across = std::min(max_relative_depth_ * depth, std::ldexp(1.0, cell_level));
      NearestInCells(point, *cell, max_along, max_across, nearest, nearest_distance);
    }
    return nearest;
  }

  // Updates `nearest` with the points of the 27 cells around `cell` that `point` samples again.
  void NearestInCells(const FusedPoint& point, const Cell& cell, double max_along, double max_across,
                      std::optional<uint32_t>& nearest, double& nearest_distance) const {
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const auto found = cells_.find({cell.x + dx, cell.y + dy, cell.z + dz, cell.level});
          if (found == cells_.end()) continue;
          for (uint32_t i = found->second; i != kNone; i = next_in_cell_[i]) {
            if (i >= reference_start_) continue;
            const FusedPoint& other = points_[i];
            if (static_cast<double>(other.normal.dot(point.normal)) < min_normal_cos_) continue;
            const Eigen::Vector3d offset = (point.position - other.position).cast<double>();
            const double across = std::abs(offset.dot(other.normal.cast<double>()));
            const double along = std::sqrt(std::max(0.0, offset.squaredNorm() - across * across));
            if (across > max_across || along > max_along) continue;
            if (!nearest || offset.norm() < nearest_distance) {
              nearest = i;
              nearest_distance = offset.norm();
            }
          }
        }
      }
    }
  }

  // `into` becomes the mean of both, each weighted by the pixels it was fused from.
  static void Merge(const FusedPoint& point, FusedPoint& into) {
    const float a = into.views, b = point.views, sum = a + b;
    into.position = (into.position * a + point.position * b) / sum;
    into.normal = (into.normal * a + point.normal * b).normalized();
    for (int c = 0; c < 3; ++c) {
      const float linear = (SrgbToLinear(into.color[c] / 255.0f) * a + SrgbToLinear(point.color[c] / 255.0f) * b) / sum;
      into.color[c] = static_cast<uint8_t>(std::lround(std::clamp(LinearToSrgb(linear), 0.0f, 1.0f) * 255));
    }
    into.views = static_cast<uint16_t>(std::min(sum, 65535.0f));
  }

  const double min_normal_cos_;
  const double max_relative_depth_;
  const double merge_spacing_;
  FusedPoints points_;
  std::deque<uint32_t> next_in_cell_;  // Per point: the next point of its cell, or kNone.
  std::unordered_map<Cell, uint32_t, CellHash> cells_;  // The last point added to each cell.
  size_t reference_start_ = 0;
};

// The reference's unused pixels, each merged with the neighbours' pixels that see the same
// surface, appended to `points`.
void FuseReference(size_t reference_index, const std::map<size_t, FusionView*>& views, const FusionOptions& options,
                   UsedPixels& used, FusedCloud& cloud) {
  const double min_normal_cos = std::cos(options.max_normal_angle_deg * std::numbers::pi / 180);
  const FusionView& reference = *views.at(reference_index);
  std::vector<bool>& reference_used = used[reference_index];
  cloud.BeginReference();
  for (int y = 0; y < reference.depth.Height(); ++y) {
    for (int x = 0; x < reference.depth.Width(); ++x) {
      const size_t pixel = static_cast<size_t>(y) * reference.depth.Width() + x;
      const float depth = reference.depth.At(x, y);
      if (reference_used[pixel] || !(depth > 0)) continue;
      reference_used[pixel] = true;
      const Eigen::Vector3d point = reference.world_from_cam *
          (*reference.camera.Unproject({x + 0.5, y + 0.5}, depth) - reference.cam_from_world.translation);
      const Eigen::Vector3d normal = reference.world_from_cam * reference.Normal(x, y);
      Eigen::Vector3d position_sum = point, normal_sum = normal, color_sum = Eigen::Vector3d::Zero();
      for (int c = 0; c < 3; ++c) color_sum[c] = reference.color.At(x, y, c);
      int count = 1;
      for (const auto& [j, other] : views) {
        if (j == reference_index) continue;
        const Eigen::Vector3d in_other = other->cam_from_world * point;
        const std::optional<Eigen::Vector2d> projected = other->camera.Project(in_other);
        if (!projected) continue;
        const int ox = static_cast<int>(std::floor(projected->x()));
        const int oy = static_cast<int>(std::floor(projected->y()));
        if (ox < 0 || oy < 0 || ox >= other->depth.Width() || oy >= other->depth.Height()) continue;
        const size_t other_pixel = static_cast<size_t>(oy) * other->depth.Width() + ox;
        const double other_depth = other->depth.At(ox, oy);
        if (used[j][other_pixel] || !(other_depth > 0) ||
            std::abs(other_depth - in_other.z()) > options.max_relative_depth * in_other.z()) {
          continue;
        }
        const Eigen::Vector3d other_normal = other->world_from_cam * other->Normal(ox, oy);
        if (other_normal.dot(normal) < min_normal_cos) continue;
        used[j][other_pixel] = true;
        position_sum += other->world_from_cam *
            (*other->camera.Unproject({ox + 0.5, oy + 0.5}, other_depth) - other->cam_from_world.translation);
        normal_sum += other_normal;
        for (int c = 0; c < 3; ++c) color_sum[c] += static_cast<double>(other->color.At(ox, oy, c));
        ++count;
      }
      if (count < options.min_views) continue;
      FusedPoint fused;
      fused.position = (position_sum / count).cast<float>();
      fused.normal = normal_sum.normalized().cast<float>();
      for (int c = 0; c < 3; ++c) {
        const float encoded = LinearToSrgb(static_cast<float>(color_sum[c] / count));
        fused.color[c] = static_cast<uint8_t>(std::lround(std::clamp(encoded, 0.0f, 1.0f) * 255));
      }
      fused.views = static_cast<uint16_t>(std::min(count, 65535));
      cloud.Add(fused, static_cast<double>(depth), static_cast<double>(depth) / reference.camera.FocalX());
    }
  }
}

}  // namespace

void FusionOptions::Check() const {
  RequireOption(min_views >= 1, "FusionOptions.min_views", min_views, ">= 1");
  RequireOption(max_neighbours >= 1, "FusionOptions.max_neighbours", max_neighbours, ">= 1");
  RequireOption(max_relative_depth > 0, "FusionOptions.max_relative_depth", max_relative_depth, "> 0");
  RequireOption(max_normal_angle_deg > 0 && max_normal_angle_deg <= 180, "FusionOptions.max_normal_angle_deg",
                max_normal_angle_deg, "(0, 180]");
  RequireOption(max_merge_normal_angle_deg > 0 && max_merge_normal_angle_deg <= 180,
                "FusionOptions.max_merge_normal_angle_deg", max_merge_normal_angle_deg, "(0, 180]");
  RequireOption(merge_spacing_pixels > 0 && merge_spacing_pixels <= 2, "FusionOptions.merge_spacing_pixels",
                merge_spacing_pixels, "(0, 2]");
  RequireOption(image_scale >= 0.25 && image_scale <= 1, "FusionOptions.image_scale", image_scale, "[0.25, 1]");
  RequireOption(max_image_size == 0 || max_image_size >= 64, "FusionOptions.max_image_size", max_image_size,
                "0 (no cap) or >= 64");
}

FusedPoints FuseDepthMaps(const SparseModel& model, const std::vector<const SparseImage*>& views,
                          const LoadFusionView& load, const FusionOptions& options, Progress& progress) {
  options.Check();
  const std::vector<std::vector<size_t>> neighbours = Neighbours(model, views, options.max_neighbours);
  FusionViewCache cache(model, views, load, options);
  UsedPixels used(views.size());
  for (size_t i = 0; i < views.size(); ++i) {
    const Camera camera = FusionCamera(model.CameraById(views[i]->camera_id), options);
    used[i].assign(static_cast<size_t>(camera.width) * static_cast<size_t>(camera.height), false);
  }
  FusedCloud cloud(options);
  const auto total = static_cast<int64_t>(views.size());
  for (size_t i = 0; i < views.size(); ++i) {
    progress.Update("fusion", static_cast<int64_t>(i), total);
    std::vector<size_t> wanted = neighbours[i];
    wanted.push_back(i);
    FuseReference(i, cache.Acquire(wanted), options, used, cloud);
  }
  progress.Update("fusion", total, total);
  return std::move(cloud).Release();
}

void WritePly(const fs::path& path, const FusedPoints& points) {
  const std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex " +
                             std::to_string(points.size()) +
                             "\nproperty float x\nproperty float y\nproperty float z\n"
                             "property float nx\nproperty float ny\nproperty float nz\n"
                             "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  // Streamed: a copy of the whole cloud in memory would double fusion's peak.
  WriteAtomically(path, [&](const fs::path& temporary) {
    std::ofstream out(temporary, std::ios::binary);
    out << header;
    std::array<char, 6 * sizeof(float) + 3> vertex{};
    for (const FusedPoint& point : points) {
      std::memcpy(vertex.data(), point.position.data(), 3 * sizeof(float));
      std::memcpy(vertex.data() + 3 * sizeof(float), point.normal.data(), 3 * sizeof(float));
      std::memcpy(vertex.data() + 6 * sizeof(float), point.color.data(), 3);
      out.write(vertex.data(), vertex.size());
    }
    out.close();
    if (!out) throw BadInputError("cannot write " + path.string());
  });
}

}  // namespace parallax
