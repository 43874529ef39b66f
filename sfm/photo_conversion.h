#pragma once
// Photos COLMAP cannot read as they are (16-bit, grayscale, an alpha channel, an EXIF
// orientation, a file whose content is not what its extension says, TIFF), rewritten as the
// 8-bit RGB, upright file its name promises.
#include <filesystem>
#include <memory>
#include <string>

#include <OpenImageIO/imageio.h>

namespace parallax {

// Opens `path` with the reader its content calls for (PNG, JPEG, TIFF and BMP recognised by
// their first bytes), whatever its name says: OpenImageIO's own fallback for a misnamed file
// failed now and then with several files opened at once, and other formats are never handed
// to a reader (a 164-byte EXR header found by fuzzing makes OpenEXR take 2 GB). Null when it
// is none of these or the reader refuses it, with `error` saying why ("is not ...").
std::unique_ptr<OIIO::ImageInput> OpenPhoto(const std::filesystem::path& path, std::string& error);

// Writes `from` to `to` (atomically) as 8-bit RGB in the format `to`'s extension names,
// turned upright as its EXIF orientation says, with the rest of its metadata. Grey is
// replicated, alpha dropped; the values are not colour-converted. Throws BadInputError naming
// the file when it cannot be read or written.
void WriteReadablePhoto(const std::filesystem::path& from, const std::filesystem::path& to);

}  // namespace parallax
