#include "core/hash.h"

#include <algorithm>
#include <cstdio>
#include <vector>

#include "core/atomic_file.h"

namespace parallax {

std::string Hasher::Hex() const {
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(state_));
  return hex;
}

uint64_t HashFolder(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  Hasher hasher;
  for (const auto& file : files) hasher.Add(file.filename().string()).Add(ReadFileBytes(file));
  return hasher.Value();
}

}  // namespace parallax
