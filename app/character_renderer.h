// Draws the skinned character: each mesh's bind-pose vertices (with up to four bone weights)
// are skinned on the GPU from two palettes, the start and end of the last physics step, and
// blended by the interpolation fraction, so the character moves as smoothly as the balls.
// Reads the session's character (model meshes, pose palettes, root); no CPU skinning per frame.
// Decision: the start-of-step palette is rebuilt on the CPU from the pose's previous joint
// transforms (a few dozen matrices), rather than kept from the last frame, so pausing, single
// steps and dropped frames never blend against a stale pose.
// Look: base colour x vertex colour x base colour texture, as glTF multiplies them (colours and
// texels are sRGB, decoded to linear before the product; alpha is not drawn: the character is
// opaque). A mesh with none of them (no colours, no texture, a white base colour: the Wuson)
// keeps the engine's brown albedo.
#pragma once

#include <memory>
#include <vector>

#include "app/gl_objects.h"
#include "app/shader.h"
#include "engine/model.h"

namespace ballpit {

class Session;

namespace gl_detail {
inline void create_texture_2d(GLuint* id) { glCreateTextures(GL_TEXTURE_2D, 1, id); }
inline void delete_texture(GLuint id) { glDeleteTextures(1, &id); }
}  // namespace gl_detail
using GlTexture2D = GlName<gl_detail::create_texture_2d, gl_detail::delete_texture>;

class CharacterRenderer {
 public:
  CharacterRenderer();
  // ghost: drawn translucent over the collider debug view.
  void draw(const Session& session, bool ghost);

 private:
  struct MeshBuffers {
    GlVertexArray vao;
    GlBuffer positions, normals, bones, weights, indices;
    GlBuffer colors{nullptr}, uvs{nullptr};  // no names unless the mesh has them
    GlTexture2D texture{nullptr};            // base colour texture (sRGB); none unless the mesh has one
    GLsizei index_count = 0;
    std::size_t bones_in_palette = 0;
    Vec4 base_color = Vec4::Ones();  // linear RGBA
    bool fallback_albedo = false;    // none of the look's parts: the engine's own colour
  };
  void load(const std::shared_ptr<const Model>& model);

  Program program_;
  std::shared_ptr<const Model> model_;  // the model the buffers were made from
  std::vector<MeshBuffers> meshes_;
  GlBuffer palette_;
  std::size_t palette_capacity_ = 0;    // in matrices
  std::vector<Mat4> start_;    // start-of-step palette of one mesh
  std::vector<Mat4> staging_;  // start then end palettes, as uploaded
};

}  // namespace ballpit
