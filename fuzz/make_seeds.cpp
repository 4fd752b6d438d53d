// Writes the fuzz targets' seed corpora into a folder: small valid inputs made by the engine
// itself, so they follow the formats as the code writes them today and nothing binary sits in
// the repository. Each seed is loaded back once and must be accepted, so every seed takes the
// fuzzer past the parsers' first refusals into the deep code.
// Usage: make_seeds OUT_DIR   (writes OUT_DIR/scene_file, OUT_DIR/snapshot, OUT_DIR/model_import)
#include <array>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "engine/fixed_step_loop.h"
#include "engine/model_import.h"
#include "engine/scene_file.h"
#include "engine/scheduler.h"
#include "engine/snapshot.h"
#include "engine/world.h"
#include "systems/character_pipeline.h"
#include "systems/physics_pipeline.h"
#include "systems/pit_character_scene.h"

namespace fs = std::filesystem;
using namespace ballpit;

namespace {

// The smallest model import accepts: one bone, one triangle weighted to it, one clip that
// turns and lifts the bone. DirectX .X text, the format of the default character, laid out
// as assimp's own test files are (its text parser refuses a float without a decimal point).
constexpr const char* kTinySkinnedX = R"(xof 0303txt 0032
Frame Root {
 FrameTransformMatrix {
  1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0;;
 }
 Frame Bone {
  FrameTransformMatrix {
   1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,1.0,0.0,1.0;;
  }
 }
 Mesh Tri {
  3;
  0.0;0.0;0.0;,
  1.0;0.0;0.0;,
  0.0;1.0;0.0;;
  1;
  3;0,1,2;;
  XSkinMeshHeader {
   1;
   1;
   1;
  }
  SkinWeights {
   "Bone";
   3;
   0,
   1,
   2;
   1.0,
   1.0,
   1.0;
   1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,-1.0,0.0,1.0;;
  }
 }
}
AnimTicksPerSecond {
 10;
}
AnimationSet Wave {
 Animation {
  { Bone }
  AnimationKey {
   0;
   2;
   0;4;1.0,0.0,0.0,0.0;;,
   10;4;0.7071,0.0,0.0,0.7071;;;
  }
  AnimationKey {
   2;
   2;
   0;3;0.0,1.0,0.0;;,
   10;3;0.0,2.0,0.0;;;
  }
 }
}
)";

void write(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out.flush()) throw std::runtime_error("cannot write " + path.string());
}

void scene_seeds(const fs::path& dir) {
  // The embedded default scene (10000 spheres: parsed, not built), a small one that is built
  // and stepped, and the default with --set overrides (the part after each NUL byte).
  write(dir / "default.json", scene_to_json(SceneFile{}).dump(2));
  SceneFile small;
  small.populations.front().count = 12;
  small.solver.sleeping = true;
  small.solver.narrowphase = NarrowphaseMode::Naive;
  write(dir / "small.json", scene_to_json(small).dump());
  write(dir / "overrides.json", scene_to_json(SceneFile{}).dump() + std::string(1, '\0') + "populations.0.count=9" +
                                    std::string(1, '\0') + "solver.substeps=3" + std::string(1, '\0') +
                                    "gravity=[0,-5,1]");
  load_scene((dir / "small.json").string());
  // A character whose clips come from sources (engine/clip_sources.h), every form of the
  // section: parsed only by the target, so the absolute model path need not be beside it.
  SceneFile sources;
  sources.character = SceneCharacter{};
  sources.character->model = kWusonModelPath;
  RoleClips& clips = sources.character->clips;
  clips = {ClipSource::named("Wuson_Bind"), ClipSource{}, ClipSource{}, ClipSource{}, ClipSource{}};
  clips[1].file = kWusonModelPath;
  clips[1].clip = "Wuson_Walk";
  clips[1].range = std::array<double, 2>{0.0, 108.0};
  clips[1].unit = ClipSource::Unit::Frames;
  clips[1].fps = 30.0;
  clips[1].root_motion = ClipSource::RootMotion::Auto;
  clips[2].clip = "Wuson_Run";
  clips[2].root_motion = ClipSource::RootMotion::InPlace;
  clips[2].root_joint = "Root";
  clips[4] = ClipSource::named("Wuson_Walk");
  write(dir / "character_clips.json", scene_to_json(sources).dump(2));
  load_scene((dir / "character_clips.json").string());
}

// A few spheres in a small pit, stepped so the warm-start cache holds contacts, one removed
// so the entity registry has a free list.
World tiny_world(bool friction, bool sleeping, bool closed) {
  World w;
  w.pit.half_width = 0.12f;
  w.pit.wall_height = 0.5f;
  w.pit.closed = closed;
  w.pit.material = {0.4f, friction ? 0.5f : 0.0f};
  w.materials.assign(1, w.pit.material);
  w.materials.push_back({0.9f, 0.0f});
  w.solver.sleeping = sleeping;
  w.enable_angular(friction);
  for (int i = 0; i < 6; ++i) {
    SphereDesc d;
    d.position = Vec3(0.01f * static_cast<float>(i % 2), 0.041f + 0.079f * static_cast<float>(i), 0.0f);
    d.velocity = Vec3(0.1f * static_cast<float>(i % 3), 0.0f, 0.0f);
    d.material = static_cast<std::uint16_t>(i % 2);
    w.add_sphere(d);
  }
  w.remove_sphere({2, 0});
  Scheduler scheduler(1);
  add_physics_systems(scheduler, w);
  FixedStepLoop loop(w, scheduler);
  for (int s = 0; s < 8; ++s) loop.step();
  return w;
}

// The pit-character scene with a few balls, walking: characters and joint colliders in the
// snapshot (the model is named, not stored: a restore imports the default character's file).
World character_world() {
  World w;
  PitCharacterScene scene;
  scene.pour.spheres = 40;
  scene.start_path(w, scene.build(w));
  Scheduler scheduler(1);
  add_character_systems(scheduler, w);
  add_physics_systems(scheduler, w);
  FixedStepLoop loop(w, scheduler);
  for (int s = 0; s < 3; ++s) loop.step();
  return w;
}

void snapshot_seeds(const fs::path& dir) {
  save_snapshot(tiny_world(true, false, false), (dir / "spinning.snap").string());
  save_snapshot(tiny_world(false, true, true), (dir / "closed_sleeping.snap").string());
  save_snapshot(character_world(), (dir / "pit_character.snap").string());
  for (const char* name : {"spinning.snap", "closed_sleeping.snap"}) {
    World w;
    load_snapshot(w, (dir / name).string());
    if (w.contacts.warm.empty()) throw std::runtime_error(std::string(name) + ": no warm-start contacts");
  }
  World w;
  load_snapshot(w, (dir / "pit_character.snap").string());
  if (w.characters.size() != 1 || w.colliders.size() == 0)
    throw std::runtime_error("pit_character.snap: no character or no joint colliders after loading");
}

void model_seeds(const fs::path& dir) {
  write(dir / "tiny_skinned.x", kTinySkinnedX);
  import_model((dir / "tiny_skinned.x").string());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  try {
    const fs::path out = argv[1];
    for (const char* target : {"scene_file", "snapshot", "model_import"}) fs::create_directories(out / target);
    scene_seeds(out / "scene_file");
    snapshot_seeds(out / "snapshot");
    model_seeds(out / "model_import");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
