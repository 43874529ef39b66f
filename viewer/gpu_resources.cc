#include "viewer/gpu_resources.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>
#include <tuple>

#include <Eigen/Geometry>

namespace parallax::gpu {
namespace {

// The attribute layout of Vertex, for the vertex buffer bound to GL_ARRAY_BUFFER.
void SetVertexLayout() {
  const auto attribute = [](GLuint index, GLint size, size_t offset) {
    glEnableVertexAttribArray(index);
    glVertexAttribPointer(index, size, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<const void*>(offset));
  };
  attribute(0, 3, offsetof(Vertex, position));
  attribute(1, 3, offsetof(Vertex, normal));
  attribute(2, 2, offsetof(Vertex, uv));
  attribute(3, 3, offsetof(Vertex, color));
}

// The mesh's positions, shared between triangles and drawn by index, for depth-only passes
// (the eye's pre-pass, shadow maps, projector depth): a third of the vertex work of the
// per-corner buffer below, a quarter of its bytes. Position 0 is the only attribute.
IndexedMesh UploadPositions(const TriangleMesh& mesh) {
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float) && sizeof(Eigen::Vector3i) == 3 * sizeof(GLuint),
                "uploaded as packed arrays");
  IndexedMesh d{MakeGlVertexArray(), MakeGlBuffer(), MakeGlBuffer(), static_cast<GLsizei>(mesh.triangles.size() * 3)};
  glBindVertexArray(d.vao.Get());
  glBindBuffer(GL_ARRAY_BUFFER, d.positions.Get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.vertices.size() * sizeof(float) * 3),
               mesh.vertices.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, d.indices.Get());
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.triangles.size() * sizeof(int) * 3),
               mesh.triangles.data(), GL_STATIC_DRAW);
  glBindVertexArray(0);
  return d;
}

// Unit face normals (zero for a degenerate triangle).
std::vector<Eigen::Vector3f> FaceNormals(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3f> normals;
  normals.reserve(mesh.triangles.size());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3f n = (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    normals.push_back(n.norm() > 0 ? Eigen::Vector3f(n.normalized()) : Eigen::Vector3f::Zero());
  }
  return normals;
}

// A normal per triangle corner, smooth across edges flatter than kCreaseDeg and sharp across
// the others (a box keeps its edges, a Poisson pillar loses its facets): the mean of the normals
// of the corner vertex's faces within the crease angle of this face. Windings of reconstructed
// meshes are not consistent, so a face pointing the other way counts with its sign flipped.
std::vector<Eigen::Vector3f> CornerNormals(const TriangleMesh& mesh) {
  constexpr float kCreaseDeg = 40;
  const float crease_cos = std::cos(kCreaseDeg * std::numbers::pi_v<float> / 180);
  const std::vector<Eigen::Vector3f> face = FaceNormals(mesh);
  // The faces around each vertex, as compressed rows.
  std::vector<int> first(mesh.vertices.size() + 1, 0), faces(mesh.triangles.size() * 3);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int c = 0; c < 3; ++c) ++first[static_cast<size_t>(t[c]) + 1];
  }
  for (size_t v = 0; v < mesh.vertices.size(); ++v) first[v + 1] += first[v];
  std::vector<int> filled(first.begin(), first.end() - 1);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int c = 0; c < 3; ++c) faces[static_cast<size_t>(filled[static_cast<size_t>(mesh.triangles[t][c])]++)] = static_cast<int>(t);
  }
  std::vector<Eigen::Vector3f> normals(mesh.triangles.size() * 3, Eigen::Vector3f::Zero());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int c = 0; c < 3; ++c) {
      const size_t v = static_cast<size_t>(mesh.triangles[t][c]);
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      for (int i = first[v]; i < first[v + 1]; ++i) {
        const Eigen::Vector3f& other = face[static_cast<size_t>(faces[static_cast<size_t>(i)])];
        const float cosine = other.dot(face[t]);
        if (std::abs(cosine) >= crease_cos) sum += cosine > 0 ? other : Eigen::Vector3f(-other);
      }
      normals[3 * t + c] = sum.norm() > 0 ? Eigen::Vector3f(sum.normalized()) : face[t];
    }
  }
  return normals;
}

