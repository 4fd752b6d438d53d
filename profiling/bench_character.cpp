// The character's per-frame work, each job alone, for both models: the marine (22 joints,
// 10,248 vertices) and the Wuson (37 bones, 3205 vertices): clip sampling, blending,
// local-to-model, skinning palette, CPU skinning, the whole animation step, and the
// joint-collider update; then the pit-character scene of shared/SCENES.md (the marine) at 10k,
// 100k and 1M balls, ms per step with and without the character, so the character's cost shows.
//
// Names: "character/<job>/<marine|wuson>" (time per call, one character) and
// "pit_character/<with|without>/n:<N>/threads:<T>" (time per full step). The pit worlds are
// settled once per N (the scene's 300 steps, the character standing in the pit) and copied
// for each benchmark; settling costs the pour itself, so by default only N <= 10,000 is made
// (BALLPIT_BENCH_CHARACTER_MAX=1000000 makes all three).
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cstdlib>
#include <map>
#include <memory>

#include "engine/fixed_step_loop.h"
#include "engine/marine/marine.h"
#include "engine/model_import.h"
#include "engine/scheduler.h"
#include "engine/world.h"
#include "systems/animation.h"
#include "systems/character_pipeline.h"
#include "systems/clip_sampling.h"
#include "systems/joint_colliders.h"
#include "systems/physics_pipeline.h"
#include "systems/pit_character_scene.h"
#include "systems/skinning.h"

