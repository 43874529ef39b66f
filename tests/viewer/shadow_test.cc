#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>

#include <gtest/gtest.h>

#include "testing/viewer_scenes.h"
#include "viewer/view_cameras.h"
#include "viewer/shadow_volume.h"
#include "viewer/view_math.h"

namespace parallax {
namespace {
using namespace viewer_test;

// Set PARALLAX_VIEWER_TEST_OUT=<dir> to keep the rendered images for a look.
void MaybeSave(const std::string& name, const FrameResult& result) {
  const char* dir = std::getenv("PARALLAX_VIEWER_TEST_OUT");
  if (!dir) return;
  std::filesystem::create_directories(dir);
  WriteImage(std::filesystem::path(dir) / (name + ".png"), result.color, PixelFormat::kUint8);
}

const Eigen::Vector3d kLight = Eigen::Vector3d(-0.5, -0.3, -0.8).normalized();

ViewCamera TestView(const ViewerScene& scene) {
  ViewCamera view = OrbitViewCamera(scene, 200, 35, 640, 480, 50);
  return view;
}

TEST(ViewerShadows, ShadowMapMatchesRayTracedMask) {
  EnsureGlContext();
  const ViewerScene scene = BoxOnGround();
  ASSERT_TRUE(scene.ground.has_value());
  SceneRenderer renderer(scene);
  const ViewCamera view = TestView(scene);
  const std::vector<ReferencePixel> reference = ReferenceShadows(scene.mesh, view, kLight);
  for (const auto& [mode, min_iou, name] : {std::tuple{ShadowMode::kMap, 0.95, "map"},
                                            std::tuple{ShadowMode::kPcf, 0.90, "pcf"}}) {
    const FrameResult result = renderer.Render(view, ShadowSettings(mode, kLight));
    MaybeSave(std::string("shadow_") + name, result);
    const MaskComparison all = CompareShadowMasks(reference, result.aux);
    // Cast shadows alone (the ground), without the box's faces turned away from the light.
    const MaskComparison ground = CompareShadowMasks(reference, result.aux,
                                               [](const ReferencePixel& p) { return std::abs(p.point.z()) < 1e-3; });
    std::printf("[ measure ] %s: IoU %.4f (ground only %.4f) over %d pixels, shadowed ref %d / rendered %d\n",
                name, all.iou, ground.iou, all.compared, all.reference_shadowed, all.rendered_shadowed);
    EXPECT_GE(all.iou, min_iou) << name;
    EXPECT_GE(ground.iou, min_iou) << name;
    EXPECT_GT(ground.reference_shadowed, 1000) << "the view must show a real cast shadow";
  }
}

TEST(ViewerShadows, PlanarShadowsMatchRayTracedMaskOnTheGround) {
  EnsureGlContext();
  const ViewerScene scene = BoxOnGround();
  SceneRenderer renderer(scene);
  const ViewCamera view = TestView(scene);
  const std::vector<ReferencePixel> reference = ReferenceShadows(scene.mesh, view, kLight);
  const FrameResult result = renderer.Render(view, ShadowSettings(ShadowMode::kPlanar, kLight));
  MaybeSave("shadow_planar", result);
  const MaskComparison ground = CompareShadowMasks(reference, result.aux,
                                             [](const ReferencePixel& p) { return std::abs(p.point.z()) < 1e-3; });
  std::printf("[ measure ] planar: ground IoU %.4f over %d pixels\n", ground.iou, ground.compared);
  EXPECT_GE(ground.iou, 0.95);
}

// Pixels of the frame against the ray-traced reference, all of them and the ground alone.
void ExpectVolumeMatchesReference(const ViewerScene& scene, const ViewCamera& view, const char* name,
                                  double min_iou) {
  SceneRenderer renderer(scene);
  const std::vector<ReferencePixel> reference = ReferenceShadows(scene.mesh, view, kLight);
  const FrameResult result = renderer.Render(view, ShadowSettings(ShadowMode::kVolume, kLight));
  MaybeSave(name, result);
  const MaskComparison all = CompareShadowMasks(reference, result.aux);
  const MaskComparison cast = CompareCastShadows(reference, result.aux);
  std::printf("[ measure ] %s: IoU %.4f (cast shadows alone %.4f) over %d pixels, shadowed ref %d / rendered %d\n",
              name, all.iou, cast.iou, all.compared, all.reference_shadowed, all.rendered_shadowed);
  EXPECT_GE(all.iou, min_iou) << name;
  EXPECT_GE(cast.iou, min_iou) << name;
  EXPECT_GT(cast.reference_shadowed, 1000) << "the view must show a real cast shadow";
  EXPECT_GT(all.compared - all.reference_shadowed, 1000) << "and lit surfaces";
}

TEST(ViewerShadows, ShadowVolumesMatchRayTracedMask) {
  EnsureGlContext();
  const ViewerScene scene = BoxOnGround();
  ExpectVolumeMatchesReference(scene, TestView(scene), "shadow_volume", 0.99);
}

// The lecture's warning: counting the volume faces in front of the surface (z-pass) goes wrong
// once the eye is inside a volume. z-fail counts behind it and does not care.
TEST(ViewerShadows, ShadowVolumesStayRightWithTheEyeInsideAVolume) {
  EnsureGlContext();
  const ViewerScene scene = BoxOnGround();
  // 0.3 above the ground on the way of the light from the box's top centre, beside the box:
  // inside its shadow volume, looking out over the ground, partly in the box's shadow.
  const Eigen::Vector3d eye = Eigen::Vector3d(0.5, 0.2, 2) + 2.125 * Eigen::Vector3d(-0.5, -0.3, -0.8);
  ViewCamera view;
  view.camera = ViewerCamera(640, 480, 90);
  view.cam_from_world = LookAt(eye, {-1.5, -1.2, 0}, {0, 0, 1});
  view.near = 0.01;
  const MeshRaycaster raycaster(scene.mesh.vertices, scene.mesh.triangles);
  ASSERT_FALSE(raycaster.Unoccluded({eye.cast<float>()}, (-kLight).cast<float>(), 100)[0])
      << "the eye must be in the box's shadow";
  ASSERT_TRUE(raycaster.Unoccluded({eye.cast<float>()}, Eigen::Vector3f(0, 0, 1), 100)[0]) << "outside the box";
  ExpectVolumeMatchesReference(scene, view, "shadow_volume_eye_inside", 0.99);
}

// Every triangle turned to face the light, interior edges cancelled: a closed box lit from
// straight above casts its top and its bottom (4 caps), extrudes each of their 4 outer edges
// (8), and its walls, edge-on, nothing. A lamp above it sees the walls at a slant: all 12
// triangles cast, each with its image at infinity.
TEST(ViewerShadows, ShadowVolumeExtrudesOnlyTheSilhouette) {
  const TriangleMesh box = TessellateObject(Box({0, 0, 1}, {2, 2, 2}));
  ASSERT_EQ(box.triangles.size(), 12u);
  const ShadowVolume sun = BuildShadowVolume(box, {0, 0, 1, 0}, 0.0f);
  EXPECT_EQ(sun.caps, 4);
  EXPECT_EQ(sun.silhouette_edges, 8);
  EXPECT_EQ(sun.vertices.size(), 3u * (4 + 8));
  const ShadowVolume lamp = BuildShadowVolume(box, {0, 0, 100, 1}, 0.0f);
  EXPECT_EQ(lamp.caps, 2 * 12);
  for (const Eigen::Vector4f& v : lamp.vertices) ASSERT_TRUE(v.allFinite());
}

// A blob is the shadow's rough place and size on the ground, nothing more: it must overlap the
// true shadow more than it misses, and darken nothing above the ground (no self-shadowing).
TEST(ViewerShadows, BlobShadowLiesOnTheGroundWhereTheShadowFalls) {
  EnsureGlContext();
  const ViewerScene scene = BoxOnGround();
  SceneRenderer renderer(scene);
  const ViewCamera view = TestView(scene);
  const std::vector<ReferencePixel> reference = ReferenceShadows(scene.mesh, view, kLight);
  const FrameResult result = renderer.Render(view, ShadowSettings(ShadowMode::kBlob, kLight));
  MaybeSave("shadow_blob", result);
  const auto on_ground = [](const ReferencePixel& p) { return std::abs(p.point.z()) < 1e-3; };
  const MaskComparison ground = CompareShadowMasks(reference, result.aux, on_ground);
  int off_ground_darkened = 0;
  for (int y = 0; y < result.aux.Height(); ++y) {
    for (int x = 0; x < result.aux.Width(); ++x) {
      const ReferencePixel& ref = reference[static_cast<size_t>(y) * 640 + x];
      // Above the band the renderer counts as ground (1% of the focus radius, < 0.05 here).
      off_ground_darkened += ref.hit && ref.point.z() > 0.1 && result.aux.At(x, y, 0) < 1.0f;
    }
  }
  std::printf("[ measure ] blob: ground IoU %.4f, shadowed ref %d / rendered %d; above the ground darkened %d\n",
              ground.iou, ground.reference_shadowed, ground.rendered_shadowed, off_ground_darkened);
  EXPECT_GT(ground.rendered_shadowed, ground.reference_shadowed / 4);
  EXPECT_GE(ground.iou, 0.5);
  EXPECT_EQ(off_ground_darkened, 0);
}

// --shadows auto leaves out what the picture does not need and says why.
TEST(ViewerShadows, AutomaticShadowsFitTheScene) {
  ViewerScene scene = BoxOnGround();
  const ShadowChoice small = ChooseShadows(scene, TextureMode::kAtlas);
  EXPECT_EQ(small.mode, ShadowMode::kVolume) << small.reason;
  EXPECT_NE(small.reason.find("exact"), std::string::npos) << small.reason;
  const ShadowChoice photos = ChooseShadows(scene, TextureMode::kProjective);
  EXPECT_EQ(photos.mode, ShadowMode::kNone) << photos.reason;
  EXPECT_NE(photos.reason.find("their own shadows"), std::string::npos) << photos.reason;
  while (scene.mesh.triangles.size() <= 4000) scene.mesh.triangles.push_back(scene.mesh.triangles.front());
  const ShadowChoice large = ChooseShadows(scene, TextureMode::kAtlas);
  EXPECT_EQ(large.mode, ShadowMode::kPcf) << large.reason;
  EXPECT_NE(large.reason.find("4001 triangles"), std::string::npos) << large.reason;
  scene.mesh.triangles.clear();
  EXPECT_EQ(ChooseShadows(scene, TextureMode::kAtlas).mode, ShadowMode::kPcf);
}

TEST(ViewerShadows, PlanarShadowsAreSkippedWithANoteWithoutAGround) {
  EnsureGlContext();
  // A lone box: no plane holds 15% of its surface samples within tolerance... except a face;
  // a sphere has no plane at all.
  const ViewerScene scene = SceneFromObjects({Sphere(1)});
  EXPECT_FALSE(scene.ground.has_value());
  SceneRenderer renderer(scene);
  renderer.Render(TestView(scene), ShadowSettings(ShadowMode::kPlanar, kLight));
  const std::vector<std::string> notes = renderer.TakeNotes();
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("planar shadows skipped"), std::string::npos);
}

TEST(ViewerShadows, LitPlaneFacingTheLightHasNoAcne) {
  EnsureGlContext();
  const ViewerScene scene = SceneFromObjects({Plane(10)});
  SceneRenderer renderer(scene);
  const ViewCamera view = OrbitViewCamera(scene, 30, 40, 640, 480, 50);
  for (const Eigen::Vector3d& light : {Eigen::Vector3d(0, 0, -1), kLight, Eigen::Vector3d(-1, 0, -0.3).normalized()}) {
    for (ShadowMode mode : {ShadowMode::kMap, ShadowMode::kPcf}) {
      const FrameResult result = renderer.Render(view, ShadowSettings(mode, light));
      int covered = 0, shadowed = 0;
      for (int y = 0; y < result.aux.Height(); ++y) {
        for (int x = 0; x < result.aux.Width(); ++x) {
          if (!RenderedCovered(result.aux, x, y)) continue;
          ++covered;
          shadowed += RenderedShadowed(result.aux, x, y);
        }
      }
      const double ratio = static_cast<double>(shadowed) / covered;
      std::printf("[ measure ] acne, light (%.2f %.2f %.2f) %s: %.5f%% of %d pixels\n", light.x(), light.y(),
                  light.z(), mode == ShadowMode::kMap ? "map" : "pcf", 100 * ratio, covered);
      EXPECT_GT(covered, 50000);
      EXPECT_LT(ratio, 0.001);
    }
  }
}

// Looking straight down from far away (nearly orthographic) at a box lit from the side: the
// shadow on the ground must start at the box, not float away from it.
TEST(ViewerShadows, ContactShadowStartsAtTheBox) {
  EnsureGlContext();
  const ViewerScene scene = SceneFromObjects({Plane(10), Box({0, 0, 1}, {2, 2, 2})});
  SceneRenderer renderer(scene);
  ViewCamera view;
  view.camera = ViewerCamera(640, 480, 2.5);
  view.cam_from_world = LookAt({0, 0, 200}, {0, 0, 0}, {0, 1, 0});  // Image x = world x.
  const Eigen::Vector3d light = Eigen::Vector3d(1, 0.0, -1).normalized();  // Shadow towards +x.
  for (ShadowMode mode : {ShadowMode::kMap, ShadowMode::kPcf}) {
    const FrameResult result = renderer.Render(view, ShadowSettings(mode, light));
    MaybeSave(mode == ShadowMode::kMap ? "contact_map" : "contact_pcf", result);
    int worst_gap = 0, rows = 0;
    for (int y = 180; y < 300; ++y) {
      int box_right = -1;  // Box top: nearer than the ground (depth 198 against 200).
      for (int x = 0; x < 640; ++x) {
        if (RenderedCovered(result.aux, x, y) && result.aux.At(x, y, 2) < 199) box_right = x;
      }
      if (box_right < 0) continue;
      ++rows;
      int gap = 0;
      while (box_right + 1 + gap < 640 && !RenderedShadowed(result.aux, box_right + 1 + gap, y)) ++gap;
      worst_gap = std::max(worst_gap, gap);
    }
    std::printf("[ measure ] contact shadow gap (%s): %d px over %d rows\n",
                mode == ShadowMode::kMap ? "map" : "pcf", worst_gap, rows);
    EXPECT_GT(rows, 50);
    EXPECT_LE(worst_gap, 2);
  }
}

// A box only 1e-3 scene sizes tall on the ground, seen from 10 scene sizes with a near plane
// 1e-6 of the distance: reverse-Z keeps the two surfaces apart.
TEST(ViewerShadows, ThinBoxDoesNotZFightWithTheGroundAtNearFarRatioOneMillion) {
  EnsureGlContext();
  const double size = 10, thickness = 1e-3 * size;
  const ViewerScene scene = SceneFromObjects({Plane(size), Box({0, 0, thickness / 2}, {4, 4, thickness})});
  SceneRenderer renderer(scene);
  ViewCamera view;
  view.camera = ViewerCamera(640, 480, 8);
  view.cam_from_world = OrbitPose({0, 0, 0}, {0, 0, 1}, 30, 40, 10 * size);
  view.near = 10 * size * 1e-6;
  const MeshRaycaster raycaster(scene.mesh.vertices, scene.mesh.triangles);
  const std::vector<RayHit> hits = raycaster.CastPixels(view.camera, view.cam_from_world);
  for (bool reverse_z : {true, false}) {
    FrameSettings settings = ShadowSettings(ShadowMode::kNone, Eigen::Vector3d(0, 0, -1));
    settings.reverse_z = reverse_z;
    if (!reverse_z) view.near = 0;  // Without reverse-Z the near plane is fitted to the scene.
    const FrameResult result = renderer.Render(view, settings);
    int box_pixels = 0, fighting = 0;
    for (int y = 0; y < 480; ++y) {
      for (int x = 0; x < 640; ++x) {
        const RayHit& hit = hits[static_cast<size_t>(y) * 640 + x];
        if (hit.triangle < 2) continue;  // Triangles 0 and 1 are the ground.
        ++box_pixels;
        // The ground under the box top lies >= thickness / sin(40 deg) further along the ray.
        fighting += std::abs(static_cast<double>(result.aux.At(x, y, 2) - hit.depth)) > 0.25 * thickness;
      }
    }
    std::printf("[ measure ] z-fighting (%s): %d of %d box pixels\n", reverse_z ? "reverse-Z, near/far 1e-6" : "fitted near",
                fighting, box_pixels);
    EXPECT_GT(box_pixels, 10000);
    EXPECT_EQ(fighting, 0);
  }
  EXPECT_TRUE(renderer.UsesReverseZ()) << "llvmpipe has ARB_clip_control";
}

TEST(ViewerShadows, GrazingLightGivesNoNanAndNoFullScreenAcne) {
  EnsureGlContext();
  const ViewerScene scene = BoxOnGround();
  SceneRenderer renderer(scene);
  const ViewCamera view = TestView(scene);
  // 89.9 degrees from the ground's normal.
  const double elevation = 0.1 * std::numbers::pi / 180;
  const Eigen::Vector2d across = Eigen::Vector2d(1, 0.3).normalized();
  const Eigen::Vector3d light = -Eigen::Vector3d(std::cos(elevation) * across.x(),
                                                 std::cos(elevation) * across.y(), std::sin(elevation));
  const std::vector<ReferencePixel> reference = ReferenceShadows(scene.mesh, view, light);
  for (ShadowMode mode : {ShadowMode::kMap, ShadowMode::kPcf, ShadowMode::kPlanar}) {
    const FrameResult result = renderer.Render(view, ShadowSettings(mode, light));
    for (float v : result.color.Pixels()) ASSERT_TRUE(std::isfinite(v));
    for (float v : result.aux.Pixels()) ASSERT_TRUE(std::isfinite(v));
    // Pixels shadowed by the renderer that the ray tracer sees lit.
    int lit = 0, false_shadow = 0;
    for (int y = 0; y < 480; ++y) {
      for (int x = 0; x < 640; ++x) {
        const ReferencePixel& ref = reference[static_cast<size_t>(y) * 640 + x];
        if (!ref.hit || ref.shadowed || !RenderedCovered(result.aux, x, y)) continue;
        ++lit;
        false_shadow += RenderedShadowed(result.aux, x, y);
      }
    }
    std::printf("[ measure ] grazing light, mode %d: %d of %d lit pixels shadowed\n", static_cast<int>(mode),
                false_shadow, lit);
    EXPECT_LT(false_shadow, std::max(50, lit / 50));
  }
}

}  // namespace
}  // namespace parallax
