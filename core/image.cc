#include "core/image.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <string>

#include <OpenImageIO/imageio.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/oiio_metadata.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

OIIO::TypeDesc ToTypeDesc(PixelFormat format) {
  switch (format) {
    case PixelFormat::kUint8: return OIIO::TypeDesc::UINT8;
    case PixelFormat::kUint16: return OIIO::TypeDesc::UINT16;
    case PixelFormat::kHalf: return OIIO::TypeDesc::HALF;
    case PixelFormat::kFloat: return OIIO::TypeDesc::FLOAT;
  }
  throw InternalError("unknown pixel format");
}

bool HasAlpha(const Image& image) { return image.Channels() == 2 || image.Channels() == 4; }

Image MapColorChannels(const Image& input, float (*function)(float)) {
  Image output = input;
  const int color_channels = HasAlpha(input) ? input.Channels() - 1 : input.Channels();
  std::vector<float>& pixels = output.Pixels();
  for (size_t i = 0; i < pixels.size(); ++i) {
    if (static_cast<int>(i % static_cast<size_t>(input.Channels())) < color_channels) {
      pixels[i] = function(pixels[i]);
    }
  }
  return output;
}

// The first `size` bytes of a file, or fewer if it is shorter.
std::string FileStart(const fs::path& path, size_t size) {
  std::ifstream file(path, std::ios::binary);
  std::string bytes(size, '\0');
  file.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  bytes.resize(static_cast<size_t>(file.gcount()));
  return bytes;
}

// Every PNG chunk must fit in the file: found by fuzzing, a 169-byte PNG whose text chunk
// claims more makes libpng (through OpenImageIO) take 2 GB.
std::optional<std::string> PngChunkProblem(const std::string& bytes, int64_t file_size) {
  size_t at = 8;
  while (at + 8 <= bytes.size()) {
    const auto byte = [&](size_t i) { return static_cast<uint32_t>(static_cast<unsigned char>(bytes[at + i])); };
    const uint32_t length = byte(0) << 24 | byte(1) << 16 | byte(2) << 8 | byte(3);
    if (static_cast<int64_t>(at) + 12 + length > file_size) {
      return "is corrupt or truncated: its chunk '" + bytes.substr(at + 4, 4) + "' runs past the end of the file";
    }
    if (bytes.compare(at + 4, 4, "IEND") == 0) return std::nullopt;
    at += 12 + static_cast<size_t>(length);
  }
  return std::nullopt;
}

// What an OpenEXR file's header claims: found by fuzzing, a 164-byte header whose attribute
// sizes run past the file makes OpenEXR take 2 GB. Refuses an attribute larger than the file,
// a data window over kMaxImageMegapixels, or a multi-part or deep file (parallax writes
// neither).
std::optional<std::string> ExrHeaderProblem(const std::string& bytes, int64_t file_size) {
  if (static_cast<unsigned char>(bytes[5]) & 0x18) return "is a deep or multi-part OpenEXR file; parallax reads single-part images";
  const auto read_int = [&](size_t at) {
    int32_t value;
    std::memcpy(&value, bytes.data() + at, sizeof value);
    return value;
  };
  size_t at = 8;
  while (at < bytes.size() && bytes[at] != '\0') {
    const size_t name_end = bytes.find('\0', at);
    const size_t type_end = name_end == std::string::npos ? name_end : bytes.find('\0', name_end + 1);
    if (type_end == std::string::npos || type_end + 5 > bytes.size()) return std::nullopt;  // Beyond what was read.
    const std::string name = bytes.substr(at, name_end - at);
    const int32_t size = read_int(type_end + 1);
    at = type_end + 5;
    if (size < 0 || static_cast<int64_t>(at) + size > file_size) {
      return "is corrupt or truncated: its header attribute '" + name + "' runs past the end of the file";
    }
    if (name == "dataWindow" && size == 16 && at + 16 <= bytes.size()) {
      const double width = static_cast<double>(read_int(at + 8)) - read_int(at) + 1;
      const double height = static_cast<double>(read_int(at + 12)) - read_int(at + 4) + 1;
      if (!(width >= 1 && height >= 1)) return "is corrupt: its data window is empty";
      if (OverPixelLimit(width, height)) {
        return "claims " + std::to_string(static_cast<int64_t>(width)) + "x" +
               std::to_string(static_cast<int64_t>(height)) + " pixels, over " + PixelLimitName(width, height) +
               "; not decoded";
      }
    }
    at += static_cast<size_t>(size);
  }
  return std::nullopt;
}

}  // namespace

Image::Image(int width, int height, int channels) { Reset(width, height, channels); }

void Image::Reset(int width, int height, int channels) {
  if (width < 0 || height < 0 || channels < 1 || channels > 4) {
    throw InternalError("Image: invalid size " + std::to_string(width) + "x" +
                        std::to_string(height) + "x" + std::to_string(channels));
  }
  width_ = width;
  height_ = height;
  channels_ = channels;
  pixels_.assign(static_cast<size_t>(width) * height * channels, 0.0f);
}

