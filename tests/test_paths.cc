#include "tests/test_paths.h"

namespace parallax {

std::filesystem::path SourceDir() { return PARALLAX_SOURCE_DIR; }

std::string ParallaxExecutable() { return PARALLAX_EXECUTABLE; }

}  // namespace parallax
