// HDR rendering and materials against references computed here: tone-mapped pixels against
// the operators applied to the analytic radiance of a lit ground, auto exposure against a scene
// 16 times brighter, the eye's adaptation over time, the glare of an over-bright sphere (its
// light kept, its halo falling off), the sphere-map specular against per-pixel Blinn-Phong and
// the analytic highlight.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>

#include <gtest/gtest.h>

#include "testing/viewer_scenes.h"
#include "viewer/view_cameras.h"
#include "viewer/view_math.h"

namespace parallax {
namespace {
using namespace viewer_test;

const Eigen::Vector3d kLight = Eigen::Vector3d(-0.5, -0.3, -0.8).normalized();

double Srgb(double linear) {
  linear = std::clamp(linear, 0.0, 1.0);
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
}

double Linear(double srgb) { return srgb <= 0.04045 ? srgb / 12.92 : std::pow((srgb + 0.055) / 1.055, 2.4); }

double Reinhard(double c, double white) { return c * (1 + c / (white * white)) / (1 + c); }
double Aces(double c) { return (c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14); }

struct PixelErrors {
  double mean = 0, max = 0;
  int pixels = 0;
};

// Over the lit ground the ray tracer sees: the rendered value against `expected(radiance)`,
// the radiance being the shader's Blinn-Phong (grey albedo, ambient, specular) for that point.
PixelErrors CompareLitGround(const ViewerScene& scene, const ViewCamera& view, const FrameSettings& settings,
                             const FrameResult& frame, const std::function<double(double)>& expected) {
  const std::vector<ReferencePixel> reference = ReferenceShadows(scene.mesh, view, settings.light.direction);
  const Eigen::Vector3d eye = CameraCenter(view.cam_from_world), to_light = -settings.light.direction.normalized();
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  PixelErrors errors;
  for (int y = 0; y < frame.color.Height(); ++y) {
    for (int x = 0; x < frame.color.Width(); ++x) {
      const ReferencePixel& ref = reference[static_cast<size_t>(y) * frame.color.Width() + x];
      // Away from the shadows' edges, where a pixel is part shadow.
      if (!ref.hit || ref.shadowed || std::abs(ref.point.z()) > 1e-3 || frame.aux.At(x, y, 0) < 1.0f) continue;
      const Eigen::Vector3d half = (to_light + (eye - ref.point).normalized()).normalized();
      const double irradiance = settings.light.intensity, ambient = settings.ambient, specular = settings.specular,
                   shininess = settings.shininess;
      const double radiance = 0.7 * (ambient + up.dot(to_light) * irradiance) +
                              specular * std::pow(std::max(up.dot(half), 0.0), shininess) * irradiance;
      const double error = std::abs(static_cast<double>(frame.color.At(x, y, 1)) - expected(radiance));
      errors.mean += error;
      errors.max = std::max(errors.max, error);
      ++errors.pixels;
    }
  }
  errors.mean /= std::max(errors.pixels, 1);
  return errors;
}

// A light six times the usual on the grey ground: clamped, most of it is white; each operator's
// pixels are that operator applied to the analytic radiance.
TEST(ViewerHdr, ToneMappedPixelsAreTheOperatorsOfTheAnalyticRadiance) {
  EnsureGlContext();
  const ViewerScene scene = BoxOnGround();
  SceneRenderer renderer(scene);
  const ViewCamera view = OrbitViewCamera(scene, 200, 35, 320, 240, 50);
  FrameSettings settings = ShadowSettings(ShadowMode::kPcf, kLight);
  settings.light.intensity = 6;
  settings.white = 8;  // Above the brightest radiance in view (5.2): Reinhard reaches white nowhere.
  const std::vector<std::tuple<ToneMap, const char*, std::function<double(double)>>> operators = {
      {ToneMap::kClamp, "clamp", [](double c) { return Srgb(c); }},
      {ToneMap::kReinhard, "reinhard", [&](double c) { return Srgb(Reinhard(c, settings.white)); }},
      {ToneMap::kAces, "aces", [](double c) { return Srgb(Aces(c)); }}};
  for (const auto& [tone_map, name, expected] : operators) {
    settings.tone_map = tone_map;
    const FrameResult frame = renderer.Render(view, settings);
    const PixelErrors errors = CompareLitGround(scene, view, settings, frame, expected);
    int white = 0;
    for (int y = 0; y < frame.color.Height(); ++y) {
      for (int x = 0; x < frame.color.Width(); ++x) white += frame.color.At(x, y, 1) >= 1.0f;
    }
    std::printf("[ measure ] %s: lit ground %d pixels, error mean %.5f max %.5f; %d white pixels\n", name,
                errors.pixels, errors.mean, errors.max, white);
    EXPECT_GT(errors.pixels, 10000) << name;
    EXPECT_LT(errors.mean, 1.0 / 255) << name;
    EXPECT_LT(errors.max, 3.0 / 255) << name;
    if (tone_map == ToneMap::kClamp) {
      EXPECT_GT(white, errors.pixels / 2) << "a strong light clips";
    } else {
      EXPECT_EQ(white, 0) << name << " keeps every lit pixel below white";
    }
  }
}

double MeanAbsoluteDifference(const Image& a, const Image& b) {
  double sum = 0;
  for (size_t i = 0; i < a.Pixels().size(); ++i) sum += std::abs(static_cast<double>(a.Pixels()[i] - b.Pixels()[i]));
  return sum / static_cast<double>(a.Pixels().size());
}

// Auto exposure shows a scene 16 times brighter (light, ambient and background) as it shows
// the scene itself; the eye adapting over half a second is dazzled first, then adapts.
TEST(ViewerHdr, AutoExposureAdaptsToTheScenesBrightness) {
  EnsureGlContext();
  const ViewerScene scene = BoxOnGround();
  SceneRenderer renderer(scene);
  const ViewCamera view = OrbitViewCamera(scene, 200, 35, 320, 240, 50);
  FrameSettings dim = ShadowSettings(ShadowMode::kPcf, kLight);
  dim.auto_exposure = true;
  FrameSettings bright = dim;
  bright.light.intensity *= 16;
  bright.ambient *= 16;
  bright.background *= 16;
  const Image dim_frame = renderer.Render(view, dim).color;
  const Image bright_frame = renderer.Render(view, bright).color;
  const double auto_difference = MeanAbsoluteDifference(dim_frame, bright_frame);
  FrameSettings fixed_dim = dim, fixed_bright = bright;
  fixed_dim.auto_exposure = fixed_bright.auto_exposure = false;
  fixed_dim.tone_map = fixed_bright.tone_map = ToneMap::kReinhard;
  const double fixed_difference =
      MeanAbsoluteDifference(renderer.Render(view, fixed_dim).color, renderer.Render(view, fixed_bright).color);
  std::printf("[ measure ] 16x brighter: mean difference %.5f with auto exposure, %.5f without\n", auto_difference,
              fixed_difference);
  EXPECT_LT(auto_difference, 1.0 / 255);
  EXPECT_GT(fixed_difference, 0.1);

  // Adapted to the dim scene, the eye meets the bright one: at first too bright, then as the
  // dim frame was within 2/255 after ten time constants. The renderer's clock is the test's.
  FrameSettings adapting_dim = dim, adapting_bright = bright;
  adapting_dim.adaptation_seconds = adapting_bright.adaptation_seconds = 0.05f;
  double now = 0;
  SceneRenderer eye(scene, [&now] { return now; });
  eye.Render(view, adapting_dim);
  const Image dazzled = eye.Render(view, adapting_bright).color;
  now += 0.5;
  const Image adapted = eye.Render(view, adapting_bright).color;
  const double dazzled_difference = MeanAbsoluteDifference(dazzled, dim_frame);
  const double adapted_difference = MeanAbsoluteDifference(adapted, dim_frame);
  std::printf("[ measure ] adaptation: %.5f from the adapted picture at first, %.5f after 0.5 s\n",
              dazzled_difference, adapted_difference);
  EXPECT_GT(dazzled_difference, 0.05);
  EXPECT_LT(adapted_difference, 2.0 / 255);
}

double Luminance(const Image& linear, int x, int y) {
  return 0.2126 * static_cast<double>(linear.At(x, y, 0)) + 0.7152 * static_cast<double>(linear.At(x, y, 1)) +
         0.0722 * static_cast<double>(linear.At(x, y, 2));
}

// A sphere lit ten times over the display's white on a black background: with glare, what its
// pixels hold over the white is spread around it and the frame keeps its light; a sphere lit
// below the white is drawn as it is without glare.
TEST(ViewerHdr, GlareSpreadsTheLightOverWhiteAndKeepsIt) {
  EnsureGlContext();
  const ViewerScene scene = SceneFromObjects({Sphere(1)});
  SceneRenderer renderer(scene);
  ViewCamera view;
  view.camera = ViewerCamera(320, 240, 20);
  view.cam_from_world = LookAt({0, -30, 0}, {0, 0, 0}, {0, 0, 1});
  FrameSettings settings = ShadowSettings(ShadowMode::kNone, Eigen::Vector3d(0.3, 1, -0.4).normalized());
  settings.ambient = 0;
  settings.background = Eigen::Vector3f::Zero();
  settings.tone_map = ToneMap::kReinhard;  // White at 4.
  settings.light.intensity = 60;           // Up to 0.85 * 60 = 51 (diffuse and specular).
  const FrameResult plain = renderer.Render(view, settings);
  settings.glare = true;
  const FrameResult glared = renderer.Render(view, settings);
  ASSERT_EQ(plain.linear.Width(), 320);
  ASSERT_EQ(glared.linear.Width(), 320);

  // The sphere's disc and rings around it by distance from its centre (its radius about 31 px).
  const Eigen::Vector2d centre = view.camera.Project(view.cam_from_world * Eigen::Vector3d::Zero()).value();
  double plain_light = 0, glared_light = 0, plain_peak = 0, glared_peak = 0;
  std::array<double, 3> ring_light{}, ring_plain{};
  std::array<int, 3> ring_pixels{};
  for (int y = 0; y < 240; ++y) {
    for (int x = 0; x < 320; ++x) {
      const double before = Luminance(plain.linear, x, y), after = Luminance(glared.linear, x, y);
      plain_light += before;
      glared_light += after;
      plain_peak = std::max(plain_peak, before);
      glared_peak = std::max(glared_peak, after);
      const double distance = (Eigen::Vector2d(x + 0.5, y + 0.5) - centre).norm();
      const int ring = distance > 40 && distance < 50 ? 0 : distance > 60 && distance < 70 ? 1
                     : distance > 90 && distance < 100 ? 2 : -1;
      if (ring < 0 || RenderedCovered(plain.aux, x, y)) continue;
      ring_light[ring] += after;
      ring_plain[ring] += before;
      ++ring_pixels[ring];
    }
  }
  for (int ring = 0; ring < 3; ++ring) ring_light[ring] /= std::max(ring_pixels[ring], 1);
  std::printf("[ measure ] glare: frame light %.1f -> %.1f, peak %.2f -> %.2f, halo at 45 / 65 / 95 px %.4f / %.4f / "
              "%.4f\n",
              plain_light, glared_light, plain_peak, glared_peak, ring_light[0], ring_light[1], ring_light[2]);
  // Over white and taken out, the light is added back around: the frame holds as much (what
  // spreads past the frame's border is lost; the sphere sits in its middle).
  // The disc's brightest pixel keeps the white and its neighbours' halo: measured 35.5 of 50.
  EXPECT_GT(plain_peak, 40);
  EXPECT_LT(glared_peak, 0.8 * plain_peak);
  EXPECT_NEAR(glared_light, plain_light, 0.01 * plain_light);
  // A halo over the black background that falls off with distance.
  for (int ring = 0; ring < 3; ++ring) {
    EXPECT_GT(ring_pixels[ring], 100) << ring;
    EXPECT_EQ(ring_plain[ring], 0) << ring;
  }
  EXPECT_GT(ring_light[0], 0.02);
  EXPECT_GT(ring_light[0], 2 * ring_light[1]);
  EXPECT_GT(ring_light[1], ring_light[2]);
  EXPECT_GT(ring_light[2], 0);

  // Below white there is nothing to spread: the same frame.
  settings.light.intensity = 4;  // Up to 3.4.
  const FrameResult dim_glared = renderer.Render(view, settings);
  settings.glare = false;
  const FrameResult dim_plain = renderer.Render(view, settings);
  EXPECT_EQ(dim_glared.color.Pixels(), dim_plain.color.Pixels());
}

// The sphere map's specular on a sphere seen through a narrow field of view (where every pixel
// is seen nearly along the axis, as the sphere map assumes) against the shader's own per-pixel
// Blinn-Phong, and its highlight where the analytic one is: the normal halfway between the
// light and the eye.
TEST(ViewerMatcap, SphereMapSpecularMatchesBlinnPhong) {
  EnsureGlContext();
  const ViewerScene scene = SceneFromObjects({Sphere(1)});
  SceneRenderer renderer(scene);
  ViewCamera view;
  view.camera = ViewerCamera(320, 320, 2.5);
  const Eigen::Vector3d eye(0, -60, 10);
  view.cam_from_world = LookAt(eye, {0, 0, 0}, {0, 0, 1});
  FrameSettings settings = ShadowSettings(ShadowMode::kNone, Eigen::Vector3d(0.3, 0.6, -0.5).normalized());
  settings.specular = 0.3f;  // Diffuse and specular stay below white: no plateau at the peak.
  settings.texture = TextureMode::kAtlas;
  const FrameResult phong = renderer.Render(view, settings);
  settings.texture = TextureMode::kMatcap;
  const FrameResult matcap = renderer.Render(view, settings);
  settings.specular = 0;
  const FrameResult diffuse = renderer.Render(view, settings);

  double squared = 0, highlight = 0;
  int pixels = 0;
  Eigen::Vector2d brightest(0, 0);
  float brightest_value = -1;
  for (int y = 0; y < 320; ++y) {
    for (int x = 0; x < 320; ++x) {
      if (!RenderedCovered(phong.aux, x, y)) continue;
      const double difference = static_cast<double>(matcap.color.At(x, y, 1) - phong.color.At(x, y, 1));
      squared += difference * difference;
      // In linear light: in sRGB values the same addition shows more where the diffuse is darker.
      const float specular = static_cast<float>(Linear(matcap.color.At(x, y, 1)) - Linear(diffuse.color.At(x, y, 1)));
      highlight = std::max(highlight, static_cast<double>(specular));
      if (specular > brightest_value) {
        brightest_value = specular;
        brightest = Eigen::Vector2d(x + 0.5, y + 0.5);
      }
      ++pixels;
    }
  }
  const double psnr = 10 * std::log10(1 / (squared / pixels));
  // Where the analytic highlight is: the sphere's point whose normal is the half vector.
  const Eigen::Vector3d half = (-settings.light.direction + (eye - Eigen::Vector3d::Zero()).normalized()).normalized();
  const Eigen::Vector2d expected = view.camera.Project(view.cam_from_world * half).value();
  std::printf("[ measure ] matcap: %d sphere pixels, PSNR %.2f dB against per-pixel Blinn-Phong, specular up to %.3f, "
              "its peak %.1f px from the analytic highlight\n",
              pixels, psnr, highlight, (brightest - expected).norm());
  EXPECT_GT(pixels, 20000);
  EXPECT_GT(psnr, 40);
  EXPECT_GT(highlight, 0.2) << "the sphere map adds a real highlight";
  // Measured 3.4 px on a sphere 240 px across: its tessellation's interpolated normals, not
  // the unit sphere's, place the peak.
  EXPECT_LT((brightest - expected).norm(), 6);
}

}  // namespace
}  // namespace parallax
