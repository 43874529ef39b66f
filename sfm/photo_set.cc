#include "sfm/photo_set.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <tuple>

#include <OpenImageIO/imageio.h>
#include <tbb/parallel_for.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hash.h"
#include "core/image.h"
#include "sfm/photo_conversion.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// COLMAP's default focal length when nothing better is known.
constexpr double kDefaultFocalFactor = 1.2;

// The formats photos are taken in, all of which the conversion can write 8-bit.
bool IsPhotoFormat(const std::string& format) {
  return format == "jpeg" || format == "png" || format == "tiff" || format == "bmp";
}

// Why COLMAP (through FreeImage) cannot be trusted to read the file as it is: it reads
// 8-bit JPEG and PNG, but not 16-bit TIFF; it ignores EXIF orientation; the depth stage wants
// three channels. Empty when the file is fine as it is.
std::string ConversionNeeded(const OIIO::ImageSpec& spec, const std::string& format,
                             const fs::path& path, const std::string& named_format) {
  std::vector<std::string> reasons;
  if (format != named_format) reasons.push_back("a " + format + " file named " + path.extension().string());
  if (format == "tiff" || format == "bmp") reasons.push_back(format);
  if (spec.format != OIIO::TypeDesc::UINT8) reasons.push_back(std::string(spec.format.c_str()));
  if (spec.nchannels < 3) reasons.push_back("grayscale");
  if (spec.nchannels == 2 || spec.nchannels == 4) reasons.push_back("alpha channel");
  const int orientation = spec.get_int_attribute("Orientation", 1);
  if (orientation != 1) reasons.push_back("EXIF orientation " + std::to_string(orientation));
  std::string text;
  for (const std::string& reason : reasons) text += (text.empty() ? "" : ", ") + reason;
  return text;
}

// The non-finite values among `pixels` and what the 8-bit conversion makes of them (NaN and
// -Inf black, +Inf white, as OpenImageIO converts them); empty when every value is finite.
std::string DescribeNonFinite(const std::vector<float>& pixels) {
  size_t nan = 0, positive = 0, negative = 0;
  for (const float value : pixels) {
    if (std::isnan(value)) {
      ++nan;
    } else if (std::isinf(value)) {
      ++(value > 0 ? positive : negative);
    }
  }
  if (nan + positive + negative == 0) return "";
  return std::to_string(nan) + " NaN and " + std::to_string(negative) + " -Inf values converted to 0 (black), " +
         std::to_string(positive) + " +Inf values to 255 (white)";
}

}  // namespace

// Decodes the whole file: a truncated image often has an intact header.
std::optional<std::string> CheckPhoto(const fs::path& path, Photo& photo) {
  std::string bytes;
  try {
    bytes = ReadFileBytes(path);
  } catch (const BadInputError& error) {
    return "cannot be read";
  }
  if (bytes.empty()) return "is empty (0 bytes)";
  photo.content_hash = Hasher().Add(bytes).Value();
  std::string error;
  const auto input = OpenPhoto(path, error);
  if (!input) return error;
  const OIIO::ImageSpec& spec = input->spec();
  const std::string format = input->format_name();
  const auto named = OIIO::ImageOutput::create(path.filename().string());
  if (!named || !IsPhotoFormat(named->format_name())) {
    return "is a " + format + " image without a photo file extension (.jpg, .png, .tif or .bmp)";
  }
  photo.conversion = ConversionNeeded(spec, format, path, named->format_name());
  const bool turned = spec.get_int_attribute("Orientation", 1) >= 5;  // 90 or 270 degrees.
  photo.width = turned ? spec.height : spec.width;
  photo.height = turned ? spec.width : spec.height;
  if (spec.width < 16 || spec.height < 16) return "is too small to match (under 16 px)";
  const double megapixels = static_cast<double>(spec.width) * static_cast<double>(spec.height) / 1e6;
  if (OverPixelLimit(spec.width, spec.height)) {
    char size[64];
    std::snprintf(size, sizeof size, "is %dx%d (%.0f MP), over ", spec.width, spec.height, megapixels);
    return size + PixelLimitName(spec.width, spec.height) +
           " (a decompression bomb, or a scan or panorama to downscale first); not decoded";
  }
  const std::string make = spec.get_string_attribute("Make");
  const std::string model = spec.get_string_attribute("Model");
  photo.exif_camera = make + (make.empty() || model.empty() ? "" : " ") + model;
  const float focal_35mm = spec.get_float_attribute("Exif:FocalLengthIn35mmFilm", 0.0f);
  if (focal_35mm > 0) {
    photo.exif_focal_px = static_cast<double>(focal_35mm) / 36.0 * std::max(spec.width, spec.height);
  }
  input->geterror();  // Cleared: only what decoding says counts below.
  const size_t values = static_cast<size_t>(spec.width) * static_cast<size_t>(spec.height) *
                        static_cast<size_t>(spec.nchannels);
  bool decoded = false;
  if (spec.format.is_floating_point()) {
    std::vector<float> pixels(values);
    decoded = input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data());
    if (decoded) photo.non_finite = DescribeNonFinite(pixels);
  } else {
    std::vector<unsigned char> pixels(values);
    decoded = input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, pixels.data());
  }
  const std::string message = input->geterror();
  if (!decoded || !message.empty()) return "is corrupt or truncated (" + message + ")";
  return std::nullopt;
}


