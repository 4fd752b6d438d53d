// An offscreen framebuffer (colour RGBA8 + depth), optionally multisampled and resolved into a
// single-sampled one for reading back. Screenshots, tests and the render benchmark draw into it.
#pragma once

#include <vector>

#include "app/camera.h"
#include "app/gl_objects.h"
#include "app/image.h"

namespace ballpit {

class RenderTarget {
 public:
  // samples 1: no multisampling. Throws ballpit::Error if the driver refuses the format.
  RenderTarget(int width, int height, int samples = 1);

  void bind();  // as the draw framebuffer, with a matching viewport
  // Resolves (when multisampled) and reads the colour back, top row first.
  Image read();
  // Depth buffer values in [0, 1], top row first; only for single-sampled targets.
  std::vector<float> read_depth();
  Viewport viewport() const { return {width_, height_}; }

 private:
  int width_, height_, samples_;
  GlFramebuffer draw_fbo_;
  GlRenderbuffer color_;
  GlRenderbuffer depth_;
  GlFramebuffer resolve_fbo_{nullptr};
  GlRenderbuffer resolve_color_{nullptr};
};

// Reads the bound read framebuffer's colour (a window's back buffer, say), top row first.
Image read_framebuffer(int width, int height);

}  // namespace ballpit
