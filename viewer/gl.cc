#include "viewer/gl.h"

#include <cstdio>
#include <stdexcept>
#include <vector>

namespace parallax {
namespace {

GLuint CompileShader(const std::string& name, GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(static_cast<size_t>(length) + 1, '\0');
    glGetShaderInfoLog(shader, length, nullptr, log.data());
    glDeleteShader(shader);
    throw std::runtime_error("GL: shader '" + name + "' (" +
                             (type == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                             ") does not compile: " + log.data());
  }
  return shader;
}

}  // namespace

GlBuffer MakeGlBuffer() {
  GLuint name = 0;
  glGenBuffers(1, &name);
  return GlBuffer(name);
}
GlVertexArray MakeGlVertexArray() {
  GLuint name = 0;
  glGenVertexArrays(1, &name);
  return GlVertexArray(name);
}
GlTexture MakeGlTexture() {
  GLuint name = 0;
  glGenTextures(1, &name);
  return GlTexture(name);
}
GlFramebuffer MakeGlFramebuffer() {
  GLuint name = 0;
  glGenFramebuffers(1, &name);
  return GlFramebuffer(name);
}
GlRenderbuffer MakeGlRenderbuffer() {
  GLuint name = 0;
  glGenRenderbuffers(1, &name);
  return GlRenderbuffer(name);
}

GlProgram::GlProgram(const std::string& name, const char* vertex_source,
                     const char* fragment_source) {
  const GLuint vertex = CompileShader(name, GL_VERTEX_SHADER, vertex_source);
  const GLuint fragment = CompileShader(name, GL_FRAGMENT_SHADER, fragment_source);
  program_ = GlObject<DeleteGlProgram>(glCreateProgram());
  glAttachShader(program_.Get(), vertex);
  glAttachShader(program_.Get(), fragment);
  glLinkProgram(program_.Get());
  glDeleteShader(vertex);  // Flagged for deletion; freed with the program.
  glDeleteShader(fragment);
  GLint ok = 0;
  glGetProgramiv(program_.Get(), GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetProgramiv(program_.Get(), GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(static_cast<size_t>(length) + 1, '\0');
    glGetProgramInfoLog(program_.Get(), length, nullptr, log.data());
    throw std::runtime_error("GL: program '" + name + "' does not link: " + log.data());
  }
}

GLint GlProgram::Location(const char* uniform) const {
  return glGetUniformLocation(program_.Get(), uniform);
}
void GlProgram::Set(const char* uniform, int value) const { glUniform1i(Location(uniform), value); }
void GlProgram::Set(const char* uniform, float value) const {
  glUniform1f(Location(uniform), value);
}
void GlProgram::Set(const char* uniform, const Eigen::Vector2f& value) const {
  glUniform2fv(Location(uniform), 1, value.data());
}
void GlProgram::Set(const char* uniform, const Eigen::Vector3f& value) const {
  glUniform3fv(Location(uniform), 1, value.data());
}
void GlProgram::Set(const char* uniform, const Eigen::Vector4f& value) const {
  glUniform4fv(Location(uniform), 1, value.data());
}
void GlProgram::Set(const char* uniform, const Eigen::Matrix4f& value) const {
  glUniformMatrix4fv(Location(uniform), 1, GL_FALSE, value.data());  // Eigen is column-major.
}

void CheckGlError(const char* where) {
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) {
    throw std::runtime_error(std::string("GL error 0x") + [&] {
      char hex[16];
      std::snprintf(hex, sizeof(hex), "%04x", error);
      return std::string(hex);
    }() + " in " + where);
  }
}

}  // namespace parallax
