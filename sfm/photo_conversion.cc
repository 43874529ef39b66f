#include "sfm/photo_conversion.h"

#include <fstream>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image.h"

namespace parallax {
namespace fs = std::filesystem;

namespace {

// The format the first bytes of a file announce, or "" when they are none of these.
std::string FormatFromSignature(const fs::path& path) {
  char bytes[8] = {};
  std::ifstream(path, std::ios::binary).read(bytes, sizeof bytes);
  const std::string start(bytes, sizeof bytes);
  if (start.starts_with("\x89PNG\r\n\x1a\n")) return "png";
  if (start.starts_with("\xff\xd8\xff")) return "jpeg";
  if (start.starts_with(std::string("II*\0", 4)) || start.starts_with(std::string("MM\0*", 4))) return "tiff";
  if (start.starts_with("BM")) return "bmp";
  return "";
}

}  // namespace

std::unique_ptr<OIIO::ImageInput> OpenPhoto(const fs::path& path, std::string& error) {
  const std::string format = FormatFromSignature(path);
  if (format.empty()) {
    error = "is not an image in a photo format (PNG, JPEG, TIFF or BMP)";
    return nullptr;
  }
  if (const auto problem = ImageHeaderProblem(path)) {
    error = *problem;
    return nullptr;
  }
  // Keep colour as stored where alpha is 0: OpenImageIO would otherwise premultiply it.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto input = OIIO::ImageInput::create(format);
  OIIO::ImageSpec spec;
  if (!input || !input->open(path.string(), spec, config)) {
    error = "is not an image OpenImageIO can read (" + (input ? input->geterror() : OIIO::geterror()) + ")";
    return nullptr;
  }
  return input;
}

void WriteReadablePhoto(const fs::path& from, const fs::path& to) {
  std::string error;
  const auto input = OpenPhoto(from, error);
  if (!input) throw BadInputError("cannot convert " + from.string() + ": it " + error);
  OIIO::ImageSpec spec = input->spec();
  spec.set_format(OIIO::TypeDesc::UINT8);
  OIIO::ImageBuf source(spec);
  if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, source.localpixels())) {
    throw BadInputError("cannot convert " + from.string() + ": " + input->geterror());
  }
  const OIIO::ImageBuf upright = OIIO::ImageBufAlgo::reorient(source);
  const int grey = upright.nchannels() < 3;
  const int channel_order[3] = {0, grey ? 0 : 1, grey ? 0 : 2};
  const std::string channel_names[3] = {"R", "G", "B"};
  OIIO::ImageBuf rgb;
  if (!OIIO::ImageBufAlgo::channels(rgb, upright, 3, channel_order, {}, channel_names)) {
    throw BadInputError("cannot convert " + from.string() + ": " + rgb.geterror());
  }
  OIIO::ImageSpec& written = rgb.specmod();
  written.attribute("Orientation", 1);
  written.erase_attribute("oiio:BitsPerSample");
  written.erase_attribute("oiio:ColorSpace");
  const auto output = OIIO::ImageOutput::create(to.filename().string());
  if (!output) throw BadInputError("cannot write " + to.string() + ": " + OIIO::geterror());
  const std::string format = output->format_name();
  if (format == "jpeg") {
    written.attribute("Compression", "jpeg:95");
    written.attribute("jpeg:subsampling", "4:4:4");  // Full-resolution colour for the texture.
  }
  if (format == "tiff") written.attribute("Compression", "lzw");
  WriteAtomically(to, [&](const fs::path& temporary) {
    if (!rgb.write(temporary.string(), OIIO::TypeDesc::UINT8, format)) {
      throw BadInputError("cannot write " + to.string() + ": " + rgb.geterror());
    }
  });
}

}  // namespace parallax
