#pragma once
// Images in memory and on disk (through OpenImageIO: PNG, JPEG, TIFF, EXR, ...).
//
// Common principles:
//  - In memory an image is float, interleaved, row-major, with 1..4 channels, holding the
//    values the file holds scaled to [0, 1] for integer formats. No color conversion happens
//    behind the caller's back: 8-bit files are sRGB-encoded, EXR files are linear, and the
//    caller converts explicitly with SrgbToLinear / LinearToSrgb.
//  - Readers throw BadInputError naming the file and the problem; writers refuse NaN or Inf
//    and write through a temporary file.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace parallax {

class Image {
 public:
  Image() = default;
  // Zero-filled. Throws InternalError for channels outside 1..4 or negative sizes.
  Image(int width, int height, int channels);
  // As a new Image(width, height, channels), keeping the memory when it is large enough: a
  // frame loop that reuses its images does not page-fault megabytes of fresh memory per frame.
  void Reset(int width, int height, int channels);

  int Width() const { return width_; }
  int Height() const { return height_; }
  int Channels() const { return channels_; }
  bool Empty() const { return pixels_.empty(); }

  float& At(int x, int y, int channel) {
    return pixels_[(static_cast<size_t>(y) * width_ + x) * channels_ + channel];
  }
  float At(int x, int y, int channel) const {
    return pixels_[(static_cast<size_t>(y) * width_ + x) * channels_ + channel];
  }
  float* Row(int y) { return pixels_.data() + static_cast<size_t>(y) * width_ * channels_; }
  const float* Row(int y) const {
    return pixels_.data() + static_cast<size_t>(y) * width_ * channels_;
  }
  std::vector<float>& Pixels() { return pixels_; }
  const std::vector<float>& Pixels() const { return pixels_; }

 private:
  int width_ = 0;
  int height_ = 0;
  int channels_ = 0;
  std::vector<float> pixels_;
};

// How values are stored in a written file.
enum class PixelFormat { kUint8, kUint16, kHalf, kFloat };

// Images larger than this are refused from their header, before anything is decoded (photos,
// images read, cameras rendered): no camera sensor is larger (medium format reaches 102 MP),
// and a header claiming more is a decompression bomb or a scan or panorama to downscale.
constexpr double kMaxImageMegapixels = 128;
// Nor a side longer than this (JPEG's own limit): OpenImageIO reads some formats in chunks of
// rows allocated for the full width whatever the height (a 6-row BMP claiming 16.7 million
// columns, 100 MP, asked for 12.8 GB).
constexpr double kMaxImageSide = 65535;
inline bool OverPixelLimit(double width, double height) {
  return width * height > kMaxImageMegapixels * 1e6 || std::max(width, height) > kMaxImageSide;
}
// The limit width x height is over, as a phrase: "the 128 MP limit" or "the 65535 px side limit".
std::string PixelLimitName(double width, double height);

// What is wrong with a PNG or OpenEXR file's header, checked before a library reads it:
// chunks and attributes that run past the end of the file, and data windows over
// kMaxImageMegapixels, for which libpng and OpenEXR would allocate gigabytes. The problem as
// a phrase ("is corrupt or truncated: ..."), or nullopt (other formats always).
std::optional<std::string> ImageHeaderProblem(const std::filesystem::path& path);

// Reads any format OpenImageIO knows. Throws BadInputError (missing, unreadable, corrupt or
// truncated file, more than 4 channels, over kMaxImageMegapixels) naming the file.
Image ReadImage(const std::filesystem::path& path);

// How hard a lossless PNG is compressed: kFast (zlib level 1, OpenCV's imwrite default) for
// what the pipeline writes as it works; kSmall (level 6, OpenImageIO's default) for files
// kept for good, such as the committed example scenes. kFast is markedly faster to write for
// files only slightly larger.
enum class PngCompression { kFast, kSmall };

// Writes `image` in the format the extension names, integer formats rounding [0, 1] values
// (clamped). Throws InternalError if a value is NaN or Inf, BadInputError if the file
// cannot be written. EXR is written with lossless ZIP compression, PNG as `png` says.
void WriteImage(const std::filesystem::path& path, const Image& image, PixelFormat format,
                PngCompression png = PngCompression::kFast);

// sRGB transfer function (IEC 61966-2-1) on the color channels; alpha (channel 4, or 2 of a
// grey+alpha image) is left as it is.
float SrgbToLinear(float encoded);
float LinearToSrgb(float linear);
Image SrgbToLinear(const Image& encoded);
Image LinearToSrgb(const Image& linear);

}  // namespace parallax