std::optional<std::string> ImageHeaderProblem(const fs::path& path) {
  std::error_code error;
  const auto file_size = static_cast<int64_t>(fs::file_size(path, error));
  if (error) return std::nullopt;  // The reader says what is wrong.
  const std::string signature = FileStart(path, 8);
  const bool png = signature == std::string("\x89PNG\r\n\x1a\n", 8);
  const bool exr = signature.size() == 8 && signature.compare(0, 4, "\x76\x2f\x31\x01") == 0;
  if (!png && !exr) return std::nullopt;
  // The first MiB holds every header worth walking; past it, the reader checks on its own.
  constexpr int64_t kMaxHeaderBytes = 1 << 20;
  const std::string bytes = FileStart(path, static_cast<size_t>(std::min(file_size, kMaxHeaderBytes)));
  return png ? PngChunkProblem(bytes, file_size) : ExrHeaderProblem(bytes, file_size);
}

std::string PixelLimitName(double width, double height) {
  if (width * height > kMaxImageMegapixels * 1e6) {
    return "the " + std::to_string(static_cast<int>(kMaxImageMegapixels)) + " MP limit";
  }
  return "the " + std::to_string(static_cast<int>(kMaxImageSide)) + " px side limit";
}

Image ReadImage(const fs::path& path) {
  // Keep alpha as stored: OpenImageIO would otherwise premultiply PNG color by alpha.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  if (const auto problem = ImageHeaderProblem(path)) throw BadInputError("image " + path.string() + " " + *problem);
  auto input = OIIO::ImageInput::open(path.string(), &config);
  if (!input) {
    throw BadInputError("cannot read image " + path.string() + ": " + OIIO::geterror());
  }
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.nchannels < 1 || spec.nchannels > 4) {
    throw BadInputError("image " + path.string() + " has " + std::to_string(spec.nchannels) +
                        " channels; parallax reads 1 to 4");
  }
  if (spec.depth != 1) {
    throw BadInputError("image " + path.string() + " is a volume; parallax reads 2D images");
  }
  if (OverPixelLimit(spec.width, spec.height)) {
    throw BadInputError("image " + path.string() + " is " + std::to_string(spec.width) + "x" +
                        std::to_string(spec.height) + ", over " + PixelLimitName(spec.width, spec.height) +
                        "; not decoded");
  }
  Image image(spec.width, spec.height, spec.nchannels);
  // Integer formats are scaled to [0, 1] by OpenImageIO when read as float.
  if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT,
                         image.Pixels().data())) {
    throw BadInputError("image " + path.string() + " is corrupt or truncated: " +
                        input->geterror());
  }
  for (const float value : image.Pixels()) {
    if (!std::isfinite(value)) {
      throw BadInputError("image " + path.string() + " contains NaN or Inf values");
    }
  }
  return image;
}

void WriteImage(const fs::path& path, const Image& image, PixelFormat format,
                PngCompression png) {
  if (image.Empty()) throw InternalError("WriteImage " + path.string() + ": empty image");
  for (const float value : image.Pixels()) {
    if (!std::isfinite(value)) {
      throw InternalError("WriteImage " + path.string() + ": NaN or Inf in the image");
    }
  }
  WriteAtomically(path, [&](const fs::path& temporary) {
    // The plugin is chosen from the final name's extension; the data goes to the temporary.
    auto output = OIIO::ImageOutput::create(path.string());
    if (!output) {
      throw BadInputError("cannot write " + path.string() + ": " + OIIO::geterror());
    }
    OIIO::ImageSpec spec(image.Width(), image.Height(), image.Channels(), ToTypeDesc(format));
    if (image.Channels() == 1) spec.channelnames = {"Y"};
    if (HasAlpha(image)) {
      spec.alpha_channel = image.Channels() - 1;
      spec.attribute("oiio:UnassociatedAlpha", 1);  // Color is not premultiplied.
    }
    spec.attribute("compression", "zip");
    spec.attribute("png:compressionLevel", png == PngCompression::kFast ? 1 : 6);
    SetReproducibleMetadata(spec);
    if (!output->open(temporary.string(), spec) ||
        !output->write_image(OIIO::TypeDesc::FLOAT, image.Pixels().data()) ||
        !output->close()) {
      throw BadInputError("cannot write " + path.string() + ": " + output->geterror());
    }
  });
}

float SrgbToLinear(float encoded) {
  return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

float LinearToSrgb(float linear) {
  return linear <= 0.0031308f ? linear * 12.92f
                              : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

Image SrgbToLinear(const Image& encoded) {
  return MapColorChannels(encoded, static_cast<float (*)(float)>(&SrgbToLinear));
}

Image LinearToSrgb(const Image& linear) {
  return MapColorChannels(linear, static_cast<float (*)(float)>(&LinearToSrgb));
}

}  // namespace parallax
