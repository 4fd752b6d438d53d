#include "app/sphere_renderer.h"

#include <string>

#include "app/frame_uniforms.h"
#include "engine/error.h"

namespace ballpit {

namespace {

// Instance columns, pulled by gl_InstanceID. Positions are tightly packed vec3 (12 bytes, as
// the sphere table stores them), so they are read as floats.
constexpr const char* kInstanceGlsl = R"glsl(
layout(std430, binding = 0) readonly buffer Positions { float b_position[]; };
layout(std430, binding = 1) readonly buffer Radii { float b_radius[]; };
layout(std430, binding = 2) readonly buffer Colors { uint b_color[]; };
layout(std430, binding = 3) readonly buffer Entities { uint b_entity[]; };
layout(std430, binding = 4) readonly buffer Previous { float b_previous[]; };
uniform float u_alpha;        // 0: previous step, 1: latest step
uniform int u_interpolate;    // 0 when no previous step is known

vec3 instance_center(int i) {
  vec3 c = vec3(b_position[3 * i], b_position[3 * i + 1], b_position[3 * i + 2]);
  if (u_interpolate != 0) {
    uint e = b_entity[i];
    vec3 p = vec3(b_previous[3 * e], b_previous[3 * e + 1], b_previous[3 * e + 2]);
    c = mix(p, c, u_alpha);
  }
  return c;
}
vec3 instance_albedo(int i) { return srgb_to_linear(unpackUnorm4x8(b_color[i]).rgb); }
)glsl";

// The impostor: a square facing the eye, at the sphere's nearest depth, exactly covering the
// cone from the eye that touches the sphere; every sphere point is behind it, which is what
// lets the fragment shader promise depth_greater and keep early depth rejection.
constexpr const char* kImpostorVertex = R"glsl(
out vec3 v_ray;                 // view-space point on the square: the ray direction
flat out vec3 v_center;         // view space
flat out float v_radius;
flat out vec3 v_albedo;
void main() {
  int i = gl_InstanceID;
  vec3 c = (u_view * vec4(instance_center(i), 1.0)).xyz;
  float r = b_radius[i];
  float d = length(c);
  v_center = c;
  v_radius = r;
  v_albedo = instance_albedo(i);
  if (d <= r * 1.001) {         // the eye is inside: nothing sensible to draw
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    v_ray = vec3(0.0);
    return;
  }
  vec3 axis = c / d;
  vec3 helper = abs(axis.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
  vec3 right = normalize(cross(axis, helper));
  vec3 up = cross(right, axis);
  float t = d - r;                              // nearest sphere depth along the axis
  float half_size = t * r / sqrt(d * d - r * r);  // cone radius there
  vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0;
  v_ray = axis * t + (right * corner.x + up * corner.y) * half_size;
  gl_Position = u_projection * vec4(v_ray, 1.0);
}
)glsl";

constexpr const char* kImpostorFragment = R"glsl(
in vec3 v_ray;
flat in vec3 v_center;
flat in float v_radius;
flat in vec3 v_albedo;
layout(depth_greater) out float gl_FragDepth;
out vec4 o_color;
void main() {
  vec3 dir = normalize(v_ray);
  // Closest approach of the ray to the centre, measured from the centre: subtracting two
  // nearly equal distances (b*b - |c|^2) would lose the radius to rounding at 1M-ball
  // camera distances.
  float b = dot(dir, v_center);
  vec3 off = dir * b - v_center;
  float h = v_radius * v_radius - dot(off, off);
  if (h < 0.0) discard;
  vec3 p = dir * (b - sqrt(h));
  vec3 n_view = (p - v_center) / v_radius;
  vec4 clip = u_projection * vec4(p, 1.0);
  gl_FragDepth = clip.z / clip.w * 0.5 + 0.5;
  vec3 p_world = (u_view_inverse * vec4(p, 1.0)).xyz;
  vec3 n = normalize(mat3(u_view_inverse) * n_view);
  float occlusion = depth_occlusion(p_world) * mix(0.55, 1.0, 0.5 + 0.5 * n.y);
  o_color = vec4(linear_to_srgb(shade(v_albedo, n, p_world, occlusion, 48.0, 0.35)), 1.0);
}
)glsl";

constexpr const char* kMeshVertex = R"glsl(
layout(location = 0) in vec3 a_position;   // unit icosphere (volume-matched)
out vec3 v_world;
out vec3 v_normal;
flat out vec3 v_albedo;
void main() {
  int i = gl_InstanceID;
  v_world = instance_center(i) + a_position * b_radius[i];
  v_normal = a_position;
  v_albedo = instance_albedo(i);
  gl_Position = u_projection * u_view * vec4(v_world, 1.0);
}
)glsl";

constexpr const char* kMeshFragment = R"glsl(
in vec3 v_world;
in vec3 v_normal;
flat in vec3 v_albedo;
out vec4 o_color;
void main() {
  vec3 n = normalize(v_normal);
  float occlusion = depth_occlusion(v_world) * mix(0.55, 1.0, 0.5 + 0.5 * n.y);
  o_color = vec4(linear_to_srgb(shade(v_albedo, n, v_world, occlusion, 48.0, 0.35)), 1.0);
}
)glsl";

std::string join(const char* a, const char* b, const char* c) { return std::string(a) + b + c; }

constexpr std::size_t align256(std::size_t n) { return (n + 255) & ~std::size_t{255}; }

}  // namespace

std::string_view to_string(SphereMode m) { return m == SphereMode::Impostor ? "impostor" : "mesh"; }

