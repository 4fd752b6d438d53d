// Debug draw of the joint colliders: every row of the collider table as a capsule (a sphere
// when its ends coincide), instanced from one sphere mesh whose upper half is moved to one
// end and lower half to the other. Reads the collider table (ends, radius, surface velocity).
// Decision: a row holds the collider at the start of the last step and its surface velocity
// over that step, so the drawn ends are a + v_a * alpha * dt: where the solver had the
// collider at the moment being shown, in step with the interpolated balls and character.
#pragma once

#include <vector>

#include "app/gl_objects.h"
#include "app/shader.h"

namespace ballpit {

class Session;

class ColliderRenderer {
 public:
  ColliderRenderer();
  void draw(const Session& session);

 private:
  Program program_;
  GlVertexArray vao_;
  GlBuffer vertices_, indices_;
  GLsizei index_count_ = 0;
  GlBuffer instances_{nullptr};
  std::size_t capacity_ = 0;
  std::vector<float> staging_;
};

}  // namespace ballpit
