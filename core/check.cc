#include "core/check.h"

#include <cstdio>
#include <string>

#include "core/error.h"

namespace parallax {

void RequireOption(bool ok, std::string_view field, double value, std::string_view expected) {
  if (ok) return;
  char number[32];
  std::snprintf(number, sizeof(number), "%.9g", value);
  throw UsageError(std::string(field) + " = " + number + ": expected " + std::string(expected));
}

}  // namespace parallax
