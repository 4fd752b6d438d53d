// GLSL programs: compiled and linked from sources embedded in the binary (no asset files to
// lose). A stage that fails to compile, or a program that fails to link, throws ShaderError
// carrying the program's name, the stage, the driver's log and the numbered source, so the
// message alone is enough to fix the shader.
#pragma once

#include <epoxy/gl.h>

#include <initializer_list>
#include <string>
#include <string_view>

#include "app/gl_context.h"
#include "engine/math.h"

namespace ballpit {

class ShaderError : public Error {
 public:
  ShaderError(const std::string& message, std::string log) : Error(message), log_(std::move(log)) {}
  const std::string& log() const { return log_; }

 private:
  std::string log_;
};

struct ShaderStage {
  GLenum type;                 // GL_VERTEX_SHADER, GL_FRAGMENT_SHADER, ...
  std::string_view source;     // without the #version line; "#version 450 core" is prepended
};

class Program {
 public:
  Program() = default;
  Program(std::string_view name, std::initializer_list<ShaderStage> stages);
  ~Program();
  Program(Program&& o) noexcept;
  Program& operator=(Program&& o) noexcept;
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  GLuint id() const { return id_; }
  void use() const { glUseProgram(id_); }
  // Uniform setters by name; a name the linker dropped (unused) is ignored, as GL does.
  void set(const char* name, float v) const;
  void set(const char* name, int v) const;
  void set(const char* name, const Vec3& v) const;
  void set(const char* name, const Vec4& v) const;
  void set(const char* name, const Mat4& m) const;

 private:
  GLint location(const char* name) const { return glGetUniformLocation(id_, name); }
  GLuint id_ = 0;
};

}  // namespace ballpit
