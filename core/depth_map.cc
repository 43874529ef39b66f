#include "core/depth_map.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <string>

#include <OpenImageIO/imageio.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/oiio_metadata.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

static_assert(std::endian::native == std::endian::little,
              "COLMAP's dense format is little-endian; a big-endian port must swap bytes");

// Index of the first value that is not a valid depth (finite and >= 0), or -1.
int64_t FindInvalidDepth(const std::vector<float>& values) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i]) || values[i] < 0) return static_cast<int64_t>(i);
  }
  return -1;
}

std::string DescribeInvalidDepth(const std::vector<float>& values, int64_t index) {
  return "depth value " + std::to_string(values[static_cast<size_t>(index)]) + " at index " +
         std::to_string(index) + " (depth must be finite and >= 0)";
}

// For readers: a bad value in a file is bad input.
void CheckReadDepth(const std::vector<float>& values, const fs::path& path) {
  const int64_t bad = FindInvalidDepth(values);
  if (bad >= 0) throw BadInputError(path.string() + ": " + DescribeInvalidDepth(values, bad));
}

// For writers: a bad value in memory is the caller's bug.
void CheckWrittenDepth(const DepthMap& depth, const fs::path& path) {
  const int64_t bad = FindInvalidDepth(depth.Values());
  if (bad >= 0) {
    throw InternalError("writing " + path.string() + ": " +
                        DescribeInvalidDepth(depth.Values(), bad));
  }
}

// Parses one "<number>&" field of the dense header starting at `position`.
int ParseHeaderField(const std::string& bytes, size_t& position, const fs::path& path,
                     const char* field) {
  const size_t end = bytes.find('&', position);
  int value = -1;
  if (end == std::string::npos || end - position > 10) {
    throw BadInputError(path.string() + ": malformed dense header (" + field + ")");
  }
  const auto result = std::from_chars(bytes.data() + position, bytes.data() + end, value);
  if (result.ec != std::errc() || result.ptr != bytes.data() + end || value <= 0) {
    throw BadInputError(path.string() + ": malformed dense header: " + field + " '" +
                        bytes.substr(position, end - position) + "'");
  }
  position = end + 1;
  return value;
}

}  // namespace

DepthMap::DepthMap(int width, int height) { Reset(width, height); }

void DepthMap::Reset(int width, int height) {
  if (width < 0 || height < 0) {
    throw InternalError("DepthMap: invalid size " + std::to_string(width) + "x" +
                        std::to_string(height));
  }
  width_ = width;
  height_ = height;
  values_.assign(static_cast<size_t>(width) * height, 0.0f);
}

std::optional<double> SampleDepth(const DepthMap& depth, const Eigen::Vector2d& pixel,
                                  double max_ratio) {
  if (!pixel.allFinite()) return std::nullopt;
  const double fx = pixel.x() - 0.5, fy = pixel.y() - 0.5;
  const double x0 = std::floor(fx), y0 = std::floor(fy);
  if (x0 >= 0 && y0 >= 0 && x0 + 1 < depth.Width() && y0 + 1 < depth.Height()) {
    const int x = static_cast<int>(x0), y = static_cast<int>(y0);
    const double d[4] = {depth.At(x, y), depth.At(x + 1, y), depth.At(x, y + 1),
                         depth.At(x + 1, y + 1)};
    const auto [low, high] = std::minmax_element(d, d + 4);
    if (*low > 0 && *high <= max_ratio * *low) {
      const double ax = fx - x0, ay = fy - y0;
      return 1 / ((1 - ay) * ((1 - ax) / d[0] + ax / d[1]) + ay * ((1 - ax) / d[2] + ax / d[3]));
    }
  }
  const double px = std::floor(pixel.x()), py = std::floor(pixel.y());
  if (px < 0 || py < 0 || px >= depth.Width() || py >= depth.Height()) return std::nullopt;
  const double nearest = depth.At(static_cast<int>(px), static_cast<int>(py));
  if (!(nearest > 0)) return std::nullopt;
  return nearest;
}

DepthMap ReadDepthExr(const fs::path& path) {
  auto input = OIIO::ImageInput::open(path.string());
  if (!input) throw BadInputError("cannot read depth " + path.string() + ": " + OIIO::geterror());
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.nchannels != 1) {
    throw BadInputError("depth " + path.string() + " has " + std::to_string(spec.nchannels) +
                        " channels; a depth map has one");
  }
  DepthMap depth(spec.width, spec.height);
  if (!input->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, depth.Values().data())) {
    throw BadInputError("depth " + path.string() + " is corrupt: " + input->geterror());
  }
  CheckReadDepth(depth.Values(), path);
  return depth;
}

std::vector<size_t> PixelsAtCentres(int grid_width, int grid_height, int width, int height) {
  std::vector<size_t> indices;
  indices.reserve(static_cast<size_t>(width) * static_cast<size_t>(height));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) indices.push_back(PixelAtCentre(grid_width, grid_height, width, height, x, y));
  }
  return indices;
}

