#include "viewer/glare.h"

#include <string>

#include "viewer/shaders.h"

namespace parallax {
namespace {

std::string GlareSource(const char* body) {
  return std::string("#version 330 core\n") + shaders::kGlareExcess + body;
}

}  // namespace

Glare::Glare()
    : first_level_("glare first level", shaders::kToneMapVertex,
                   GlareSource(shaders::kGlareFirstLevelFragment).c_str()),
      upsample_("glare upsample", shaders::kToneMapVertex, shaders::kGlareUpsampleFragment),
      composite_("glare composite", shaders::kToneMapVertex, GlareSource(shaders::kGlareCompositeFragment).c_str()),
      empty_vao_(MakeGlVertexArray()) {}

void Glare::Resize(int width, int height) {
  if (width == width_ && height == height_) return;
  width_ = width;
  height_ = height;
  // Padded so that every level is exactly half the one before: a linear blit then averages
  // 2x2 texels, and each level holds the light of the first.
  constexpr int kMultiple = 1 << kLevels;
  extent_width_ = (width + kMultiple - 1) / kMultiple * kMultiple;
  extent_height_ = (height + kMultiple - 1) / kMultiple * kMultiple;
  for (int level = 0; level < kLevels; ++level) {
    levels_[level] = gpu::MakeFloatTarget(extent_width_ >> (level + 1), extent_height_ >> (level + 1), GL_LINEAR);
  }
  result_ = gpu::MakeFloatTarget(width, height, GL_LINEAR);
}

void Glare::Apply(const gpu::EyeTarget& eye, float exposure, float white) {
  Resize(eye.width, eye.height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_STENCIL_TEST);
  glBindVertexArray(empty_vao_.Get());
  glActiveTexture(GL_TEXTURE0 + gpu::kScratchUnit);
  glBindTexture(GL_TEXTURE_2D, eye.hdr.Get());
  // The excess, 2x2 averaged, into the first level.
  glBindFramebuffer(GL_FRAMEBUFFER, levels_[0].framebuffer.Get());
  glViewport(0, 0, extent_width_ / 2, extent_height_ / 2);
  first_level_.Use();
  first_level_.Set("u_hdr", gpu::kScratchUnit);
  first_level_.Set("u_exposure", exposure);
  first_level_.Set("u_white", white);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  // Each further level the 2x2 average of the one before.
  for (int level = 1; level < kLevels; ++level) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, levels_[level - 1].framebuffer.Get());
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, levels_[level].framebuffer.Get());
    const int from_width = extent_width_ >> level, from_height = extent_height_ >> level;
    glBlitFramebuffer(0, 0, from_width, from_height, 0, 0, from_width / 2, from_height / 2, GL_COLOR_BUFFER_BIT,
                      GL_LINEAR);
  }
  // From the coarsest, each level added to the next finer one, upsampled: the first then holds
  // every level, each spread over its own width.
  upsample_.Use();
  upsample_.Set("u_coarser", gpu::kGlareUnit);
  glActiveTexture(GL_TEXTURE0 + gpu::kGlareUnit);
  glEnable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ONE);
  for (int level = kLevels - 2; level >= 0; --level) {
    const int width = extent_width_ >> (level + 1), height = extent_height_ >> (level + 1);
    glBindTexture(GL_TEXTURE_2D, levels_[level + 1].texture.Get());
    glBindFramebuffer(GL_FRAMEBUFFER, levels_[level].framebuffer.Get());
    glViewport(0, 0, width, height);
    upsample_.Set("u_size", Eigen::Vector2f(static_cast<float>(width), static_cast<float>(height)));
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
  glDisable(GL_BLEND);
  // The frame less its excess, plus the halo: the levels' mean.
  glBindTexture(GL_TEXTURE_2D, levels_[0].texture.Get());
  glActiveTexture(GL_TEXTURE0);
  glBindFramebuffer(GL_FRAMEBUFFER, result_.framebuffer.Get());
  glViewport(0, 0, width_, height_);
  composite_.Use();
  composite_.Set("u_hdr", gpu::kScratchUnit);
  composite_.Set("u_halo", gpu::kGlareUnit);
  composite_.Set("u_exposure", exposure);
  composite_.Set("u_white", white);
  composite_.Set("u_levels", static_cast<float>(kLevels));
  composite_.Set("u_extent", Eigen::Vector2f(static_cast<float>(extent_width_), static_cast<float>(extent_height_)));
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
}

}  // namespace parallax
