#pragma once
// Content hashes for the stage cache: FNV-1a, 64-bit. Not cryptographic; it detects changed
// inputs and options, which is all the cache needs.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace parallax {

class Hasher {
 public:
  Hasher& Add(std::string_view bytes) {
    for (const char c : bytes) {
      state_ ^= static_cast<uint8_t>(c);
      state_ *= 0x100000001b3ull;
    }
    // A separator, so ("ab", "c") and ("a", "bc") differ.
    state_ ^= 0xff;
    state_ *= 0x100000001b3ull;
    return *this;
  }
  Hasher& Add(uint64_t value) { return Add(std::to_string(value)); }
  uint64_t Value() const { return state_; }
  // 16 hex digits.
  std::string Hex() const;

 private:
  uint64_t state_ = 0xcbf29ce484222325ull;
};

// The names and contents of the regular files in `dir`, in name order. Throws BadInputError
// naming a file that cannot be read.
uint64_t HashFolder(const std::filesystem::path& dir);

// Murmur3's 64-bit finaliser: every input bit reaches every output bit. Deterministic
// pseudo-random numbers keyed by coordinates (procedural textures, PatchMatch proposals)
// start from it, so results never depend on thread scheduling.
inline uint64_t MixBits(uint64_t h) {
  h ^= h >> 33;
  h *= 0xFF51AFD7ED558CCDull;
  h ^= h >> 33;
  h *= 0xC4CEB9FE1A85EC53ull;
  h ^= h >> 33;
  return h;
}

// The top 24 bits of a mixed hash as a float in [0, 1).
inline float UnitFloat(uint64_t mixed) {
  return static_cast<float>(mixed >> 40) / static_cast<float>(1ull << 24);
}

}  // namespace parallax
