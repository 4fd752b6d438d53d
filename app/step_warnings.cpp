#include "app/step_warnings.h"

#include <cstdio>

#include "engine/world.h"

namespace ballpit {

void print_step_warnings(const World& world, bool substeps_chosen_per_step) {
  const World::StepWarnings warnings = world.step_warnings();
  auto print = [](const std::string& warning) {
    if (!warning.empty()) std::fprintf(stderr, "ballpit: warning: %s\n", warning.c_str());
  };
  if (!substeps_chosen_per_step) print(warnings.substep);
  print(warnings.step);
  print(warnings.passes);
  print(warnings.gravity);
}

}  // namespace ballpit
