#include "app/offscreen_context.h"

// epoxy's headers must come before any EGL or GL header.
#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstdio>
#include <vector>

#include "app/gl_context.h"

namespace ballpit {

namespace {

std::string egl_error() {
  char buf[32];
  std::snprintf(buf, sizeof buf, "EGL error 0x%04x", static_cast<unsigned>(eglGetError()));
  return buf;
}

// Surfaceless first (Mesa: llvmpipe or a GPU's render node), then the first EGL device
// (NVIDIA's driver offers no surfaceless platform but renders headless through a device).
EGLDisplay open_display(std::string* platform) {
  if (!epoxy_has_egl()) throw GlUnavailable("no EGL library found (install libegl1 and a driver such as libegl-mesa0)");
  if (epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (d != EGL_NO_DISPLAY && eglInitialize(d, nullptr, nullptr)) {
      *platform = "EGL surfaceless";
      return d;
    }
  }
  if (epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_platform_device") &&
      epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_device_enumeration")) {
    EGLint count = 0;
    eglQueryDevicesEXT(0, nullptr, &count);
    std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(count));
    if (count > 0 && eglQueryDevicesEXT(count, devices.data(), &count)) {
      for (EGLDeviceEXT device : devices) {
        EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
        if (d != EGL_NO_DISPLAY && eglInitialize(d, nullptr, nullptr)) {
          *platform = "EGL device";
          return d;
        }
      }
    }
  }
  throw GlUnavailable("EGL offers neither a surfaceless nor a device platform that initialises (" + egl_error() +
                      "); offscreen rendering needs Mesa (libegl-mesa0) or a GPU driver with EGL");
}

}  // namespace

OffscreenContext::OffscreenContext() {
  std::string platform;
  EGLDisplay display = open_display(&platform);
  display_ = display;
  if (!eglBindAPI(EGL_OPENGL_API)) {
    throw GlUnavailable(platform + ": desktop OpenGL is not available through EGL (" + egl_error() + ")");
  }
  // No config is needed for a context that only draws into framebuffer objects; drivers
  // without EGL_KHR_no_config_context get any config that supports desktop GL.
  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!epoxy_has_egl_extension(display, "EGL_KHR_no_config_context")) {
    const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLint found = 0;
    if (!eglChooseConfig(display, want, &config, 1, &found) || found < 1) {
      throw GlUnavailable(platform + ": no EGL config supports desktop OpenGL (" + egl_error() + ")");
    }
  }
  const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, attributes);
  if (context == EGL_NO_CONTEXT) {
    std::string err = egl_error();
    throw GlUnavailable(platform + ": the driver cannot create an OpenGL 4.5 core context (" + err + ")");
  }
  context_ = context;
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    std::string err = egl_error();
    eglDestroyContext(display, context);
    throw GlUnavailable(platform + ": cannot make a context current without a surface (" + err + ")");
  }
  try {
    description_ = platform + ", " + require_gl45(platform).describe();
  } catch (...) {
    eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display, context);
    throw;
  }
}

// The display stays initialised: EGL shares one display per platform across the process and
// does not count references, so terminating it here would pull it from under other contexts.
OffscreenContext::~OffscreenContext() {
  auto display = static_cast<EGLDisplay>(display_);
  eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(display, static_cast<EGLContext>(context_));
}

void OffscreenContext::make_current() {
  eglMakeCurrent(static_cast<EGLDisplay>(display_), EGL_NO_SURFACE, EGL_NO_SURFACE, static_cast<EGLContext>(context_));
}

}  // namespace ballpit
