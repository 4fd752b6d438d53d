#include "app/collider_renderer.h"

#include <string>

#include "app/frame_uniforms.h"
#include "app/icosphere.h"
#include "app/session.h"

namespace ballpit {

namespace {

constexpr const char* kVertex = R"glsl(
layout(location = 0) in vec3 a_position;  // sphere mesh vertex
struct Collider { vec4 a; vec4 b; vec4 velocity_a; vec4 velocity_b; };  // a.w: radius (m)
layout(std430, binding = 6) readonly buffer Colliders { Collider b_colliders[]; };
uniform float u_advance;  // alpha * dt: time since the rows' pose (s)
out vec3 v_world;
out vec3 v_normal;
void main() {
  Collider c = b_colliders[gl_InstanceID];
  vec3 a = c.a.xyz + c.velocity_a.xyz * u_advance;
  vec3 b = c.b.xyz + c.velocity_b.xyz * u_advance;
  vec3 axis = b - a;
  float len = length(axis);
  vec3 y = len > 1e-6 ? axis / len : vec3(0.0, 1.0, 0.0);
  vec3 helper = abs(y.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
  vec3 x = normalize(cross(helper, y));
  vec3 z = cross(x, y);
  vec3 v = normalize(a_position);
  vec3 dir = x * v.x + y * v.y + z * v.z;
  v_world = (v.y >= 0.0 ? b : a) + dir * c.a.w;
  v_normal = dir;
  gl_Position = u_projection * u_view * vec4(v_world, 1.0);
}
)glsl";

constexpr const char* kFragment = R"glsl(
in vec3 v_world;
in vec3 v_normal;
out vec4 o_color;
void main() {
  vec3 n = normalize(v_normal);
  vec3 albedo = srgb_to_linear(vec3(0.95, 0.85, 0.25));
  o_color = vec4(linear_to_srgb(shade(albedo, n, v_world, 1.0, 32.0, 0.3)), 0.55);
}
)glsl";

}  // namespace

ColliderRenderer::ColliderRenderer() {
  const std::string vs = std::string(kFrameGlsl) + kVertex;
  const std::string fs = std::string(kFrameGlsl) + kFragment;
  program_ = Program("joint colliders", {{GL_VERTEX_SHADER, vs}, {GL_FRAGMENT_SHADER, fs}});
  IcosphereMesh ico = make_icosphere(2);
  glNamedBufferStorage(vertices_.id(), static_cast<GLsizeiptr>(ico.positions.size() * sizeof(Vec3)),
                       ico.positions.data(), 0);
  glNamedBufferStorage(indices_.id(), static_cast<GLsizeiptr>(ico.indices.size() * sizeof(std::uint16_t)),
                       ico.indices.data(), 0);
  index_count_ = static_cast<GLsizei>(ico.indices.size());
  glVertexArrayVertexBuffer(vao_.id(), 0, vertices_.id(), 0, sizeof(Vec3));
  glVertexArrayElementBuffer(vao_.id(), indices_.id());
  glEnableVertexArrayAttrib(vao_.id(), 0);
  glVertexArrayAttribFormat(vao_.id(), 0, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vao_.id(), 0, 0);
}

void ColliderRenderer::draw(const Session& session) {
  const ColliderTable& t = session.world().colliders;
  const std::size_t n = t.size();
  if (n == 0) return;
  staging_.clear();
  auto push = [&](const Vec3& v, float w) { staging_.insert(staging_.end(), {v.x(), v.y(), v.z(), w}); };
  for (std::size_t i = 0; i < n; ++i) {
    push(t.a()[i], t.radius()[i]);
    push(t.b()[i], 0.0f);
    push(t.velocity_a()[i], 0.0f);
    push(t.velocity_b()[i], 0.0f);
  }
  if (n > capacity_) {
    instances_ = GlBuffer();
    capacity_ = 2 * n;
    glNamedBufferStorage(instances_.id(), static_cast<GLsizeiptr>(capacity_ * 16 * sizeof(float)), nullptr,
                         GL_DYNAMIC_STORAGE_BIT);
  }
  glNamedBufferSubData(instances_.id(), 0, static_cast<GLsizeiptr>(staging_.size() * sizeof(float)), staging_.data());
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 6, instances_.id(), 0,
                    static_cast<GLsizeiptr>(staging_.size() * sizeof(float)));
  program_.use();
  program_.set("u_advance", session.alpha() * session.world().step());
  // Translucent and not writing depth, so the ghosted character drawn next shows through
  // them and they through it: the view is for judging how well they cover the mesh.
  glEnable(GL_CULL_FACE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glDepthMask(GL_FALSE);
  glBindVertexArray(vao_.id());
  glDrawElementsInstanced(GL_TRIANGLES, index_count_, GL_UNSIGNED_SHORT, nullptr, static_cast<GLsizei>(n));
  glBindVertexArray(0);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
}

}  // namespace ballpit
