// Owning handles for OpenGL object names: each deletes its name when it goes out of scope, so
// a renderer is a plain struct of members and a failed constructor leaks nothing. Move-only.
// Needs a current context for both creation and destruction.
#pragma once

#include <epoxy/gl.h>

#include <utility>

namespace ballpit {

template <void (*Create)(GLuint*), void (*Destroy)(GLuint)>
class GlName {
 public:
  GlName() { Create(&id_); }
  explicit GlName(std::nullptr_t) {}
  ~GlName() {
    if (id_) Destroy(id_);
  }
  GlName(GlName&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  GlName& operator=(GlName&& o) noexcept {
    if (this != &o) {
      if (id_) Destroy(id_);
      id_ = std::exchange(o.id_, 0);
    }
    return *this;
  }
  GlName(const GlName&) = delete;
  GlName& operator=(const GlName&) = delete;
  GLuint id() const { return id_; }

 private:
  GLuint id_ = 0;
};

namespace gl_detail {
inline void create_buffer(GLuint* id) { glCreateBuffers(1, id); }
inline void delete_buffer(GLuint id) { glDeleteBuffers(1, &id); }
inline void create_vertex_array(GLuint* id) { glCreateVertexArrays(1, id); }
inline void delete_vertex_array(GLuint id) { glDeleteVertexArrays(1, &id); }
inline void create_framebuffer(GLuint* id) { glCreateFramebuffers(1, id); }
inline void delete_framebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
inline void create_renderbuffer(GLuint* id) { glCreateRenderbuffers(1, id); }
inline void delete_renderbuffer(GLuint id) { glDeleteRenderbuffers(1, &id); }
inline void create_query(GLuint* id) { glCreateQueries(GL_TIME_ELAPSED, 1, id); }
inline void delete_query(GLuint id) { glDeleteQueries(1, &id); }
}  // namespace gl_detail

using GlBuffer = GlName<gl_detail::create_buffer, gl_detail::delete_buffer>;
using GlVertexArray = GlName<gl_detail::create_vertex_array, gl_detail::delete_vertex_array>;
using GlFramebuffer = GlName<gl_detail::create_framebuffer, gl_detail::delete_framebuffer>;
using GlRenderbuffer = GlName<gl_detail::create_renderbuffer, gl_detail::delete_renderbuffer>;
using GlTimerQuery = GlName<gl_detail::create_query, gl_detail::delete_query>;

}  // namespace ballpit
