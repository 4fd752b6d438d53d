#include "app/shader.h"

#include <algorithm>
#include <sstream>
#include <utility>
#include <vector>

namespace ballpit {

namespace {

const char* stage_name(GLenum type) {
  switch (type) {
    case GL_VERTEX_SHADER: return "vertex";
    case GL_FRAGMENT_SHADER: return "fragment";
    case GL_GEOMETRY_SHADER: return "geometry";
    case GL_COMPUTE_SHADER: return "compute";
    default: return "unknown";
  }
}

constexpr std::string_view kVersion = "#version 450 core\n";

std::string numbered(std::string_view source) {
  std::ostringstream out;
  std::istringstream in{std::string(kVersion) + std::string(source)};
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) out << (n < 10 ? "   " : n < 100 ? "  " : " ") << n << "  " << line << '\n';
  return out.str();
}

std::string shader_log(GLuint shader) {
  GLint length = 0;
  glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
  glGetShaderInfoLog(shader, length, nullptr, log.data());
  log.resize(std::char_traits<char>::length(log.c_str()));
  return log;
}

std::string program_log(GLuint program) {
  GLint length = 0;
  glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
  glGetProgramInfoLog(program, length, nullptr, log.data());
  log.resize(std::char_traits<char>::length(log.c_str()));
  return log;
}

}  // namespace

Program::Program(std::string_view name, std::initializer_list<ShaderStage> stages) {
  std::vector<GLuint> shaders;
  auto cleanup = [&] {
    for (GLuint s : shaders) glDeleteShader(s);
  };
  for (const ShaderStage& stage : stages) {
    GLuint shader = glCreateShader(stage.type);
    shaders.push_back(shader);
    const GLchar* parts[] = {kVersion.data(), stage.source.data()};
    const GLint lengths[] = {static_cast<GLint>(kVersion.size()), static_cast<GLint>(stage.source.size())};
    glShaderSource(shader, 2, parts, lengths);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      std::string log = shader_log(shader);
      cleanup();
      throw ShaderError("shader '" + std::string(name) + "': the " + stage_name(stage.type) +
                            " stage failed to compile:\n" + log + "\nsource:\n" + numbered(stage.source),
                        log);
    }
  }
  id_ = glCreateProgram();
  for (GLuint s : shaders) glAttachShader(id_, s);
  glLinkProgram(id_);
  GLint ok = GL_FALSE;
  glGetProgramiv(id_, GL_LINK_STATUS, &ok);
  for (GLuint s : shaders) glDetachShader(id_, s);
  cleanup();
  if (!ok) {
    std::string log = program_log(id_);
    glDeleteProgram(id_);
    id_ = 0;
    throw ShaderError("shader '" + std::string(name) + "': the program failed to link:\n" + log, log);
  }
}

Program::~Program() {
  if (id_) glDeleteProgram(id_);
}

Program::Program(Program&& o) noexcept : id_(std::exchange(o.id_, 0)) {}

Program& Program::operator=(Program&& o) noexcept {
  if (this != &o) {
    if (id_) glDeleteProgram(id_);
    id_ = std::exchange(o.id_, 0);
  }
  return *this;
}

void Program::set(const char* name, float v) const { glProgramUniform1f(id_, location(name), v); }
void Program::set(const char* name, int v) const { glProgramUniform1i(id_, location(name), v); }
void Program::set(const char* name, const Vec3& v) const { glProgramUniform3fv(id_, location(name), 1, v.data()); }
void Program::set(const char* name, const Vec4& v) const { glProgramUniform4fv(id_, location(name), 1, v.data()); }
void Program::set(const char* name, const Mat4& m) const {
  glProgramUniformMatrix4fv(id_, location(name), 1, GL_FALSE, m.data());  // Eigen is column-major, as GL
}

}  // namespace ballpit
