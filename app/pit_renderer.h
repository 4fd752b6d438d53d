// Draws the pit: a tiled floor, the inner faces of the four walls up to a drawn height, a rim
// along their tops, and the ground around it. Lit with the shared light model; the floor and
// walls darken towards the floor corners and with depth, which is what makes depth readable.
// Decision: the walls' inner faces are opaque and their outer faces are tinted glass drawn after
// the balls, with back faces culled: from any orbit angle the walls between the eye and the
// balls show as glass and the far ones as solid, with no transparency sorting.
#pragma once

#include "app/gl_objects.h"
#include "app/shader.h"
#include "engine/settings.h"

namespace ballpit {

class PitRenderer {
 public:
  PitRenderer();
  // drawn_wall_height (unit: m): the canonical walls are 20 m tall; the app draws them only a
  // little above the balls so they do not hide the pit.
  void draw_opaque(const Pit& pit, float drawn_wall_height);
  // The glass outer faces; after everything opaque.
  void draw_glass();

 private:
  void rebuild(const Pit& pit, float drawn_wall_height);

  Program program_;
  GlVertexArray vao_;
  GlBuffer vertices_{nullptr};
  GLsizei vertex_count_ = 0;
  GLsizei opaque_count_ = 0;
  float built_half_width_ = -1.0f;
  float built_height_ = -1.0f;
};

// How high the app draws the walls for a pit filled to fill_height (unit: m).
float drawn_wall_height(const Pit& pit, float fill_height);

}  // namespace ballpit
