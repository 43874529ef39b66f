#pragma once
// Fuzz targets for every reader of untrusted files: COLMAP sparse models (binary and text),
// COLMAP dense arrays, scene JSON, PLY, OBJ, images (as photos and as read) and the camera
// files `render` takes. Each takes arbitrary bytes, hands them to the
// reader as the file it reads, and accepts only two outcomes: a result, or BadInputError.
// Anything else (a crash, a sanitizer report, another exception, a huge allocation) is a bug.
//
// The same targets run under libFuzzer (scripts/fuzz, clang) and, over the committed corpus
// in fuzz/corpus/<target>/, as a regression test in CI (tests/fuzz).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace parallax::fuzz {

using TargetFunction = void (*)(const uint8_t* data, size_t size);

struct Target {
  std::string name;  // Also the corpus folder name.
  TargetFunction run;
};

const std::vector<Target>& Targets();
const Target& FindTarget(const std::string& name);

// Writes the seed inputs of every target into <dir>/<target>/ (used once to create the
// committed corpus; kept so it can be regenerated when a format changes).
void WriteSeeds(const std::filesystem::path& dir);

}  // namespace parallax::fuzz
