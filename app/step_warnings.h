// The console's word on a world's dt and substeps (World::step_warnings), for every way of
// running a scene: `ballpit run`, the window and the offscreen app.
#pragma once

namespace ballpit {

class World;

// Prints each warning on stderr. substeps_chosen_per_step (--tolerance) leaves out the
// long-substep one: the substep control bounds overlaps itself, whatever it starts from.
void print_step_warnings(const World& world, bool substeps_chosen_per_step = false);

}  // namespace ballpit