namespace ballpit::profiling {
namespace {

constexpr float kFrame = 1.0f / 60.0f;  // (unit: s)

// The two models and how a character plays each.
enum Who { kMarine, kWuson };
CharacterDesc desc_of(Who who) { return who == kMarine ? CharacterDesc{} : CharacterDesc::wuson(); }
std::shared_ptr<const Model> model_of(Who who) {
  static const std::shared_ptr<const Model> wuson = import_model(kWusonModelPath);
  return who == kMarine ? marine::marine_model() : wuson;
}

// A character walking in an empty pit, a second in: its pose, colliders and palette are live.
struct Walker {
  World world;
  std::unique_ptr<Scheduler> scheduler;
  std::unique_ptr<FixedStepLoop> loop;
  explicit Walker(Who who) {
    world.pit.half_width = 50.0f;
    add_character(world, model_of(who), desc_of(who));
    scheduler = std::make_unique<Scheduler>(1);
    add_character_systems(*scheduler, world);
    loop = std::make_unique<FixedStepLoop>(world, *scheduler);
    world.characters.mut_motion(0).input = {1.0f, 0.0f, false};
    for (int i = 0; i < 60; ++i) loop->step();
  }
};

void BM_SampleClip(benchmark::State& state, Who who, bool run) {
  const Model& m = *model_of(who);
  const Clip& clip = m.clips[m.clip_index(run ? desc_of(who).run_clip : desc_of(who).walk_clip)];
  ClipCursor cursor;
  cursor.reset(m.skeleton.size());
  LocalPose pose;
  float t = 0.0f;
  for (auto _ : state) {
    sample_clip(clip, t, cursor, pose);  // 60 Hz playback: the cursor moves a key or none
    benchmark::DoNotOptimize(pose.rotation.data());
    t += kFrame;
  }
  state.counters["joints"] = static_cast<double>(m.skeleton.size());
}
BENCHMARK_CAPTURE(BM_SampleClip, walk, kMarine, false)->Name("character/sample_clip/walk/marine");
BENCHMARK_CAPTURE(BM_SampleClip, run, kMarine, true)->Name("character/sample_clip/run/marine");
BENCHMARK_CAPTURE(BM_SampleClip, walk, kWuson, false)->Name("character/sample_clip/walk/wuson");
BENCHMARK_CAPTURE(BM_SampleClip, run, kWuson, true)->Name("character/sample_clip/run/wuson");

void BM_Blend(benchmark::State& state, Who who) {
  const Model& m = *model_of(who);
  ClipCursor cursor;
  cursor.reset(m.skeleton.size());
  LocalPose walk, run, out;
  sample_clip(m.clips[m.clip_index(desc_of(who).walk_clip)], 1.0f, cursor, walk);
  sample_clip(m.clips[m.clip_index(desc_of(who).run_clip)], 0.4f, cursor, run);
  const LocalPose* poses[] = {&walk, &run};
  const float weights[] = {0.4f, 0.6f};
  for (auto _ : state) {
    blend_poses(poses, weights, out);
    benchmark::DoNotOptimize(out.rotation.data());
  }
}
BENCHMARK_CAPTURE(BM_Blend, marine, kMarine)->Name("character/blend/walk_run/marine");
BENCHMARK_CAPTURE(BM_Blend, wuson, kWuson)->Name("character/blend/walk_run/wuson");

void BM_LocalToModel(benchmark::State& state, Who who) {
  const Model& m = *model_of(who);
  ClipCursor cursor;
  cursor.reset(m.skeleton.size());
  LocalPose pose;
  sample_clip(m.clips[m.clip_index(desc_of(who).run_clip)], 0.4f, cursor, pose);
  std::vector<Affine3> model;
  for (auto _ : state) {
    local_to_model(m.skeleton, pose, model);
    benchmark::DoNotOptimize(model.data());
  }
}
BENCHMARK_CAPTURE(BM_LocalToModel, marine, kMarine)->Name("character/local_to_model/marine");
BENCHMARK_CAPTURE(BM_LocalToModel, wuson, kWuson)->Name("character/local_to_model/wuson");

void BM_AnimationStep(benchmark::State& state, Who who) {
  // Phase, weights, sampling of the clips with weight, blend, local-to-model, foot slip.
  Walker w(who);
  const CharacterSetup& setup = w.world.characters.setup(0);
  const CharacterMotion& motion = w.world.characters.motion(0);
  CharacterPose& pose = w.world.characters.mut_pose(0);
  for (auto _ : state) {
    advance_pose(setup, motion, pose, kFrame);
    benchmark::DoNotOptimize(pose.model.data());
  }
}
BENCHMARK_CAPTURE(BM_AnimationStep, marine, kMarine)->Name("character/animation_step/marine");
BENCHMARK_CAPTURE(BM_AnimationStep, wuson, kWuson)->Name("character/animation_step/wuson");

void BM_SkinningPalette(benchmark::State& state, Who who) {
  Walker w(who);
  const CharacterSetup& setup = w.world.characters.setup(0);
  const CharacterPose& pose = w.world.characters.pose(0);
  const Affine3 world = character_transform(setup, w.world.characters.motion(0).current);
  std::vector<Mat4> palette;
  for (auto _ : state) {
    skinning_palette(setup.model->meshes[0], pose.model, world, palette);
    benchmark::DoNotOptimize(palette.data());
  }
  state.counters["bones"] = static_cast<double>(setup.model->meshes[0].bone_joint.size());
}
BENCHMARK_CAPTURE(BM_SkinningPalette, marine, kMarine)->Name("character/skinning_palette/marine");
BENCHMARK_CAPTURE(BM_SkinningPalette, wuson, kWuson)->Name("character/skinning_palette/wuson");

void BM_CpuSkinning(benchmark::State& state, Who who) {
  Walker w(who);
  const SkinnedMesh& mesh = w.world.characters.setup(0).model->meshes[0];
  const std::vector<Mat4>& palette = w.world.characters.pose(0).palettes[0];
  std::vector<Vec3> out;
  for (auto _ : state) {
    skin_positions(mesh, palette, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["vertices"] = static_cast<double>(mesh.positions.size());
}
BENCHMARK_CAPTURE(BM_CpuSkinning, marine, kMarine)->Name("character/cpu_skinning/marine");
BENCHMARK_CAPTURE(BM_CpuSkinning, wuson, kWuson)->Name("character/cpu_skinning/wuson");

void BM_ColliderUpdate(benchmark::State& state, Who who) {
  Walker w(who);
  for (auto _ : state) {
    update_colliders(w.world, 0);
    benchmark::DoNotOptimize(w.world.colliders.a().data());
  }
  state.counters["colliders"] = static_cast<double>(w.world.colliders.size());
}
BENCHMARK_CAPTURE(BM_ColliderUpdate, marine, kMarine)->Name("character/collider_update/marine");
BENCHMARK_CAPTURE(BM_ColliderUpdate, wuson, kWuson)->Name("character/collider_update/wuson");

// ---- the pit-character scene ------------------------------------------------------------

std::size_t character_max_spheres() {
  const char* s = std::getenv("BALLPIT_BENCH_CHARACTER_MAX");
  return s ? static_cast<std::size_t>(std::strtoull(s, nullptr, 10)) : 10000;
}

// The scene built and settled (character standing), one per N, kept for the process.
const World& settled_pit(std::size_t n, int threads) {
  static std::map<std::size_t, std::unique_ptr<World>> cache;
  auto& slot = cache[n];
  if (!slot) {
    slot = std::make_unique<World>();
    PitCharacterScene scene;
    scene.pour.spheres = n;
    scene.build(*slot);  // the marine
    omp_set_num_threads(threads);
    Scheduler scheduler(threads);
    add_character_systems(scheduler, *slot);
    add_physics_systems(scheduler, *slot);
    scene.settle(*slot, scheduler);
  }
  return *slot;
}

// Times full steps of the settled pit from the middle of the path's turn (script time 4 s):
// a second of turning, then the run. Without the character the same pit has no character
// systems and no colliders: the pour, settled in the same pit.
void BM_PitCharacter(benchmark::State& state, bool with_character) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  if (n > character_max_spheres()) {
    state.SkipWithError("settling this N takes the whole pour: set BALLPIT_BENCH_CHARACTER_MAX to run it");
    return;
  }
  World world = settled_pit(n, threads);
  if (with_character) {
    CharacterMotion& motion = world.characters.mut_motion(0);
    motion.script = PitCharacterScene::scripted_path();
    motion.script_time = 4.0f;
  } else {
    world.characters.clear();
    world.colliders.clear();
  }
  omp_set_num_threads(threads);
  Scheduler scheduler(threads);
  add_character_systems(scheduler, world);
  add_physics_systems(scheduler, world);
  FixedStepLoop loop(world, scheduler);
  for (auto _ : state) loop.step();
  state.counters["spheres"] = static_cast<double>(n);
  state.counters["colliders"] = static_cast<double>(world.colliders.size());
}

void pit_args(benchmark::internal::Benchmark* b) {
  for (std::int64_t n : {10000, 100000, 1000000})
    for (std::int64_t t : {1, 2}) b->Args({n, t});
  // 120 steps: 1 s of turning and 1 s of the run, the same steps for every N.
  b->ArgNames({"n", "threads"})->Iterations(120)->UseRealTime()->Unit(benchmark::kMillisecond);
}
BENCHMARK_CAPTURE(BM_PitCharacter, with, true)->Name("pit_character/with")->Apply(pit_args);
BENCHMARK_CAPTURE(BM_PitCharacter, without, false)->Name("pit_character/without")->Apply(pit_args);

}  // namespace
}  // namespace ballpit::profiling
