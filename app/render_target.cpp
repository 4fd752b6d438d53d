#include "app/render_target.h"

#include <cstring>
#include <string>

#include "engine/error.h"

namespace ballpit {

namespace {

void require_complete(GLuint fbo, const char* what) {
  GLenum status = glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw Error(std::string("OpenGL: the ") + what + " framebuffer is incomplete (status 0x" +
                std::to_string(status) + ")");
}

}  // namespace

RenderTarget::RenderTarget(int width, int height, int samples) : width_(width), height_(height), samples_(samples) {
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    throw Error("render target size " + std::to_string(width) + "x" + std::to_string(height) +
                " is out of range (1..16384 pixels a side)");
  if (samples_ > 1) {
    glNamedRenderbufferStorageMultisample(color_.id(), samples_, GL_RGBA8, width, height);
    glNamedRenderbufferStorageMultisample(depth_.id(), samples_, GL_DEPTH_COMPONENT32F, width, height);
  } else {
    glNamedRenderbufferStorage(color_.id(), GL_RGBA8, width, height);
    glNamedRenderbufferStorage(depth_.id(), GL_DEPTH_COMPONENT32F, width, height);
  }
  glNamedFramebufferRenderbuffer(draw_fbo_.id(), GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_.id());
  glNamedFramebufferRenderbuffer(draw_fbo_.id(), GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_.id());
  require_complete(draw_fbo_.id(), "offscreen");
  if (samples_ > 1) {
    resolve_fbo_ = GlFramebuffer();
    resolve_color_ = GlRenderbuffer();
    glNamedRenderbufferStorage(resolve_color_.id(), GL_RGBA8, width, height);
    glNamedFramebufferRenderbuffer(resolve_fbo_.id(), GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolve_color_.id());
    require_complete(resolve_fbo_.id(), "resolve");
  }
}

void RenderTarget::bind() {
  glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_.id());
  glViewport(0, 0, width_, height_);
}

Image RenderTarget::read() {
  GLuint source = draw_fbo_.id();
  if (samples_ > 1) {
    glBlitNamedFramebuffer(draw_fbo_.id(), resolve_fbo_.id(), 0, 0, width_, height_, 0, 0, width_, height_,
                           GL_COLOR_BUFFER_BIT, GL_NEAREST);
    source = resolve_fbo_.id();
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, source);
  Image image = read_framebuffer(width_, height_);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  return image;
}

std::vector<float> RenderTarget::read_depth() {
  if (samples_ > 1) throw Error("read_depth: multisampled depth cannot be read back directly");
  std::vector<float> bottom_up(static_cast<std::size_t>(width_) * height_);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_fbo_.id());
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, width_, height_, GL_DEPTH_COMPONENT, GL_FLOAT, bottom_up.data());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  std::vector<float> depth(bottom_up.size());
  const std::size_t row = static_cast<std::size_t>(width_);
  for (int y = 0; y < height_; ++y)
    std::memcpy(&depth[static_cast<std::size_t>(y) * row], &bottom_up[static_cast<std::size_t>(height_ - 1 - y) * row],
                row * sizeof(float));
  return depth;
}

Image read_framebuffer(int width, int height) {
  Image image;
  image.width = width;
  image.height = height;
  image.rgba.resize(static_cast<std::size_t>(width) * height * 4);
  std::vector<std::uint8_t> bottom_up(image.rgba.size());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
  const std::size_t row = static_cast<std::size_t>(width) * 4;
  for (int y = 0; y < height; ++y)
    std::memcpy(&image.rgba[static_cast<std::size_t>(y) * row], &bottom_up[static_cast<std::size_t>(height - 1 - y) * row], row);
  // The alpha channel holds whatever blending left; a screenshot is opaque.
  for (std::size_t i = 3; i < image.rgba.size(); i += 4) image.rgba[i] = 255;
  return image;
}

}  // namespace ballpit
