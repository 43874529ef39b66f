#include "core/hash.h"

#include <cstdio>

namespace parallax {

std::string Hasher::Hex() const {
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(state_));
  return hex;
}

}  // namespace parallax