SphereMode sphere_mode_from_string(std::string_view name) {
  if (name == "impostor") return SphereMode::Impostor;
  if (name == "mesh") return SphereMode::Mesh;
  throw Error("unknown sphere renderer '" + std::string(name) + "' (known: impostor, mesh)");
}

SphereRenderer::SphereRenderer() {
  const std::string impostor_vs = join(kFrameGlsl, kInstanceGlsl, kImpostorVertex);
  const std::string impostor_fs = join(kFrameGlsl, "", kImpostorFragment);
  impostor_ = Program("sphere impostor", {{GL_VERTEX_SHADER, impostor_vs}, {GL_FRAGMENT_SHADER, impostor_fs}});
  const std::string mesh_vs = join(kFrameGlsl, kInstanceGlsl, kMeshVertex);
  const std::string mesh_fs = join(kFrameGlsl, "", kMeshFragment);
  mesh_ = Program("sphere mesh", {{GL_VERTEX_SHADER, mesh_vs}, {GL_FRAGMENT_SHADER, mesh_fs}});

  IcosphereMesh ico = make_icosphere(1);
  glNamedBufferStorage(mesh_vertices_.id(), static_cast<GLsizeiptr>(ico.positions.size() * sizeof(Vec3)),
                       ico.positions.data(), 0);
  glNamedBufferStorage(mesh_indices_.id(), static_cast<GLsizeiptr>(ico.indices.size() * sizeof(std::uint16_t)),
                       ico.indices.data(), 0);
  mesh_index_count_ = static_cast<GLsizei>(ico.indices.size());
  const GLuint vao = mesh_vao_.id();
  glVertexArrayVertexBuffer(vao, 0, mesh_vertices_.id(), 0, sizeof(Vec3));
  glVertexArrayElementBuffer(vao, mesh_indices_.id());
  glEnableVertexArrayAttrib(vao, 0);
  glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vao, 0, 0);
}

SphereRenderer::Layout SphereRenderer::layout(std::size_t spheres, std::size_t entities) {
  Layout l{};
  std::size_t at = 0;
  l.position = at;
  at = align256(at + spheres * sizeof(Vec3));
  l.radius = at;
  at = align256(at + spheres * sizeof(float));
  l.color = at;
  at = align256(at + spheres * sizeof(std::uint32_t));
  l.entity = at;
  at = align256(at + spheres * sizeof(std::uint32_t));
  l.previous = at;
  at = align256(at + std::max<std::size_t>(entities, 1) * sizeof(Vec3));
  l.total = at;
  return l;
}

void SphereRenderer::upload(const SphereRenderState& s) {
  if (s.version == version_) return;
  version_ = s.version;
  count_ = s.position.size();
  interpolate_ = !s.previous_by_entity.empty();
  entities_ = interpolate_ ? s.previous_by_entity.size() : 0;
  if (count_ == 0) return;
  current_ = layout(count_, entities_);
  // A quarter more than needed, so pouring balls in does not reallocate every time.
  if (current_.total > stream_.region_bytes()) stream_.reserve(current_.total + current_.total / 4);
  std::byte* region = stream_.acquire();
  parallel_copy(region + current_.position, s.position.data(), count_ * sizeof(Vec3));
  parallel_copy(region + current_.radius, s.radius.data(), count_ * sizeof(float));
  parallel_copy(region + current_.color, s.color.data(), count_ * sizeof(std::uint32_t));
  if (interpolate_) {
    parallel_copy(region + current_.entity, s.entity.data(), count_ * sizeof(std::uint32_t));
    parallel_copy(region + current_.previous, s.previous_by_entity.data(), entities_ * sizeof(Vec3));
  }
}

void SphereRenderer::draw(SphereMode mode, float alpha) {
  if (count_ == 0) return;
  const GLuint buffer = stream_.buffer();
  const GLintptr base = stream_.offset();
  auto bind = [&](GLuint index, std::size_t offset, std::size_t bytes) {
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, index, buffer, base + static_cast<GLintptr>(offset),
                      static_cast<GLsizeiptr>(bytes));
  };
  bind(0, current_.position, count_ * sizeof(Vec3));
  bind(1, current_.radius, count_ * sizeof(float));
  bind(2, current_.color, count_ * sizeof(std::uint32_t));
  // Unused without interpolation, but every declared block gets a valid range.
  bind(3, interpolate_ ? current_.entity : current_.color, count_ * sizeof(std::uint32_t));
  bind(4, interpolate_ ? current_.previous : current_.position,
       interpolate_ ? entities_ * sizeof(Vec3) : count_ * sizeof(Vec3));

  const Program& program = mode == SphereMode::Impostor ? impostor_ : mesh_;
  program.set("u_alpha", alpha);
  program.set("u_interpolate", interpolate_ ? 1 : 0);
  program.use();
  const auto n = static_cast<GLsizei>(count_);
  if (mode == SphereMode::Impostor) {
    glDisable(GL_CULL_FACE);  // the square's winding depends on the basis it was built in
    glBindVertexArray(empty_vao_.id());
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, n);
  } else {
    glEnable(GL_CULL_FACE);
    glBindVertexArray(mesh_vao_.id());
    glDrawElementsInstanced(GL_TRIANGLES, mesh_index_count_, GL_UNSIGNED_SHORT, nullptr, n);
  }
  glBindVertexArray(0);
}

std::size_t SphereRenderer::triangles_per_sphere(SphereMode mode) const {
  return mode == SphereMode::Impostor ? 2 : static_cast<std::size_t>(mesh_index_count_) / 3;
}

}  // namespace ballpit
