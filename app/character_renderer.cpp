#include "app/character_renderer.h"

#include <algorithm>
#include <string>

#include "app/frame_uniforms.h"
#include "app/session.h"
#include "systems/skinning.h"

namespace ballpit {

namespace {

constexpr const char* kVertex = R"glsl(
layout(location = 0) in vec3 a_position;   // bind pose, model units
layout(location = 1) in vec3 a_normal;
layout(location = 2) in uvec4 a_bones;     // indices into this mesh's palette
layout(location = 3) in vec4 a_weights;    // sum to 1
layout(location = 4) in vec4 a_color;      // sRGB RGB + linear alpha (read only with u_has_colors)
layout(location = 5) in vec2 a_uv;         // v down from the texture's top row (only with u_has_texture)
layout(std430, binding = 5) readonly buffer Palette { mat4 b_palette[]; };  // start, then end of step
uniform int u_bones;       // palette entries per pose
uniform float u_alpha;     // 0: start of the last step, 1: its end
out vec3 v_world;
out vec3 v_normal;
out vec4 v_color;
out vec2 v_uv;

mat4 skin(int base) {
  return a_weights.x * b_palette[base + int(a_bones.x)] + a_weights.y * b_palette[base + int(a_bones.y)] +
         a_weights.z * b_palette[base + int(a_bones.z)] + a_weights.w * b_palette[base + int(a_bones.w)];
}

void main() {
  mat4 start = skin(0);
  mat4 end = skin(u_bones);
  vec4 p = mix(start * vec4(a_position, 1.0), end * vec4(a_position, 1.0), u_alpha);
  // Palettes hold rigid motion times a uniform scale, so their upper 3x3 carries normals.
  v_normal = mix(mat3(start) * a_normal, mat3(end) * a_normal, u_alpha);
  v_world = p.xyz;
  v_color = a_color;
  v_uv = a_uv;
  gl_Position = u_projection * u_view * p;
}
)glsl";

constexpr const char* kFragment = R"glsl(
in vec3 v_world;
in vec3 v_normal;
in vec4 v_color;
in vec2 v_uv;
uniform float u_opacity;
uniform vec4 u_base_color;    // linear
uniform int u_has_colors;
uniform int u_has_texture;
uniform int u_fallback;       // none of the above: the engine's brown albedo
layout(binding = 0) uniform sampler2D u_texture;  // GL_SRGB8_ALPHA8: sampled linear
out vec4 o_color;

// The exact sRGB curve (as the texture unit decodes), for vertex colours.
vec3 srgb_decode(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
}

void main() {
  vec3 n = normalize(v_normal);
  if (!gl_FrontFacing) n = -n;     // imported meshes are not always consistently wound
  vec3 albedo = srgb_to_linear(vec3(0.66, 0.47, 0.30));
  if (u_fallback == 0) {
    albedo = u_base_color.rgb;
    if (u_has_colors != 0) albedo *= srgb_decode(v_color.rgb);
    if (u_has_texture != 0) albedo *= texture(u_texture, v_uv).rgb;
  }
  float occlusion = depth_occlusion(v_world);
  o_color = vec4(linear_to_srgb(shade(albedo, n, v_world, occlusion, 24.0, 0.12)), u_opacity);
}
)glsl";

}  // namespace

CharacterRenderer::CharacterRenderer() {
  const std::string vs = std::string(kFrameGlsl) + kVertex;
  const std::string fs = std::string(kFrameGlsl) + kFragment;
  program_ = Program("character", {{GL_VERTEX_SHADER, vs}, {GL_FRAGMENT_SHADER, fs}});
}

