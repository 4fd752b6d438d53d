#include "systems/character_controller.h"

#include <algorithm>
#include <cmath>

#include "engine/world.h"

namespace ballpit {

ControllerInput scripted_input(const std::vector<ScriptSegment>& script, float time) {
  float start = 0.0f;
  for (const ScriptSegment& s : script) {
    if (time < start + s.duration) return s.input;
    start += s.duration;
  }
  return {};
}

float root_limit(const CharacterSetup& setup, const Pit& pit) {
  return std::max(pit.half_width - setup.footprint_radius - setup.controller.wall_clearance, 0.0f);
}

void advance_controller(const CharacterSetup& setup, CharacterMotion& motion, const Pit& pit, float dt) {
  if (!motion.script.empty()) {
    motion.input = scripted_input(motion.script, motion.script_time);
    motion.script_time += dt;
  }
  const ControllerSettings& c = setup.controller;
  const ControllerInput& in = motion.input;
  const float forward = std::clamp(in.forward, -1.0f, 1.0f);
  const float turn = std::clamp(in.turn, -1.0f, 1.0f);
  const float target = forward >= 0.0f ? forward * (in.run ? c.run_speed : c.walk_speed) : forward * c.back_speed;

  motion.previous = motion.current;
  RootState& r = motion.current;
  // Acceleration, capped so a blend segment (idle-walk or walk-run, in ground speed) takes at
  // least blend_time to cross.
  const float walk = setup.gaits[kWalk].speed, run = setup.gaits[kRun].speed;
  const float segment = std::abs(r.speed) < walk ? walk : (std::abs(r.speed) < run ? run - walk : run);
  const float accel = std::min(c.acceleration, segment / c.blend_time);
  const float dv = std::clamp(target - r.speed, -accel * dt, accel * dt);
  const float mean_speed = r.speed + 0.5f * dv;
  const float mean_heading = r.heading + 0.5f * turn * c.turn_rate * dt;
  r.speed += dv;
  r.heading += turn * c.turn_rate * dt;
  // Keep the heading in (-pi, pi] so float precision does not erode over a long session.
  if (r.heading > 3.14159265f) r.heading -= 6.28318531f;
  if (r.heading <= -3.14159265f) r.heading += 6.28318531f;
  r.position += Vec3(std::sin(mean_heading), 0.0f, std::cos(mean_heading)) * (mean_speed * dt);
  const float limit = root_limit(setup, pit);
  r.position.x() = std::clamp(r.position.x(), -limit, limit);
  r.position.z() = std::clamp(r.position.z(), -limit, limit);
}

Access CharacterControllerSystem::access() const {
  Access a;
  a.writes = {ColumnId::CharacterController};
  return a;
}

void CharacterControllerSystem::run(World& world) {
  for (std::size_t i = 0; i < world.characters.size(); ++i)
    advance_controller(world.characters.setup(i), world.characters.mut_motion(i), world.pit, world.step());
}

}  // namespace ballpit
