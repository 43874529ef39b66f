#pragma once
// Where the tests find the repository's files and the built executable. Defined in one
// translation unit, so that the other tests compile the same wherever the repository is
// cloned (a compiler cache then serves them from another clone).
#include <filesystem>
#include <string>

namespace parallax {

// The repository's root folder.
std::filesystem::path SourceDir();

// The real photos beside the repository (../shared/datasets, docs/design.md); tests that use
// them skip where the folder is absent.
std::filesystem::path SharedDatasets();

// The built `parallax` executable.
std::string ParallaxExecutable();

}  // namespace parallax
