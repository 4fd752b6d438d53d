// Fuzz target: scene files (engine/scene_file.h). The input is a scene file's text, then any
// number of `--set` assignments, each after a NUL byte; it goes through load_scene exactly as
// `ballpit run --scene FILE.json --set ...` does. A small scene that loads is built and stepped
// (fuzz/step_world.h): a file the parser accepts must build and run.
#include <string>
#include <vector>

#include "engine/error.h"
#include "engine/scene_file.h"
#include "engine/world.h"
#include "fuzz/fuzz_target.h"
#include "fuzz/step_world.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace ballpit;
  static const fuzz::TempFile file(".json");
  const std::string_view in = fuzz::as_text(data, size);
  const std::size_t end = in.find('\0');
  file.write(in.substr(0, end));
  std::vector<std::string> overrides;
  for (std::size_t at = end; at != std::string_view::npos;) {
    const std::size_t next = in.find('\0', at + 1);
    overrides.emplace_back(in.substr(at + 1, next == std::string_view::npos ? std::string_view::npos : next - at - 1));
    at = next;
  }
  try {
    const SceneFile scene = load_scene(file.path(), overrides);
    // Building allocates every sphere: only small scenes, so a scene of 2^32 spheres (valid,
    // refused later by the app's memory check) does not read as an out-of-memory finding.
    // A character scene is parsed only: building it imports the model and settles the pit for
    // hundreds of steps, too slow per input (model import has its own target).
    if (!scene.uses_character() && scene.total_spheres() <= fuzz::kMaxSteppedSpheres) {
      World world;
      build_scene(scene, world);
      fuzz::step_small_world(world, 2);
    }
  } catch (const Error&) {
    // The documented clean failure: the file, the field and what was expected.
  }
  return 0;
}
