#include "app/gl_context.h"

#include <epoxy/gl.h>

#include <cstdio>

namespace ballpit {

namespace {

std::string gl_string(GLenum name) {
  const GLubyte* s = glGetString(name);
  return s ? reinterpret_cast<const char*>(s) : "(unknown)";
}

void GLAPIENTRY on_gl_message(GLenum, GLenum type, GLuint, GLenum severity, GLsizei, const GLchar* message,
                              const void*) {
  if (severity == GL_DEBUG_SEVERITY_NOTIFICATION || type == GL_DEBUG_TYPE_PERFORMANCE) return;
  std::fprintf(stderr, "ballpit: OpenGL %s: %s\n", type == GL_DEBUG_TYPE_ERROR ? "error" : "warning", message);
}

}  // namespace

GlInfo require_gl45(const std::string& how) {
  GlInfo info;
  info.vendor = gl_string(GL_VENDOR);
  info.renderer = gl_string(GL_RENDERER);
  info.version = gl_string(GL_VERSION);
  info.version_number = epoxy_gl_version();
  GLint profile = 0;
  if (info.version_number >= 32) glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
  if (!epoxy_is_desktop_gl() || info.version_number < 45 || !(profile & GL_CONTEXT_CORE_PROFILE_BIT)) {
    throw GlUnavailable("OpenGL 4.5 core profile is required, but " + how + " gave " + info.describe() +
                        ". Update the graphics driver, or use Mesa's llvmpipe (LIBGL_ALWAYS_SOFTWARE=1).");
  }
  return info;
}

bool is_software_renderer() {
  const std::string r = gl_string(GL_RENDERER);
  return r.find("llvmpipe") != std::string::npos || r.find("softpipe") != std::string::npos;
}

void install_gl_debug_output() {
  glEnable(GL_DEBUG_OUTPUT);
  glDebugMessageCallback(on_gl_message, nullptr);
}

}  // namespace ballpit