// The mesh for the eye's shaded pass: a vertex per distinct (position, atlas coordinate, corner
// normal), drawn by index, so triangles inside an atlas chart and a smooth patch share their
// corners and llvmpipe shades fewer vertices.
IndexedMesh UploadShadedMesh(const TriangleMesh& mesh) {
  const std::vector<Eigen::Vector3f> normals = CornerNormals(mesh);
  std::vector<Vertex> vertices;
  std::vector<GLuint> indices;
  indices.reserve(mesh.triangles.size() * 3);
  const bool has_uv = mesh.corner_uvs.size() == mesh.triangles.size() * 3;
  std::map<std::tuple<int, float, float, float, float, float>, GLuint> index_of;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int c = 0; c < 3; ++c) {
      const int v = mesh.triangles[t][c];
      const Eigen::Vector2f uv = has_uv ? mesh.corner_uvs[3 * t + c] : Eigen::Vector2f(0.5f, 0.5f);
      const Eigen::Vector3f& n = normals[3 * t + c];
      const auto [found, inserted] =
          index_of.try_emplace({v, uv.x(), uv.y(), n.x(), n.y(), n.z()}, static_cast<GLuint>(vertices.size()));
      if (inserted) {
        const Eigen::Vector3f& p = mesh.vertices[v];
        vertices.push_back({{p.x(), p.y(), p.z()}, {n.x(), n.y(), n.z()}, {uv.x(), 1 - uv.y()}, {0, 0, 0}});
      }
      indices.push_back(found->second);
    }
  }
  IndexedMesh d{MakeGlVertexArray(), MakeGlBuffer(), MakeGlBuffer(), static_cast<GLsizei>(indices.size())};
  glBindVertexArray(d.vao.Get());
  glBindBuffer(GL_ARRAY_BUFFER, d.positions.Get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)), vertices.data(), GL_STATIC_DRAW);
  SetVertexLayout();
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, d.indices.Get());
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(GLuint)), indices.data(), GL_STATIC_DRAW);
  glBindVertexArray(0);
  return d;
}

// The planar shadow casters' mesh: three vertices per triangle, each with its face normal and
// its corner's atlas coordinate (t = 1 - v: the atlas is uploaded top row first). color.x of a
// mesh vertex holds its triangle's greatest height above the ground, so planar shadows can drop
// the ground's own triangles without also dropping the foot of a wall.
std::vector<Vertex> MeshVertices(const TriangleMesh& mesh, const std::optional<GroundPlane>& ground) {
  const std::vector<Eigen::Vector3f> normals = FaceNormals(mesh);
  std::vector<Vertex> vertices;
  vertices.reserve(mesh.triangles.size() * 3);
  const bool has_uv = mesh.corner_uvs.size() == mesh.triangles.size() * 3;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    const Eigen::Vector3f& normal = normals[t];
    float max_height = 0;
    for (int c = 0; c < 3 && ground; ++c) {
      max_height = std::max(max_height, static_cast<float>(ground->SignedDistance(mesh.vertices[tri[c]].cast<double>())));
    }
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3f& p = mesh.vertices[tri[c]];
      const Eigen::Vector2f uv = has_uv ? mesh.corner_uvs[3 * t + c] : Eigen::Vector2f(0.5f, 0.5f);
      vertices.push_back({{p.x(), p.y(), p.z()}, {normal.x(), normal.y(), normal.z()},
                          {uv.x(), 1 - uv.y()}, {max_height, 0, 0}});
    }
  }
  return vertices;
}

}  // namespace

GlTexture MakeTextureOnScratchUnit() {
  glActiveTexture(GL_TEXTURE0 + kScratchUnit);
  GlTexture texture = MakeGlTexture();
  glBindTexture(GL_TEXTURE_2D, texture.Get());
  return texture;
}

Drawable Upload(const std::vector<Vertex>& vertices) {
  Drawable d{MakeGlVertexArray(), MakeGlBuffer(), static_cast<GLsizei>(vertices.size())};
  glBindVertexArray(d.vao.Get());
  glBindBuffer(GL_ARRAY_BUFFER, d.buffer.Get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)),
               vertices.data(), GL_STATIC_DRAW);
  SetVertexLayout();
  glBindVertexArray(0);
  return d;
}

void HomogeneousTriangles::Replace(const std::vector<Eigen::Vector4f>& points) {
  static_assert(sizeof(Eigen::Vector4f) == 4 * sizeof(float), "uploaded as a packed array");
  if (vao.Get() == 0) {
    vao = MakeGlVertexArray();
    buffer = MakeGlBuffer();
  }
  glBindVertexArray(vao.Get());
  glBindBuffer(GL_ARRAY_BUFFER, buffer.Get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(points.size() * sizeof(Eigen::Vector4f)), points.data(),
               GL_DYNAMIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, sizeof(Eigen::Vector4f), nullptr);
  glBindVertexArray(0);
  count = static_cast<GLsizei>(points.size());
}

GpuMesh UploadMesh(const TriangleMesh& mesh, const std::optional<GroundPlane>& ground) {
  GpuMesh uploaded;
  if (mesh.triangles.empty()) return uploaded;
  uploaded.casters = Upload(MeshVertices(mesh, ground));
  uploaded.positions = UploadPositions(mesh);
  uploaded.shaded = UploadShadedMesh(mesh);
  if (!mesh.atlas.Empty()) uploaded.atlas = UploadSrgbTexture(mesh.atlas);
  uploaded.triangles = mesh.triangles.size();
  return uploaded;
}

