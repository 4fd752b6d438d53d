#include "engine/marine/marine.h"

#include <limits>

#include "engine/marine/marine_body.h"
#include "engine/marine/marine_clips.h"
#include "engine/marine/marine_skeleton.h"

namespace ballpit::marine {

Model make_marine() {
  Model m;
  m.path = kModelName;
  m.skeleton = make_skeleton();
  m.meshes.push_back(make_body(m.skeleton));
  m.clips = make_clips(m.skeleton);
  m.bind_min = Vec3::Constant(std::numeric_limits<float>::max());
  m.bind_max = Vec3::Constant(-std::numeric_limits<float>::max());
  for (const Vec3& p : m.meshes.front().positions) {
    m.bind_min = m.bind_min.cwiseMin(p);
    m.bind_max = m.bind_max.cwiseMax(p);
  }
  return m;
}

std::shared_ptr<const Model> marine_model() {
  // Built on first use (thread-safe static initialisation), never again.
  static const std::shared_ptr<const Model> model = std::make_shared<const Model>(make_marine());
  return model;
}

}  // namespace ballpit::marine
