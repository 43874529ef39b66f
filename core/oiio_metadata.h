#pragma once
// Internal to core: metadata for files that must be byte-for-byte reproducible.
#include <OpenImageIO/imagebuf.h>

namespace parallax {

// OpenImageIO stamps EXR files with the current date and PNG/TIFF files with its version;
// a fixed DateTime and an empty Software tag make the same pixels give the same bytes.
inline void SetReproducibleMetadata(OIIO::ImageSpec& spec) {
  spec.attribute("DateTime", "1970:01:01 00:00:00");
  spec.attribute("Software", "parallax");
}

}  // namespace parallax
