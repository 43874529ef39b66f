// Every input of the committed fuzz corpus (seeds, and each crasher the fuzzers found, fixed
// since) replayed through its target: the readers must refuse bad bytes with BadInputError
// and nothing else. Runs in CI without clang; scripts/fuzz searches for new inputs.
#include <cstdlib>

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "fuzz/fuzz_targets.h"
#include "tests/test_paths.h"

namespace parallax::fuzz {
namespace {

namespace fs = std::filesystem;

const fs::path kCorpus = SourceDir() / "fuzz" / "corpus";

TEST(FuzzCorpus, EveryTargetHasSeeds) {
  // PARALLAX_WRITE_SEEDS=<dir> regenerates the seed files (after a format change).
  if (const char* dir = std::getenv("PARALLAX_WRITE_SEEDS")) WriteSeeds(dir);
  for (const Target& target : Targets()) {
    EXPECT_TRUE(fs::is_directory(kCorpus / target.name)) << target.name;
  }
}

TEST(FuzzCorpus, EveryInputIsReadOrRefusedCleanly) {
  size_t inputs = 0;
  for (const Target& target : Targets()) {
    if (!fs::is_directory(kCorpus / target.name)) continue;
    for (const auto& entry : fs::directory_iterator(kCorpus / target.name)) {
      SCOPED_TRACE(entry.path().string());
      const std::string bytes = ReadFileBytes(entry.path());
      EXPECT_NO_THROW(target.run(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()));
      ++inputs;
    }
  }
  EXPECT_GE(inputs, Targets().size());
}

}  // namespace
}  // namespace parallax::fuzz
