#include "viewer/tone_mapper.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "viewer/shaders.h"

namespace parallax {
namespace {

// The operator a frame is mapped with: auto exposure alone, on an 8-bit frame that would clip,
// maps as Reinhard does.
ToneMap Operator(const FrameSettings& settings) {
  return settings.tone_map == ToneMap::kClamp && settings.auto_exposure ? ToneMap::kReinhard : settings.tone_map;
}

// The exposed value `op` shows as white: what the glare spreads is over it.
float DisplayWhite(ToneMap op, float reinhard_white) {
  switch (op) {
    case ToneMap::kReinhard: return reinhard_white;
    // Where the ACES fit (2.51c^2 + 0.03c) / (2.43c^2 + 0.59c + 0.14) reaches 1:
    // 0.08c^2 - 0.56c - 0.14 = 0.
    case ToneMap::kAces: return static_cast<float>((0.56 + std::sqrt(0.56 * 0.56 + 4 * 0.08 * 0.14)) / 0.16);
    case ToneMap::kClamp: break;
  }
  return 1;
}

}  // namespace

ToneMapper::ToneMapper(FrameClock clock)
    : program_("tone map", shaders::kToneMapVertex, shaders::kToneMapFragment),
      empty_vao_(MakeGlVertexArray()),
      clock_(std::move(clock)) {}

double ToneMapper::LogAverageLuminance(const gpu::EyeTarget& eye) {
  constexpr int kMeterWidth = 64, kMeterHeight = 36;
  if (meter_.texture.Get() == 0) meter_ = gpu::MakeFloatTarget(kMeterWidth, kMeterHeight, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, eye.hdr_framebuffer.Get());
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, meter_.framebuffer.Get());
  glBlitFramebuffer(0, 0, eye.width, eye.height, 0, 0, kMeterWidth, kMeterHeight, GL_COLOR_BUFFER_BIT, GL_LINEAR);
  std::vector<float> texels(static_cast<size_t>(kMeterWidth) * kMeterHeight * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, meter_.framebuffer.Get());
  glReadPixels(0, 0, kMeterWidth, kMeterHeight, GL_RGBA, GL_FLOAT, texels.data());
  double sum_log = 0;
  for (size_t i = 0; i < texels.size(); i += 4) {
    const double luminance = 0.2126 * static_cast<double>(texels[i]) + 0.7152 * static_cast<double>(texels[i + 1]) +
                             0.0722 * static_cast<double>(texels[i + 2]);
    sum_log += std::log(std::max(luminance, 0.0) + 1e-4);  // The offset keeps black pixels finite.
  }
  return std::exp(sum_log / static_cast<double>(kMeterWidth * kMeterHeight));
}

double ToneMapper::Exposure(const FrameSettings& settings, const gpu::EyeTarget& eye) {
  double exposure = std::exp2(settings.exposure_stops);
  if (!settings.auto_exposure) return exposure;
  const double luminance = LogAverageLuminance(eye);
  const double now = clock_();
  if (!adapted_luminance_ || settings.adaptation_seconds <= 0) {
    adapted_luminance_ = luminance;
  } else {
    // The eye closes the gap to the frame's brightness exponentially in time.
    const double dt = now - last_adaptation_;
    *adapted_luminance_ +=
        (luminance - *adapted_luminance_) * (1 - std::exp(-dt / static_cast<double>(settings.adaptation_seconds)));
  }
  last_adaptation_ = now;
  constexpr double kMiddleGrey = 0.18;
  exposure *= kMiddleGrey / *adapted_luminance_;
  return exposure;
}

void ToneMapper::Map(const FrameSettings& settings, const gpu::EyeTarget& eye, bool with_aux) {
  const double exposure = Exposure(settings, eye);
  const ToneMap op = Operator(settings);
  GLuint linear = eye.hdr.Get();
  linear_framebuffer_ = eye.hdr_framebuffer.Get();
  if (settings.glare) {
    if (!glare_) glare_.emplace();
    glare_->Apply(eye, static_cast<float>(exposure), DisplayWhite(op, settings.white));
    linear = glare_->Result().texture.Get();
    linear_framebuffer_ = glare_->Result().framebuffer.Get();
  }
  glBindFramebuffer(GL_FRAMEBUFFER, eye.framebuffer.Get());
  const GLenum color_only = GL_COLOR_ATTACHMENT0;
  glDrawBuffers(1, &color_only);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_STENCIL_TEST);
  glActiveTexture(GL_TEXTURE0 + gpu::kScratchUnit);
  glBindTexture(GL_TEXTURE_2D, linear);
  glActiveTexture(GL_TEXTURE0);
  program_.Use();
  program_.Set("u_hdr", gpu::kScratchUnit);
  program_.Set("u_exposure", static_cast<float>(exposure));
  program_.Set("u_operator", op == ToneMap::kReinhard ? 1 : op == ToneMap::kAces ? 2 : 0);
  program_.Set("u_white", settings.white);
  glBindVertexArray(empty_vao_.Get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glEnable(GL_DEPTH_TEST);
  const GLenum both[2] = {GL_COLOR_ATTACHMENT0, with_aux ? GLenum{GL_COLOR_ATTACHMENT1} : GLenum{GL_NONE}};
  glDrawBuffers(2, both);
}

}  // namespace parallax
