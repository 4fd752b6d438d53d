// Draws the skinned character: each mesh's bind-pose vertices (with up to four bone weights)
// are skinned on the GPU from two palettes, the start and end of the last physics step, and
// blended by the interpolation fraction, so the character moves as smoothly as the balls.
// Reads the session's character (model meshes, pose palettes, root); no CPU skinning per frame.
// Decision: the start-of-step palette is rebuilt on the CPU from the pose's previous joint
// transforms (a few dozen matrices), rather than kept from the last frame, so pausing, single
// steps and dropped frames never blend against a stale pose.
#pragma once

#include <memory>
#include <vector>

#include "app/gl_objects.h"
#include "app/shader.h"
#include "engine/model.h"

namespace ballpit {

class Session;

class CharacterRenderer {
 public:
  CharacterRenderer();
  // ghost: drawn translucent over the collider debug view.
  void draw(const Session& session, bool ghost);

 private:
  struct MeshBuffers {
    GlVertexArray vao;
    GlBuffer positions, normals, bones, weights, indices;
    GLsizei index_count = 0;
    std::size_t bones_in_palette = 0;
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
