#include "viewer/frame.h"

#include <cmath>
#include <string>

#include "core/check.h"

namespace parallax {

void FrameSettings::Check() const {
  RequireOption(shadow_map_size >= 64 && shadow_map_size <= 8192, "FrameSettings.shadow_map_size", shadow_map_size,
                "[64, 8192]");
  RequireOption(pcf_radius >= 0 && pcf_radius <= 4, "FrameSettings.pcf_radius", pcf_radius, "[0, 4]");
  RequireOption(projective_views >= 1 && projective_views <= kMaxProjectors, "FrameSettings.projective_views",
                projective_views, "[1, " + std::to_string(kMaxProjectors) + "]");
  RequireOption(point_size_px > 0, "FrameSettings.point_size_px", point_size_px, "> 0");
  RequireOption(std::isfinite(exposure_stops), "FrameSettings.exposure_stops", exposure_stops, "finite");
  RequireOption(white >= 1 && std::isfinite(white), "FrameSettings.white", white, ">= 1 and finite");
  RequireOption(adaptation_seconds >= 0 && std::isfinite(adaptation_seconds), "FrameSettings.adaptation_seconds",
                adaptation_seconds, ">= 0 and finite");
  if (light.type == LightKind::kDirectional) {
    RequireOption(light.direction.norm() > 0 && light.direction.allFinite(), "FrameSettings.light.direction (norm)",
                  light.direction.norm(), "finite and non-zero");
  }
  RequireOption(light.position.allFinite(), "FrameSettings.light.position (norm)", light.position.norm(), "finite");
}

}  // namespace parallax
