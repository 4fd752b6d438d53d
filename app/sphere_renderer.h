// Draws every sphere in one instanced draw call, either as ray-cast impostors (two triangles a
// sphere; the fragment shader intersects the view ray with the sphere and writes its true
// depth and normal) or as a low-poly icosphere mesh, kept to compare cost and coverage.
// Reads the session's sphere columns (position, radius, colour, entity) and the previous-step
// positions; draws into the bound framebuffer.
// Decision: instance data is pulled from storage buffers by gl_InstanceID. The CPU copies the
// columns verbatim into a persistently mapped region once per physics step; interpolation
// between steps (a lookup of the previous position by entity, since rows are re-sorted every
// step) happens in the vertex shader.
#pragma once

#include <cstdint>
#include <string_view>

#include "app/gl_objects.h"
#include "app/icosphere.h"
#include "app/instance_stream.h"
#include "app/session.h"
#include "app/shader.h"

namespace ballpit {

enum class SphereMode { Impostor, Mesh };
std::string_view to_string(SphereMode m);
// Throws ballpit::Error listing the choices for an unknown name.
SphereMode sphere_mode_from_string(std::string_view name);

class SphereRenderer {
 public:
  SphereRenderer();

  // Copies the columns into the next stream region when their version changed.
  void upload(const SphereRenderState& state);
  // Draws the uploaded spheres, interpolated by `alpha` when a previous step is known.
  void draw(SphereMode mode, float alpha);
  // Fences the region drawn this frame; call once per frame after the last draw.
  void end_frame() { stream_.retire(); }

  std::size_t count() const { return count_; }
  std::size_t triangles_per_sphere(SphereMode mode) const;

 private:
  struct Layout {
    std::size_t position, radius, color, entity, previous, total;
  };
  static Layout layout(std::size_t spheres, std::size_t entities);

  Program impostor_;
  Program mesh_;
  GlVertexArray empty_vao_;
  GlVertexArray mesh_vao_;
  GlBuffer mesh_vertices_;
  GlBuffer mesh_indices_;
  GLsizei mesh_index_count_ = 0;
  InstanceStream stream_;
  Layout current_{};
  std::size_t count_ = 0;
  std::size_t entities_ = 0;
  bool interpolate_ = false;
  std::uint64_t version_ = ~std::uint64_t{0};
};

}  // namespace ballpit
