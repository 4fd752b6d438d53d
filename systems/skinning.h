// Skinning: the palette the renderer skins with, and CPU skinning for tests and tools.
// Reads: CharacterController (root at the end of the step), CharacterPose (joint transforms at
// the end of the step). Writes: CharacterPose (palettes).
// Decision: a palette entry is world * joint model transform * inverse bind, so a vertex goes
// straight from bind space to the world; the mesh node's own transform in the file is not
// applied on top (the Wuson's -90 degree node rotation would tip it over).
#pragma once

#include <span>
#include <vector>

#include "engine/math.h"
#include "engine/skinned_mesh.h"
#include "engine/system.h"

namespace ballpit {

// palette[k] = world * model[bone_joint[k]] * inverse_bind[k] for every bone of the mesh.
void skinning_palette(const SkinnedMesh& mesh, const std::vector<Affine3>& model, const Affine3& world,
                      std::vector<Mat4>& palette);

// Skinned position of every vertex: sum of weight x palette[bone] x bind position.
void skin_positions(const SkinnedMesh& mesh, std::span<const Mat4> palette, std::vector<Vec3>& out);

class SkinningSystem : public System {
 public:
  std::string_view name() const override { return "skinning"; }
  Access access() const override;
  void run(World& world) override;
};

}  // namespace ballpit
