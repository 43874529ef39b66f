#include "tests/test_paths.h"

namespace parallax {

std::filesystem::path SourceDir() { return PARALLAX_SOURCE_DIR; }

std::filesystem::path SharedDatasets() { return SourceDir().parent_path() / "shared" / "datasets"; }

std::string ParallaxExecutable() { return PARALLAX_EXECUTABLE; }

}  // namespace parallax
