#include "engine/character.h"

#include <cmath>

namespace ballpit {

Affine3 character_transform(const CharacterSetup& setup, const RootState& root) {
  // The model's forward axis is turned onto +z first, so heading 0 faces +z whatever the file.
  const Vec3 flat(setup.forward.x(), 0.0f, setup.forward.z());
  const float model_yaw = std::atan2(flat.x(), flat.z());
  Affine3 t = Affine3::Identity();
  t.translate(root.position);
  t.rotate(Eigen::AngleAxisf(root.heading - model_yaw, Vec3::UnitY()));
  t.scale(setup.scale);
  t.translate(-setup.pivot);
  return t;
}

std::uint32_t CharacterTable::add(CharacterSetup setup, CharacterMotion motion, CharacterPose pose) {
  check_access(ColumnId::CharacterController, true);
  check_access(ColumnId::CharacterPose, true);
  setup_.push_back(std::move(setup));
  motion_.push_back(std::move(motion));
  pose_.push_back(std::move(pose));
  return static_cast<std::uint32_t>(setup_.size() - 1);
}

void CharacterTable::clear() {
  setup_.clear();
  motion_.clear();
  pose_.clear();
}

int CharacterTable::find(Entity e) const {
  for (std::size_t i = 0; i < setup_.size(); ++i)
    if (setup_[i].entity == e) return static_cast<int>(i);
  return -1;
}

}  // namespace ballpit