FloatTarget MakeFloatTarget(int width, int height, GLenum filter) {
  FloatTarget target{MakeTextureOnScratchUnit(), MakeGlFramebuffer()};
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
  SetTextureParameters(filter, GL_CLAMP_TO_EDGE);
  glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer.Get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, target.texture.Get(), 0);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw std::runtime_error("GL: float frame buffer incomplete");
  }
  return target;
}

void SetTextureParameters(GLenum filter, GLenum wrap) {
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(filter));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, static_cast<GLint>(filter));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, static_cast<GLint>(wrap));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, static_cast<GLint>(wrap));
}

GlTexture UploadSrgbTexture(const Image& image) {
  std::vector<uint8_t> bytes(static_cast<size_t>(image.Width()) * image.Height() * 3);
  for (int y = 0; y < image.Height(); ++y) {
    for (int x = 0; x < image.Width(); ++x) {
      for (int c = 0; c < 3; ++c) {
        const float value = image.At(x, y, std::min(c, image.Channels() - 1));
        bytes[(static_cast<size_t>(y) * image.Width() + x) * 3 + c] =
            static_cast<uint8_t>(std::lround(std::clamp(value, 0.0f, 1.0f) * 255));
      }
    }
  }
  GlTexture texture = MakeTextureOnScratchUnit();
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_SRGB8, image.Width(), image.Height(), 0, GL_RGB,
               GL_UNSIGNED_BYTE, bytes.data());
  glGenerateMipmap(GL_TEXTURE_2D);
  SetTextureParameters(GL_LINEAR, GL_CLAMP_TO_EDGE);
  // Bilinear in the nearest mip level: half the texel fetches of trilinear, and nearly the
  // same image.
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_NEAREST);
  return texture;
}

void UploadFloatTexture(GlTexture& texture, const std::vector<float>& texels, int size, int unit) {
  glActiveTexture(GL_TEXTURE0 + unit);
  if (texture.Get() == 0) texture = MakeGlTexture();
  glBindTexture(GL_TEXTURE_2D, texture.Get());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, size, size, 0, GL_RED, GL_FLOAT, texels.data());
  SetTextureParameters(GL_LINEAR, GL_CLAMP_TO_EDGE);
  glActiveTexture(GL_TEXTURE0);
}

void DepthTarget::Resize(int new_width, int new_height) {
  if (width == new_width && height == new_height && texture.Get() != 0) return;
  width = new_width;
  height = new_height;
  texture = MakeTextureOnScratchUnit();
  glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, width, height, 0, GL_DEPTH_COMPONENT,
               GL_FLOAT, nullptr);
  SetTextureParameters(GL_LINEAR, GL_CLAMP_TO_BORDER);
  // Outside the map is lit: border depth 1 never occludes.
  const float border[4] = {1, 1, 1, 1};
  glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, border);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  framebuffer = MakeGlFramebuffer();
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.Get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, texture.Get(), 0);
  glDrawBuffer(GL_NONE);
  glReadBuffer(GL_NONE);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw std::runtime_error("GL: depth framebuffer incomplete");
  }
}

void EyeTarget::Resize(int new_width, int new_height) {
  if (width == new_width && height == new_height && framebuffer.Get() != 0) return;
  width = new_width;
  height = new_height;
  color = MakeTextureOnScratchUnit();
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  SetTextureParameters(GL_NEAREST, GL_CLAMP_TO_EDGE);
  aux = MakeTextureOnScratchUnit();
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
  SetTextureParameters(GL_NEAREST, GL_CLAMP_TO_EDGE);
  depth_stencil = MakeGlRenderbuffer();
  glBindRenderbuffer(GL_RENDERBUFFER, depth_stencil.Get());
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH32F_STENCIL8, width, height);
  framebuffer = MakeGlFramebuffer();
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.Get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color.Get(), 0);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, aux.Get(), 0);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER,
                            depth_stencil.Get());
  const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glDrawBuffers(2, buffers);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw std::runtime_error("GL: frame buffer incomplete");
  }
  hdr = MakeTextureOnScratchUnit();
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
  SetTextureParameters(GL_LINEAR, GL_CLAMP_TO_EDGE);
  hdr_framebuffer = MakeGlFramebuffer();
  glBindFramebuffer(GL_FRAMEBUFFER, hdr_framebuffer.Get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, hdr.Get(), 0);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, aux.Get(), 0);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, depth_stencil.Get());
  glDrawBuffers(2, buffers);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw std::runtime_error("GL: float frame buffer incomplete");
  }
}

}  // namespace parallax::gpu
