#include "sfm/quality_settings.h"

#include "core/error.h"

namespace parallax {

QualitySettings SettingsFor(Quality quality) {
  switch (quality) {
    case Quality::kFast: return {1024, 2048, false};
    case Quality::kBalanced: return {2000, 4096, false};
    case Quality::kBest: return {3200, 8192, true};
  }
  throw InternalError("unknown quality");
}

}  // namespace parallax
