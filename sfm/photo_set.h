#pragma once
// The photos `reconstruct` starts from: which files in the folder are usable images, their
// sizes, EXIF focal lengths and content hashes; and which files were skipped, and why.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace parallax {

struct Photo {
  std::string name;  // File name inside the folder.
  int width = 0;
  int height = 0;
  std::optional<double> exif_focal_px;  // From the 35 mm-equivalent focal length, if present.
  std::string exif_camera;              // EXIF Make and Model, "" when absent.
  uint64_t content_hash = 0;
  // Why COLMAP cannot read the file as it is ("16-bit", "grayscale", ...), so that it is
  // converted (sfm/photo_conversion.h); empty: the file is used as it is.
  std::string conversion;
  // Non-finite pixels of a floating-point photo and what the conversion makes of them; empty
  // when there are none.
  std::string non_finite;
};

struct SkippedFile {
  std::string name;
  std::string reason;
};

struct PhotoSet {
  std::vector<Photo> photos;  // Sorted by name (COLMAP's order).
  std::vector<SkippedFile> skipped;

  // The photos one camera can serve, as indices into `photos` in name order: those of one
  // size, EXIF focal length and EXIF camera. A shared camera is better constrained than one
  // per photo (the 12 small example photos do not register at all with a camera each).
  std::vector<std::vector<size_t>> CameraGroups() const;
  bool SharesOneCamera() const { return CameraGroups().size() == 1; }
  // The focal length SfM starts from: EXIF when present, else COLMAP's default 1.2 * max(w, h).
  double FocalPrior(const Photo& photo) const;
  // Hash of every name and content: changes when any photo changes.
  uint64_t ContentHash() const;
  // True when any photo must be converted before COLMAP reads it.
  bool NeedsConversion() const;
};

// Checks one photo as ScanPhotos does, decoding it whole: fills `photo`'s size, EXIF fields,
// content hash, conversion and non-finite pixels (not its name). Returns why it cannot be used,
// if it cannot: a decoder's warning counts (libjpeg decodes a truncated JPEG with a grey lower
// half and only warns).
std::optional<std::string> CheckPhoto(const std::filesystem::path& path, Photo& photo);

// Scans `dir` (not recursively; hidden files ignored) and decodes every file to check it.
// Unreadable, corrupt or non-image files, formats other than JPEG, PNG, TIFF and BMP, images
// over kMaxImageMegapixels (core/image.h) and identical copies of an earlier photo (by name)
// are skipped with their reason. Sizes are those of the photo turned upright (EXIF
// orientation). Throws BadInputError
// if the folder does not exist, is not a folder, or holds fewer than 2 readable images (the
// message lists the skipped files).
PhotoSet ScanPhotos(const std::filesystem::path& dir);

}  // namespace parallax