size_t PixelAtCentre(int grid_width, int grid_height, int width, int height, int x, int y) {
  const int gx = std::min(grid_width - 1, static_cast<int>((x + 0.5) * grid_width / width));
  const int gy = std::min(grid_height - 1, static_cast<int>((y + 0.5) * grid_height / height));
  return static_cast<size_t>(gy) * static_cast<size_t>(grid_width) + static_cast<size_t>(gx);
}

DepthMap ReadDepthExrAt(const fs::path& path, int width, int height) {
  DepthMap depth = ReadDepthExr(path);
  // A working size of the photo: no larger, and each side scaled alike (to a pixel's rounding).
  const double scale = static_cast<double>(depth.Width()) / width;
  if (depth.Width() > width || depth.Height() > height || std::abs(scale * height - depth.Height()) > 1) {
    throw BadInputError("depth " + path.string() + " is " + std::to_string(depth.Width()) + "x" +
                        std::to_string(depth.Height()) + ": neither its photo's size (" + std::to_string(width) +
                        "x" + std::to_string(height) + ") nor a smaller one of its shape");
  }
  if (depth.Width() == width && depth.Height() == height) return depth;
  const std::vector<size_t> nearest = PixelsAtCentres(depth.Width(), depth.Height(), width, height);
  DepthMap full(width, height);
  for (size_t i = 0; i < nearest.size(); ++i) full.Values()[i] = depth.Values()[nearest[i]];
  return full;
}

void WriteDepthExr(const fs::path& path, const DepthMap& depth) {
  CheckWrittenDepth(depth, path);
  WriteAtomically(path, [&](const fs::path& temporary) {
    auto output = OIIO::ImageOutput::create("exr");
    OIIO::ImageSpec spec(depth.Width(), depth.Height(), 1, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"Z"};
    spec.attribute("compression", "zip");
    SetReproducibleMetadata(spec);
    if (!output || !output->open(temporary.string(), spec) ||
        !output->write_image(OIIO::TypeDesc::FLOAT, depth.Values().data()) || !output->close()) {
      throw BadInputError("cannot write " + path.string() +
                          (output ? ": " + output->geterror() : std::string()));
    }
  });
}

DenseArray ReadColmapArray(const fs::path& path) {
  const std::string bytes = ReadFileBytes(path);
  size_t position = 0;
  DenseArray array;
  array.width = ParseHeaderField(bytes, position, path, "width");
  array.height = ParseHeaderField(bytes, position, path, "height");
  array.channels = ParseHeaderField(bytes, position, path, "channels");
  // Sizes are checked against the data actually present, in 64-bit, before any allocation.
  const uint64_t count = static_cast<uint64_t>(array.width) * static_cast<uint64_t>(array.height) *
                         static_cast<uint64_t>(array.channels);
  const uint64_t available = bytes.size() - position;
  if (count * sizeof(float) != available) {
    throw BadInputError(path.string() + ": header says " + std::to_string(array.width) + "x" +
                        std::to_string(array.height) + "x" + std::to_string(array.channels) +
                        " (" + std::to_string(count * sizeof(float)) + " bytes of data), file has " +
                        std::to_string(available));
  }
  array.values.resize(count);
  std::memcpy(array.values.data(), bytes.data() + position, available);
  for (const float value : array.values) {
    if (!std::isfinite(value)) throw BadInputError(path.string() + ": NaN or Inf in the data");
  }
  return array;
}

void WriteColmapArray(const fs::path& path, const DenseArray& array) {
  const size_t count = static_cast<size_t>(array.width) * array.height * array.channels;
  if (array.width <= 0 || array.height <= 0 || array.channels <= 0 || array.values.size() != count) {
    throw InternalError("WriteColmapArray " + path.string() + ": size does not match data");
  }
  for (const float value : array.values) {
    if (!std::isfinite(value)) {
      throw InternalError("WriteColmapArray " + path.string() + ": NaN or Inf in data");
    }
  }
  std::string bytes = std::to_string(array.width) + "&" + std::to_string(array.height) + "&" +
                      std::to_string(array.channels) + "&";
  const size_t header_size = bytes.size();
  bytes.resize(header_size + count * sizeof(float));
  std::memcpy(bytes.data() + header_size, array.values.data(), count * sizeof(float));
  WriteFileAtomically(path, bytes);
}

DepthMap ReadColmapDepth(const fs::path& path) {
  DenseArray array = ReadColmapArray(path);
  if (array.channels != 1) {
    throw BadInputError(path.string() + ": depth map has " + std::to_string(array.channels) +
                        " channels; expected 1");
  }
  CheckReadDepth(array.values, path);
  DepthMap depth(array.width, array.height);
  depth.Values() = std::move(array.values);
  return depth;
}

void WriteColmapDepth(const fs::path& path, const DepthMap& depth) {
  CheckWrittenDepth(depth, path);
  WriteColmapArray(path, DenseArray{depth.Width(), depth.Height(), 1, depth.Values()});
}

}  // namespace parallax
