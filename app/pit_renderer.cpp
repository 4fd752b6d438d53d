#include "app/pit_renderer.h"

#include <algorithm>
#include <string>
#include <vector>

#include "app/frame_uniforms.h"

namespace ballpit {

namespace {

enum Surface : int { kFloor = 0, kWall = 1, kRim = 2, kGround = 3, kGlass = 4 };

struct Vertex {
  float position[3];
  float normal[3];
  float surface;
};

constexpr const char* kVertex = R"glsl(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in float a_surface;
out vec3 v_world;
out vec3 v_normal;
flat out int v_surface;
void main() {
  v_world = a_position;
  v_normal = a_normal;
  v_surface = int(a_surface + 0.5);
  gl_Position = u_projection * u_view * vec4(a_position, 1.0);
}
)glsl";

constexpr const char* kFragment = R"glsl(
in vec3 v_world;
in vec3 v_normal;
flat in int v_surface;
out vec4 o_color;

// 1 on thin lines every `spacing` metres along the given coordinates, 0 between.
float grid_lines(vec2 q, float spacing, float width) {
  vec2 f = abs(fract(q / spacing + 0.5) - 0.5) * spacing;
  vec2 w = fwidth(q) + width;
  vec2 line = 1.0 - smoothstep(vec2(0.0), w, f);
  return max(line.x, line.y);
}

void main() {
  vec3 p = v_world;
  vec3 n = normalize(v_normal);
  float half_width = u_pit.x;
  float reference = max(u_pit.z, 0.25);       // fill height, the scale of the darkening
  float tile = max(0.1, exp2(round(log2(half_width / 6.0))));  // about 12 tiles across
  vec3 albedo;
  float occlusion = 1.0;
  float shininess = 16.0, specular = 0.05;
  if (v_surface == 0) {                      // floor
    vec2 cell = floor(p.xz / tile);
    albedo = mix(vec3(0.80, 0.76, 0.68), vec3(0.70, 0.66, 0.58), mod(cell.x + cell.y, 2.0));
    albedo = mix(albedo, vec3(0.45, 0.42, 0.38), grid_lines(p.xz, tile, 0.004 * tile));
    float to_wall = half_width - max(abs(p.x), abs(p.z));
    occlusion = mix(0.45, 1.0, smoothstep(0.0, 0.3 * reference, to_wall)) * mix(0.6, 1.0, depth_occlusion(p));
  } else if (v_surface == 1) {               // wall, inner face
    albedo = vec3(0.30, 0.52, 0.80);
    albedo = mix(albedo, albedo * 0.7, grid_lines(vec2(p.y, 0.5 * tile), 0.5 * tile, 0.004 * tile));
    float to_corner = half_width - min(abs(p.x), abs(p.z));
    occlusion = mix(0.45, 1.0, smoothstep(0.0, 0.3 * reference, p.y)) *
                mix(0.6, 1.0, smoothstep(0.0, 0.3 * reference, to_corner)) * depth_occlusion(p);
    specular = 0.15;
  } else if (v_surface == 2) {               // rim
    albedo = vec3(0.92, 0.92, 0.95);
    specular = 0.2;
  } else if (v_surface == 4) {               // outer wall faces: tinted plexiglass
    vec3 v = normalize(u_eye.xyz - p);
    float fresnel = pow(1.0 - abs(dot(n, v)), 3.0);
    vec3 tint = linear_to_srgb(shade(srgb_to_linear(vec3(0.55, 0.72, 0.95)), n, p, 1.0, 64.0, 0.6));
    o_color = vec4(tint, mix(0.22, 0.7, fresnel));
    return;
  } else {                                   // ground around the pit
    vec2 cell = floor(p.xz / (4.0 * tile));
    albedo = mix(vec3(0.34, 0.40, 0.30), vec3(0.31, 0.37, 0.28), mod(cell.x + cell.y, 2.0));
    float to_pit = max(abs(p.x), abs(p.z)) - half_width;
    occlusion = mix(0.55, 1.0, smoothstep(0.0, 0.5 * reference, to_pit));
  }
  o_color = vec4(linear_to_srgb(shade(srgb_to_linear(albedo), n, p, occlusion, shininess, specular)), 1.0);
}
)glsl";

// Appends the quad a, b, c, d (in order around it) as two triangles wound counter-clockwise
// when seen from the side `normal` points to.
void add_quad(std::vector<Vertex>& out, Vec3 a, Vec3 b, Vec3 c, Vec3 d, const Vec3& normal, Surface s) {
  if ((b - a).cross(c - a).dot(normal) < 0.0f) {
    std::swap(b, d);
  }
  auto v = [&](const Vec3& p) {
    return Vertex{{p.x(), p.y(), p.z()}, {normal.x(), normal.y(), normal.z()}, static_cast<float>(s)};
  };
  out.insert(out.end(), {v(a), v(b), v(c), v(a), v(c), v(d)});
}

}  // namespace

float drawn_wall_height(const Pit& pit, float fill_height) {
  return std::min(pit.wall_height, std::max(1.35f * fill_height, 0.3f));
}