void CharacterRenderer::load(const std::shared_ptr<const Model>& model) {
  meshes_.clear();
  model_ = model;
  for (const SkinnedMesh& m : model->meshes) {
    MeshBuffers b;
    auto store = [](GlBuffer& buffer, const auto& v) {
      glNamedBufferStorage(buffer.id(), static_cast<GLsizeiptr>(v.size() * sizeof(v[0])), v.data(), 0);
    };
    store(b.positions, m.positions);
    store(b.normals, m.normals);
    store(b.bones, m.bones);
    store(b.weights, m.weights);
    store(b.indices, m.indices);
    b.index_count = static_cast<GLsizei>(m.indices.size());
    b.bones_in_palette = m.bone_joint.size();
    b.base_color = m.base_color;
    const bool has_colors = m.colors.size() == m.positions.size() && !m.colors.empty();
    const bool has_uvs = m.uvs.size() == m.positions.size() && !m.uvs.empty();
    const Texture* texture = m.base_color_texture.get();
    const bool has_texture =
        has_uvs && texture && texture->width > 0 && texture->height > 0 &&
        texture->rgba.size() == static_cast<std::size_t>(texture->width) * static_cast<std::size_t>(texture->height) * 4;
    b.fallback_albedo = !has_colors && !has_texture && m.base_color.head<3>() == Vec3::Ones();
    const GLuint vao = b.vao.id();
    glVertexArrayVertexBuffer(vao, 0, b.positions.id(), 0, sizeof(Vec3));
    glVertexArrayVertexBuffer(vao, 1, b.normals.id(), 0, sizeof(Vec3));
    glVertexArrayVertexBuffer(vao, 2, b.bones.id(), 0, sizeof(m.bones[0]));
    glVertexArrayVertexBuffer(vao, 3, b.weights.id(), 0, sizeof(m.weights[0]));
    glVertexArrayElementBuffer(vao, b.indices.id());
    for (GLuint a = 0; a < 4; ++a) {
      glEnableVertexArrayAttrib(vao, a);
      glVertexArrayAttribBinding(vao, a, a);
    }
    glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribFormat(vao, 1, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribIFormat(vao, 2, 4, GL_UNSIGNED_SHORT, 0);
    glVertexArrayAttribFormat(vao, 3, 4, GL_FLOAT, GL_FALSE, 0);
    // Colours and coordinates only where the mesh has them; a disabled array is never read
    // (the shader's flags say so), whatever the context's constant attribute holds.
    if (has_colors) {
      b.colors = GlBuffer();
      store(b.colors, m.colors);
      glVertexArrayVertexBuffer(vao, 4, b.colors.id(), 0, sizeof(m.colors[0]));
      glEnableVertexArrayAttrib(vao, 4);
      glVertexArrayAttribBinding(vao, 4, 4);
      glVertexArrayAttribFormat(vao, 4, 4, GL_UNSIGNED_BYTE, GL_TRUE, 0);
    }
    if (has_texture) {
      b.uvs = GlBuffer();
      store(b.uvs, m.uvs);
      glVertexArrayVertexBuffer(vao, 5, b.uvs.id(), 0, sizeof(Vec2));
      glEnableVertexArrayAttrib(vao, 5);
      glVertexArrayAttribBinding(vao, 5, 5);
      glVertexArrayAttribFormat(vao, 5, 2, GL_FLOAT, GL_FALSE, 0);
      // Rows top to bottom as stored: the first row is t = 0, where the coordinates' v = 0 is.
      b.texture = GlTexture2D();
      const GLuint tex = b.texture.id();
      int levels = 1;
      while ((std::max(texture->width, texture->height) >> levels) > 0) ++levels;
      glTextureStorage2D(tex, levels, GL_SRGB8_ALPHA8, texture->width, texture->height);
      glTextureSubImage2D(tex, 0, 0, 0, texture->width, texture->height, GL_RGBA, GL_UNSIGNED_BYTE,
                          texture->rgba.data());
      glGenerateTextureMipmap(tex);
      glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
      glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTextureParameteri(tex, GL_TEXTURE_WRAP_S, GL_REPEAT);
      glTextureParameteri(tex, GL_TEXTURE_WRAP_T, GL_REPEAT);
    }
    meshes_.push_back(std::move(b));
  }
}

void CharacterRenderer::draw(const Session& session, bool ghost) {
  if (!session.has_character()) return;
  const World& world = session.world();
  const CharacterSetup& setup = world.characters.setup(0);
  const CharacterMotion& motion = world.characters.motion(0);
  const CharacterPose& pose = world.characters.pose(0);
  if (setup.model != model_) load(setup.model);

  program_.use();
  program_.set("u_alpha", session.alpha());
  program_.set("u_opacity", ghost ? 0.35f : 1.0f);
  glDisable(GL_CULL_FACE);
  if (ghost) {
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glDepthMask(GL_FALSE);
  }
  const Affine3 start_transform = character_transform(setup, motion.previous);
  for (std::size_t k = 0; k < meshes_.size() && k < pose.palettes.size(); ++k) {
    const MeshBuffers& b = meshes_[k];
    const SkinnedMesh& mesh = setup.model->meshes[k];
    skinning_palette(mesh, pose.model_previous, start_transform, start_);
    staging_.assign(start_.begin(), start_.end());
    staging_.insert(staging_.end(), pose.palettes[k].begin(), pose.palettes[k].end());
    if (staging_.size() > palette_capacity_) {
      palette_ = GlBuffer();
      palette_capacity_ = staging_.size() * 2;
      glNamedBufferStorage(palette_.id(), static_cast<GLsizeiptr>(palette_capacity_ * sizeof(Mat4)), nullptr,
                           GL_DYNAMIC_STORAGE_BIT);
    }
    // A few kilobytes a mesh: the driver's copy on upload costs less than a mapped ring.
    glNamedBufferSubData(palette_.id(), 0, static_cast<GLsizeiptr>(staging_.size() * sizeof(Mat4)), staging_.data());
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 5, palette_.id(), 0,
                      static_cast<GLsizeiptr>(staging_.size() * sizeof(Mat4)));
    program_.set("u_bones", static_cast<int>(b.bones_in_palette));
    program_.set("u_base_color", b.base_color);
    program_.set("u_has_colors", b.colors.id() != 0 ? 1 : 0);
    program_.set("u_has_texture", b.texture.id() != 0 ? 1 : 0);
    program_.set("u_fallback", b.fallback_albedo ? 1 : 0);
    if (b.texture.id() != 0) glBindTextureUnit(0, b.texture.id());
    glBindVertexArray(b.vao.id());
    glDrawElements(GL_TRIANGLES, b.index_count, GL_UNSIGNED_INT, nullptr);
  }
  glBindVertexArray(0);
  if (ghost) {
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
  }
}

}  // namespace ballpit
