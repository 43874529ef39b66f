#pragma once
// Depth maps: float32 z-depth along the optical axis, in scene units, one value per pixel
// centre. 0 means "no value" (invalid, sky, not estimated). Never NaN or Inf: constructors of
// depth maps from files reject them, writers refuse them.
//
// Two file formats: single-channel EXR (our convention) and COLMAP's dense array `.bin`
// (ASCII header "W&H&C&", then little-endian float32, channel-major: index (c*H + row)*W + col),
// which also carries normal maps (3 channels).
#include <filesystem>
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace parallax {

class DepthMap {
 public:
  DepthMap() = default;
  // Zero-filled ("no value" everywhere). Throws InternalError for negative sizes.
  DepthMap(int width, int height);
  // As a new DepthMap(width, height), keeping the memory when it is large enough.
  void Reset(int width, int height);

  int Width() const { return width_; }
  int Height() const { return height_; }
  bool Empty() const { return values_.empty(); }
  float& At(int x, int y) { return values_[static_cast<size_t>(y) * width_ + x]; }
  float At(int x, int y) const { return values_[static_cast<size_t>(y) * width_ + x]; }
  std::vector<float>& Values() { return values_; }
  const std::vector<float>& Values() const { return values_; }

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<float> values_;
};

// Depth at a continuous pixel position (pixel centres at +0.5): inverse depth interpolated
// bilinearly between the four nearest pixel centres when all are valid and within `max_ratio`
// of each other (one surface; exact on planes, where inverse depth is affine in the image),
// else the depth of the pixel the position lies in. std::nullopt outside the map or where
// that depth is 0.
std::optional<double> SampleDepth(const DepthMap& depth, const Eigen::Vector2d& pixel,
                                  double max_ratio);

// For each pixel of a width x height image (row-major), the index of the pixel of a
// grid_width x grid_height map over the same area that its centre falls in: how a map made at
// a lower resolution (the depth stage's working size) is read at the photo's size (nearest,
// never blending depths across an edge), and how fusion picks its working pixels.
std::vector<size_t> PixelsAtCentres(int grid_width, int grid_height, int width, int height);
// The same for the one pixel (x, y).
size_t PixelAtCentre(int grid_width, int grid_height, int width, int height, int x, int y);

// A COLMAP dense array: `channels` planes of width x height floats, channel-major.
struct DenseArray {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> values;  // Index (c * height + row) * width + col.
};

// Reads a depth EXR with exactly one channel, whatever its name ("Z", "Y", "R", ...).
// Throws BadInputError naming the file for a missing/corrupt file, several channels, negative
// values, NaN or Inf.
DepthMap ReadDepthExr(const std::filesystem::path& path);
// A depth EXR read at a photo's width x height: the depth stage writes its maps at its working
// size, which may be smaller; each pixel then holds the value of the map's pixel its centre
// falls in (PixelsAtCentres: nearest, never blending depths across an edge). Throws
// BadInputError naming the file when the map is larger than the photo or of another shape.
DepthMap ReadDepthExrAt(const std::filesystem::path& path, int width, int height);
// Writes one float32 channel named "Z", ZIP-compressed (lossless), atomically. Throws
// InternalError for negative, NaN or Inf values.
void WriteDepthExr(const std::filesystem::path& path, const DepthMap& depth);

// COLMAP dense `.bin`. The reader checks the header against the file size before allocating
// (a lying header is BadInputError, not a huge allocation) and rejects NaN/Inf.
DenseArray ReadColmapArray(const std::filesystem::path& path);
void WriteColmapArray(const std::filesystem::path& path, const DenseArray& array);

// Depth through the dense format (one channel); the reader rejects other channel counts and
// negative values.
DepthMap ReadColmapDepth(const std::filesystem::path& path);
void WriteColmapDepth(const std::filesystem::path& path, const DepthMap& depth);

}  // namespace parallax
