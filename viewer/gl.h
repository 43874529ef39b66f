#pragma once
// OpenGL 3.3 core without a loader: Mesa's libOpenGL exports every entry point, so the
// prototypes of <GL/glcorearb.h> link directly (docs/design.md, "Headless rendering"). Small RAII
// owners for GL objects and a shader program with uniform setters.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <string>
#include <utility>

#include <Eigen/Core>

namespace parallax {

// Owns one GL object name; `Delete` frees it (glDeleteBuffers and friends take a count).
template <void (*Delete)(GLuint)>
class GlObject {
 public:
  GlObject() = default;
  explicit GlObject(GLuint name) : name_(name) {}
  ~GlObject() { Reset(); }
  GlObject(GlObject&& other) noexcept : name_(std::exchange(other.name_, 0)) {}
  GlObject& operator=(GlObject&& other) noexcept {
    if (this != &other) {
      Reset();
      name_ = std::exchange(other.name_, 0);
    }
    return *this;
  }
  GlObject(const GlObject&) = delete;
  GlObject& operator=(const GlObject&) = delete;

  GLuint Get() const { return name_; }
  void Reset() {
    if (name_ != 0) Delete(name_);
    name_ = 0;
  }

 private:
  GLuint name_ = 0;
};

inline void DeleteGlBuffer(GLuint name) { glDeleteBuffers(1, &name); }
inline void DeleteGlVertexArray(GLuint name) { glDeleteVertexArrays(1, &name); }
inline void DeleteGlTexture(GLuint name) { glDeleteTextures(1, &name); }
inline void DeleteGlFramebuffer(GLuint name) { glDeleteFramebuffers(1, &name); }
inline void DeleteGlRenderbuffer(GLuint name) { glDeleteRenderbuffers(1, &name); }
inline void DeleteGlProgram(GLuint name) { glDeleteProgram(name); }

using GlBuffer = GlObject<DeleteGlBuffer>;
using GlVertexArray = GlObject<DeleteGlVertexArray>;
using GlTexture = GlObject<DeleteGlTexture>;
using GlFramebuffer = GlObject<DeleteGlFramebuffer>;
using GlRenderbuffer = GlObject<DeleteGlRenderbuffer>;

GlBuffer MakeGlBuffer();
GlVertexArray MakeGlVertexArray();
GlTexture MakeGlTexture();
GlFramebuffer MakeGlFramebuffer();
GlRenderbuffer MakeGlRenderbuffer();

// A linked vertex + fragment shader. Throws std::runtime_error with the GL info log (and the
// program's `name`) when compiling or linking fails.
class GlProgram {
 public:
  GlProgram() = default;
  GlProgram(const std::string& name, const char* vertex_source, const char* fragment_source);

  void Use() const { glUseProgram(program_.Get()); }
  // Setters on the program in use; a uniform the linker optimised away is ignored.
  void Set(const char* uniform, int value) const;
  void Set(const char* uniform, float value) const;
  void Set(const char* uniform, const Eigen::Vector2f& value) const;
  void Set(const char* uniform, const Eigen::Vector3f& value) const;
  void Set(const char* uniform, const Eigen::Vector4f& value) const;
  void Set(const char* uniform, const Eigen::Matrix4f& value) const;

 private:
  GLint Location(const char* uniform) const;
  GlObject<DeleteGlProgram> program_;
};

// Throws std::runtime_error naming `where` and the GL error code if one is pending.
void CheckGlError(const char* where);

}  // namespace parallax
