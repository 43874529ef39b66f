#include "geometry/embree_scene.h"

#include <algorithm>
#include <stdexcept>

namespace parallax {

EmbreeScene::EmbreeScene(bool high_quality) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw std::runtime_error("Embree: cannot create a device");
  rtcSetDeviceErrorFunction(
      device_,
      [](void* user, RTCError, const char* message) {
        static_cast<EmbreeScene*>(user)->error_ = message ? message : "unknown error";
      },
      this);
  scene_ = rtcNewScene(device_);
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
  if (high_quality) rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
}

EmbreeScene::~EmbreeScene() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

unsigned EmbreeScene::Add(const std::vector<Eigen::Vector3f>& vertices,
                          const std::vector<Eigen::Vector3i>& triangles) {
  RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertex_buffer = static_cast<float*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertices.size()));
  auto* index_buffer = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles.size()));
  if (!vertex_buffer || !index_buffer) {
    rtcReleaseGeometry(geometry);
    throw std::runtime_error("Embree: " + error_);
  }
  for (size_t i = 0; i < vertices.size(); ++i) std::copy_n(vertices[i].data(), 3, vertex_buffer + 3 * i);
  for (size_t i = 0; i < triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k) index_buffer[3 * i + k] = static_cast<unsigned>(triangles[i][k]);
  }
  rtcCommitGeometry(geometry);
  const unsigned id = rtcAttachGeometry(scene_, geometry);
  rtcReleaseGeometry(geometry);
  return id;
}

void EmbreeScene::Commit() {
  rtcCommitScene(scene_);
  if (!error_.empty()) throw std::runtime_error("Embree: " + error_);
}

}  // namespace parallax
