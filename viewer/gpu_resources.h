#pragma once
// The viewer's GPU resources: vertex buffers of the mesh, the cloud and the lines, textures, and
// the render targets (shadow and projector depth maps, the eye's frame). Needs a current GL
// context; every object is freed by its handle.
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "geometry/obj.h"
#include "viewer/gl.h"
#include "geometry/ground_plane.h"

namespace parallax::gpu {

// Texture units: atlas 0, shadow map 1, photos 2..4, projector depth maps 5..7, matcap 8, the
// glare's levels 9. Textures are created on a unit of their own, so making one never
// disturbs what a sampler is bound to.
constexpr int kAtlasUnit = 0, kShadowUnit = 1, kPhotoUnit = 2, kProjectorDepthUnit = 5, kMatcapUnit = 8;
constexpr int kGlareUnit = 9;
constexpr int kScratchUnit = 15;

// A texture created and bound on the scratch unit.
GlTexture MakeTextureOnScratchUnit();

// One vertex of every buffer the viewer draws; unused attributes stay zero.
struct Vertex {
  float position[3];
  float normal[3];
  float uv[2];
  float color[3];
};

// A vertex array over `vertices` with the attribute layout of the shaders.
struct Drawable {
  GlVertexArray vao;
  GlBuffer buffer;
  GLsizei count = 0;
};

Drawable Upload(const std::vector<Vertex>& vertices);

// Homogeneous points (4 floats each) as attribute 0, drawn as triangles; `Replace` refills the
// buffer, e.g. a shadow volume rebuilt for a moved light.
struct HomogeneousTriangles {
  GlVertexArray vao;
  GlBuffer buffer;
  GLsizei count = 0;
  void Replace(const std::vector<Eigen::Vector4f>& points);
};

// A vertex buffer drawn by index.
struct IndexedMesh {
  GlVertexArray vao;
  GlBuffer positions, indices;  // `positions`: the vertex buffer (whole Vertex for the shaded mesh).
  GLsizei count = 0;  // Indices.
};

// A textured mesh at one level of detail, in the three forms the passes draw.
struct GpuMesh {
  Drawable casters;       // Three vertices per triangle with face normals (planar shadows).
  IndexedMesh positions;  // Positions alone, for depth-only passes.
  IndexedMesh shaded;     // Position and atlas coordinate, for the eye's shaded passes.
  GlTexture atlas;        // 0 without an atlas.
  size_t triangles = 0;
};

// `ground` marks each caster triangle with its height above the ground (planar shadows).
GpuMesh UploadMesh(const TriangleMesh& mesh, const std::optional<GroundPlane>& ground);

void SetTextureParameters(GLenum filter, GLenum wrap);

// An sRGB texture of an image (values in [0, 1], sRGB-encoded), top row first; sampling returns
// linear values.
GlTexture UploadSrgbTexture(const Image& image);

// A single-channel float texture of `size` x `size` values, bilinear, clamped to its edge, made
// (or refilled, when `texture` already holds one) on `unit`.
void UploadFloatTexture(GlTexture& texture, const std::vector<float>& texels, int size, int unit);

// An RGBA32F texture (`filter`, clamped to its edge), made on the scratch unit, and a
// framebuffer drawing into it.
struct FloatTarget {
  GlTexture texture;
  GlFramebuffer framebuffer;
};
FloatTarget MakeFloatTarget(int width, int height, GLenum filter);

// A depth texture for hardware comparison, with an FBO that renders into it.
struct DepthTarget {
  GlTexture texture;
  GlFramebuffer framebuffer;
  int width = 0, height = 0;

  void Resize(int new_width, int new_height);
};

// The frame: sRGB-encoded color (RGBA8), auxiliary float RGBA, float depth + stencil; and the
// float frame (RGBA16F linear light) that shares the auxiliary target and the depth, for tone
// mapping into `color`.
struct EyeTarget {
  GlFramebuffer framebuffer, hdr_framebuffer;
  GlTexture color, aux, hdr;
  GlRenderbuffer depth_stencil;
  int width = 0, height = 0;

  void Resize(int new_width, int new_height);
};

}  // namespace parallax::gpu