std::vector<std::vector<size_t>> PhotoSet::CameraGroups() const {
  using Key = std::tuple<int, int, std::optional<double>, std::string>;
  std::map<Key, size_t> group_of_key;
  std::vector<std::vector<size_t>> groups;
  for (size_t i = 0; i < photos.size(); ++i) {
    const Photo& photo = photos[i];
    const Key key{photo.width, photo.height, photo.exif_focal_px, photo.exif_camera};
    const auto [group, added] = group_of_key.emplace(key, groups.size());
    if (added) groups.emplace_back();
    groups[group->second].push_back(i);
  }
  return groups;
}

double PhotoSet::FocalPrior(const Photo& photo) const {
  return photo.exif_focal_px.value_or(kDefaultFocalFactor * std::max(photo.width, photo.height));
}

bool PhotoSet::NeedsConversion() const {
  return std::any_of(photos.begin(), photos.end(),
                     [](const Photo& photo) { return !photo.conversion.empty(); });
}

uint64_t PhotoSet::ContentHash() const {
  Hasher hasher;
  for (const Photo& photo : photos) hasher.Add(photo.name).Add(photo.content_hash);
  return hasher.Value();
}

PhotoSet ScanPhotos(const fs::path& dir) {
  if (!fs::exists(dir)) throw BadInputError("photo folder " + dir.string() + " does not exist");
  if (!fs::is_directory(dir)) throw BadInputError(dir.string() + " is not a folder");
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with(".") || entry.is_directory()) continue;
    names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  if (names.empty()) throw BadInputError("photo folder " + dir.string() + " is empty");

  std::vector<Photo> candidates(names.size());
  std::vector<std::optional<std::string>> problems(names.size());
  tbb::parallel_for(size_t{0}, names.size(), [&](size_t i) {
    candidates[i].name = names[i];
    problems[i] = CheckPhoto(dir / names[i], candidates[i]);
  });
  PhotoSet set;
  std::map<uint64_t, std::string> first_with_content;
  for (size_t i = 0; i < names.size(); ++i) {
    if (problems[i]) {
      set.skipped.push_back({names[i], *problems[i]});
      continue;
    }
    // A copy adds no view: SfM would match it to its original with no baseline.
    const auto [first, unique] = first_with_content.emplace(candidates[i].content_hash, names[i]);
    if (!unique) {
      set.skipped.push_back({names[i], "is an identical copy of " + first->second});
      continue;
    }
    set.photos.push_back(std::move(candidates[i]));
  }
  if (set.photos.size() < 2) {
    std::string message = "photo folder " + dir.string() + " has " +
                          std::to_string(set.photos.size()) +
                          " readable image(s); structure from motion needs at least 2";
    for (const SkippedFile& file : set.skipped) message += "\n  " + file.name + " " + file.reason;
    throw BadInputError(message);
  }
  return set;
}

}  // namespace parallax