PitRenderer::PitRenderer() {
  const std::string vs = std::string(kFrameGlsl) + kVertex;
  const std::string fs = std::string(kFrameGlsl) + kFragment;
  program_ = Program("pit", {{GL_VERTEX_SHADER, vs}, {GL_FRAGMENT_SHADER, fs}});
  const GLuint vao = vao_.id();
  glEnableVertexArrayAttrib(vao, 0);
  glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, offsetof(Vertex, position));
  glVertexArrayAttribBinding(vao, 0, 0);
  glEnableVertexArrayAttrib(vao, 1);
  glVertexArrayAttribFormat(vao, 1, 3, GL_FLOAT, GL_FALSE, offsetof(Vertex, normal));
  glVertexArrayAttribBinding(vao, 1, 0);
  glEnableVertexArrayAttrib(vao, 2);
  glVertexArrayAttribFormat(vao, 2, 1, GL_FLOAT, GL_FALSE, offsetof(Vertex, surface));
  glVertexArrayAttribBinding(vao, 2, 0);
}

void PitRenderer::rebuild(const Pit& pit, float height) {
  const float h = pit.half_width;
  const float rim = std::max(0.02f, 0.02f * h);  // wall thickness, drawn as the rim's width
  const float g = std::max(12.0f * h, 30.0f);    // ground extent
  const Vec3 up(0, 1, 0);
  std::vector<Vertex> v;
  add_quad(v, {-h, 0, -h}, {h, 0, -h}, {h, 0, h}, {-h, 0, h}, up, kFloor);
  // Inner wall faces, normals pointing into the pit.
  add_quad(v, {h, 0, -h}, {h, height, -h}, {h, height, h}, {h, 0, h}, {-1, 0, 0}, kWall);
  add_quad(v, {-h, 0, -h}, {-h, 0, h}, {-h, height, h}, {-h, height, -h}, {1, 0, 0}, kWall);
  add_quad(v, {-h, 0, h}, {h, 0, h}, {h, height, h}, {-h, height, h}, {0, 0, -1}, kWall);
  add_quad(v, {-h, 0, -h}, {-h, height, -h}, {h, height, -h}, {h, 0, -h}, {0, 0, 1}, kWall);
  // Rim: the walls' tops, outlining the pit from above even where a wall is culled.
  const float o = h + rim;
  add_quad(v, {h, height, -o}, {o, height, -o}, {o, height, o}, {h, height, o}, up, kRim);
  add_quad(v, {-o, height, -o}, {-h, height, -o}, {-h, height, o}, {-o, height, o}, up, kRim);
  add_quad(v, {-h, height, h}, {h, height, h}, {h, height, o}, {-h, height, o}, up, kRim);
  add_quad(v, {-h, height, -o}, {h, height, -o}, {h, height, -h}, {-h, height, -h}, up, kRim);
  // Ground: a frame around the walls.
  add_quad(v, {-g, 0, -g}, {g, 0, -g}, {g, 0, -o}, {-g, 0, -o}, up, kGround);
  add_quad(v, {-g, 0, o}, {g, 0, o}, {g, 0, g}, {-g, 0, g}, up, kGround);
  add_quad(v, {-g, 0, -o}, {-o, 0, -o}, {-o, 0, o}, {-g, 0, o}, up, kGround);
  add_quad(v, {o, 0, -o}, {g, 0, -o}, {g, 0, o}, {o, 0, o}, up, kGround);

  opaque_count_ = static_cast<GLsizei>(v.size());
  // Outer faces of the walls, drawn last as glass over the balls behind them.
  add_quad(v, {o, 0, -o}, {o, 0, o}, {o, height, o}, {o, height, -o}, {1, 0, 0}, kGlass);
  add_quad(v, {-o, 0, -o}, {-o, height, -o}, {-o, height, o}, {-o, 0, o}, {-1, 0, 0}, kGlass);
  add_quad(v, {-o, 0, o}, {-o, height, o}, {o, height, o}, {o, 0, o}, {0, 0, 1}, kGlass);
  add_quad(v, {-o, 0, -o}, {o, 0, -o}, {o, height, -o}, {-o, height, -o}, {0, 0, -1}, kGlass);

  vertices_ = GlBuffer();
  glNamedBufferStorage(vertices_.id(), static_cast<GLsizeiptr>(v.size() * sizeof(Vertex)), v.data(), 0);
  glVertexArrayVertexBuffer(vao_.id(), 0, vertices_.id(), 0, sizeof(Vertex));
  vertex_count_ = static_cast<GLsizei>(v.size());
  built_half_width_ = pit.half_width;
  built_height_ = height;
}

void PitRenderer::draw_opaque(const Pit& pit, float height) {
  if (pit.half_width != built_half_width_ || height != built_height_) rebuild(pit, height);
  program_.use();
  glEnable(GL_CULL_FACE);
  glBindVertexArray(vao_.id());
  glDrawArrays(GL_TRIANGLES, 0, opaque_count_);
  glBindVertexArray(0);
}

void PitRenderer::draw_glass() {
  if (vertex_count_ == opaque_count_) return;
  program_.use();
  glEnable(GL_CULL_FACE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glDepthMask(GL_FALSE);
  glBindVertexArray(vao_.id());
  glDrawArrays(GL_TRIANGLES, opaque_count_, vertex_count_ - opaque_count_);
  glBindVertexArray(0);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
}

}  // namespace ballpit
