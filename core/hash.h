#pragma once
// Content hashes for the stage cache: FNV-1a, 64-bit. Not cryptographic; it detects changed
// inputs and options, which is all the cache needs.
#include <cstdint>
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

}  // namespace parallax
