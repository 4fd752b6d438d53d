// Clip sources (engine/clip_sources.h): a character as users bring it loads and walks. Clips in
// files of their own matched by joint name (a skin file with no clip at all), sub-clips cut by
// frame range from one long take (equal to the clips they were cut from), a walk with root
// motion made in place (its gait speed the travel's), and each clip that cannot serve refused
// naming the field, the file, the clip and why. The inputs are written here: the Wuson (Debian's
// assimp-testmodels) taken apart and put together again with assimp's glTF exporter.
#include <gtest/gtest.h>

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <assimp/SceneCombiner.h>
#include <assimp/scene.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "character_fixture.h"
#include "engine/clip_sources.h"
#include "engine/error.h"
#include "engine/fixed_step_loop.h"
#include "engine/scene_file.h"
#include "engine/scheduler.h"
#include "engine/snapshot.h"
#include "engine/state_hash.h"
#include "engine/world.h"
#include "systems/character_pipeline.h"
#include "systems/clip_sampling.h"
#include "systems/locomotion.h"
#include "systems/physics_pipeline.h"
#include "systems/scene_setup.h"

using namespace ballpit;
namespace fs = std::filesystem;

namespace {

// The Wuson's clips are keyed at 30 frames a second on 4800 ticks a second.
constexpr double kTicksPerFrame = 160.0;
constexpr double kWusonTicksPerSecond = 4800.0;

// Cut clips sample like the originals to float rounding of the key times (about 1e-7 s over
// the take's 6 s, at most ~1e-6 model units of a joint's motion); 1e-5 is the brief's bound.
constexpr float kSameSample = 1e-5f;
// Gait speed from root motion: the brief's bound; the travel is recovered to float rounding.
constexpr float kSpeedTolerance = 0.02f;

struct SceneDeleter {
  void operator()(aiScene* s) const { delete s; }
};
using ScenePtr = std::unique_ptr<aiScene, SceneDeleter>;

// The Wuson as assimp reads it, untouched (no post-processing), copied so a test may edit it.
ScenePtr wuson_scene() {
  static Assimp::Importer importer;
  static const aiScene* read = importer.ReadFile(kWusonModelPath, 0);
  if (!read) throw Error("cannot read the Wuson");
  aiScene* copy = nullptr;
  Assimp::SceneCombiner::CopyScene(&copy, read);
  return ScenePtr(copy);
}

int animation_index(const aiScene& s, const std::string& name) {
  for (unsigned i = 0; i < s.mNumAnimations; ++i)
    if (name == s.mAnimations[i]->mName.C_Str()) return static_cast<int>(i);
  throw Error("no animation " + name);
}

// Keeps only the given animations (owned by the scene or taken from elsewhere, in that order).
void set_animations(aiScene& s, std::vector<aiAnimation*> keep) {
  for (unsigned i = 0; i < s.mNumAnimations; ++i)
    if (std::find(keep.begin(), keep.end(), s.mAnimations[i]) == keep.end()) delete s.mAnimations[i];
  delete[] s.mAnimations;
  s.mNumAnimations = static_cast<unsigned>(keep.size());
  s.mAnimations = keep.empty() ? nullptr : new aiAnimation*[keep.size()];
  for (std::size_t i = 0; i < keep.size(); ++i) s.mAnimations[i] = keep[i];
}

// A clip file: the node tree (the skeleton) and its animation, no mesh and so no bone.
void drop_meshes(aiScene& s) {
  for (unsigned i = 0; i < s.mNumMeshes; ++i) delete s.mMeshes[i];
  delete[] s.mMeshes;
  s.mMeshes = nullptr;
  s.mNumMeshes = 0;
  std::function<void(aiNode*)> clear = [&](aiNode* n) {
    delete[] n->mMeshes;
    n->mMeshes = nullptr;
    n->mNumMeshes = 0;
    for (unsigned i = 0; i < n->mNumChildren; ++i) clear(n->mChildren[i]);
  };
  clear(s.mRootNode);
}

void write_glb(const aiScene& s, const fs::path& path) {
  Assimp::Exporter exporter;
  if (exporter.Export(&s, "glb2", path.string()) != aiReturn_SUCCESS)
    throw Error("cannot export " + path.string() + ": " + exporter.GetErrorString());
}

// The Wuson's clip `name` alone in a clip file.
void write_clip_file(const std::string& name, const fs::path& path,
                     const std::function<void(aiAnimation&)>& edit = {}) {
  ScenePtr s = wuson_scene();
  aiAnimation* a = s->mAnimations[animation_index(*s, name)];
  if (edit) edit(*a);
  set_animations(*s, {a});
  drop_meshes(*s);
  write_glb(*s, path);
}

struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name) : path(fs::temp_directory_path() / name) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

SceneFile scene_in(const TempDir& dir, const std::string& json) {
  std::ofstream(dir.path / "scene.json") << json;
  return load_scene(dir.file("scene.json"));
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// A scene's character walking with the balls: the character and physics systems, settled,
// then its path.
struct SceneRun {
  World world;
  std::unique_ptr<Scheduler> scheduler;
  std::unique_ptr<FixedStepLoop> loop;
  SceneSetup setup;

  explicit SceneRun(const SceneFile& scene) { setup = setup_scene(scene, world); }
  void start() {
    scheduler = std::make_unique<Scheduler>(1);
    add_character_systems(*scheduler, world);
    add_physics_systems(*scheduler, world);
    loop = std::make_unique<FixedStepLoop>(world, *scheduler);
  }
  void step(int n) {
    for (int i = 0; i < n; ++i) loop->step();
  }
};

// The split character: the Wuson's skin with no clip, each clip in a glTF file of its own.
void write_split_wuson(const TempDir& dir) {
  ScenePtr skin = wuson_scene();
  set_animations(*skin, {});
  write_glb(*skin, dir.path / "skin.glb");
  write_clip_file("Wuson_Bind", dir.path / "idle.glb");
  write_clip_file("Wuson_Walk", dir.path / "walk.glb");
  write_clip_file("Wuson_Run", dir.path / "run.glb");
}

// A pit wide enough to walk in (the automatic one fits 150 balls and the character's footprint).
constexpr const char* kSplitScene = R"({
  "populations": [{"count": 150}], "pit": {"half_width": 5},
  "character": {"model": "skin.glb", "settle_steps": 30,
                "clips": {"idle": {"file": "idle.glb"}, "walk": {"file": "walk.glb"}, "run": {"file": "run.glb"}}}
})";

}  // namespace

TEST(ClipSources, ASkinWithoutClipsIsRefusedAloneButLoadsWithClipsFromOtherFiles) {
  TempDir dir("ballpit_clip_sources_split");
  write_split_wuson(dir);
  // A plain load keeps its refusal: a character needs clips.
  EXPECT_NE(error_of([&] { import_model(dir.file("skin.glb")); }).find("has no animation clips"), std::string::npos);
  EXPECT_EQ(import_model(dir.file("skin.glb"), {.require_clips = false})->clips.size(), 0u);
  // A clip file holds a skeleton and an animation only: import_model refuses it (assimp marks a
  // file without meshes incomplete), import_clips reads it.
  EXPECT_NE(error_of([&] { import_model(dir.file("walk.glb")); }), "");
  const std::vector<FileClip> walk = import_clips(dir.file("walk.glb"));
  ASSERT_EQ(walk.size(), 1u);
  EXPECT_EQ(walk[0].name, "Wuson_Walk");
}

TEST(ClipSources, ASplitFileCharacterLoadsAndWalks) {
  TempDir dir("ballpit_clip_sources_split");
  write_split_wuson(dir);
  testing::internal::CaptureStderr();
  const SceneFile scene = scene_in(dir, kSplitScene);
  SceneRun run(scene);
  const std::string warnings = testing::internal::GetCapturedStderr();
  // The clip files animate the mesh node "Wuson" too, which is no joint: one warning per file,
  // naming the file and the joint.
  EXPECT_NE(warnings.find("character.clips.walk: file '" + dir.file("walk.glb") + "' clip 'Wuson_Walk': animates joints "
                          "the model's skeleton lacks, left out: 'Wuson'"),
            std::string::npos)
      << warnings;
  ASSERT_EQ(run.world.characters.size(), 1u);
  const CharacterSetup& setup = run.world.characters.setup(0);
  EXPECT_EQ(setup.model->path, dir.file("skin.glb"));
  EXPECT_EQ(setup.model->clips.size(), 3u);
  // The gaits are the Wuson's own: the same clips, matched to the same joints by name.
  const auto wuson = test::wuson();
  const auto feet = find_feet(*wuson);
  for (int role : {kWalk, kRun}) {
    const std::size_t clip = wuson->clip_index(role == kWalk ? "Wuson_Walk" : "Wuson_Run");
    const Gait own = measure_gait(*wuson, clip, feet, setup.scale, setup.forward);
    EXPECT_NEAR(setup.gaits[role].speed, own.speed, 0.01f * own.speed) << role;
  }
  settle_scene(run.setup, run.world, *(run.start(), run.scheduler));
  start_scene_path(run.setup, run.world);
  const Vec3 start = run.world.characters.motion(0).current.position;
  run.step(300);  // 5 s of the path: 3 s walking, 2 s walking and turning
  const RootState& now = run.world.characters.motion(0).current;
  EXPECT_TRUE(all_finite(now.position));
  // Walked: at least a metre at the Wuson's ~0.5 m/s walk.
  EXPECT_GT((now.position - start).norm(), 1.0f);
  EXPECT_GT(run.world.characters.pose(0).weights[kWalk], 0.0f);
}

TEST(ClipSources, ASavedSplitCharacterResumesFromItsSources) {
  TempDir dir("ballpit_clip_sources_snapshot");
  write_split_wuson(dir);
  const SceneFile scene = scene_in(dir, kSplitScene);
  auto walked = [&](int first, int then, const std::string& save) {
    auto run = std::make_unique<SceneRun>(scene);
    run->start();
    settle_scene(run->setup, run->world, *run->scheduler);
    start_scene_path(run->setup, run->world);
    run->step(first);
    if (!save.empty()) save_snapshot(run->world, save);
    run->step(then);
    return run;
  };
  const auto straight = walked(60, 60, "");
  walked(60, 0, dir.file("walk.snap"));
  // A fresh world from the file alone: the derived model is rebuilt from the sources it names.
  SceneRun resumed(SceneFile{});
  load_snapshot(resumed.world, dir.file("walk.snap"));
  ASSERT_EQ(resumed.world.characters.size(), 1u);
  EXPECT_TRUE(is_clip_sources_name(resumed.world.characters.setup(0).model->load_name));
  resumed.start();
  resumed.step(60);
  EXPECT_EQ(hash_hex(state_hash(resumed.world)), hash_hex(state_hash(straight->world)));
}

TEST(ClipSources, SubClipsCutByFrameRangeFromOneTakeSampleAsTheOriginals) {
  TempDir dir("ballpit_clip_sources_take");
  // One take, as older formats keep every action: the walk (frames 0..108), a second of
  // nothing, then the run (frames 138..167), with the skin in the same file.
  ScenePtr s = wuson_scene();
  const aiAnimation& walk = *s->mAnimations[animation_index(*s, "Wuson_Walk")];
  const aiAnimation& run = *s->mAnimations[animation_index(*s, "Wuson_Run")];
  const double run_start = walk.mDuration + kWusonTicksPerSecond;  // (unit: ticks)
  auto* take = new aiAnimation;
  take->mName = aiString("Take 001");
  take->mTicksPerSecond = kWusonTicksPerSecond;
  take->mDuration = run_start + run.mDuration;
  take->mNumChannels = walk.mNumChannels;
  take->mChannels = new aiNodeAnim*[walk.mNumChannels];
  auto concat = [](auto*& out, unsigned& n, const auto* a, unsigned na, const auto* b, unsigned nb, double shift) {
    using Key = std::remove_const_t<std::remove_pointer_t<decltype(a)>>;
    n = na + nb;
    out = new Key[n];
    for (unsigned k = 0; k < na; ++k) out[k] = a[k];
    for (unsigned k = 0; k < nb; ++k) {
      out[na + k] = b[k];
      out[na + k].mTime += shift;
    }
  };
  for (unsigned c = 0; c < walk.mNumChannels; ++c) {
    const aiNodeAnim& w = *walk.mChannels[c];
    const aiNodeAnim* r = nullptr;
    for (unsigned k = 0; k < run.mNumChannels; ++k)
      if (run.mChannels[k]->mNodeName == w.mNodeName) r = run.mChannels[k];
    ASSERT_NE(r, nullptr);
    auto* ch = new aiNodeAnim;
    ch->mNodeName = w.mNodeName;
    concat(ch->mPositionKeys, ch->mNumPositionKeys, w.mPositionKeys, w.mNumPositionKeys, r->mPositionKeys,
           r->mNumPositionKeys, run_start);
    concat(ch->mRotationKeys, ch->mNumRotationKeys, w.mRotationKeys, w.mNumRotationKeys, r->mRotationKeys,
           r->mNumRotationKeys, run_start);
    concat(ch->mScalingKeys, ch->mNumScalingKeys, w.mScalingKeys, w.mNumScalingKeys, r->mScalingKeys,
           r->mNumScalingKeys, run_start);
    take->mChannels[c] = ch;
  }
  const double run_first = run_start / kTicksPerFrame, run_last = (run_start + run.mDuration) / kTicksPerFrame;
  ASSERT_EQ(run_first, 138.0);
  ASSERT_EQ(run_last, 167.0);
  set_animations(*s, {take});  // (walk and run are gone from here on)
  write_glb(*s, dir.path / "take.glb");
  const SceneFile good = scene_in(dir, R"({"populations": [{"count": 20}], "character": {"model": "take.glb",
      "clips": {"idle": {"range": [0, 1], "range_unit": "frames", "fps": 30},
                "walk": {"range": [0, 108], "range_unit": "frames", "fps": 30, "root_motion": "keep"},
                "run": {"clip": "Take 001", "range": [138, 167], "range_unit": "frames", "fps": 30}}}})");
  SceneRun cut(good);
  ASSERT_EQ(cut.world.characters.size(), 1u);
  const Model& m = *cut.world.characters.setup(0).model;
  const Model& wuson = *test::wuson();
  for (const char* role : {"walk", "run"}) {
    const bool is_walk = std::string(role) == "walk";
    const Clip& original = wuson.clips[wuson.clip_index(is_walk ? "Wuson_Walk" : "Wuson_Run")];
    const CharacterDesc desc = character_desc(*good.character);
    const Clip& sub = m.clips[m.clip_index(is_walk ? desc.walk_clip : desc.run_clip)];
    EXPECT_NEAR(sub.duration, original.duration, 1e-6f) << role;
    EXPECT_EQ(sub.root_speed, 0.0f) << role << ": the Wuson walks in place: auto root motion leaves it";
    // Sampled over two cycles (the seam included) at times off the keys: every joint the
    // original animates, by name, in the cut clip's skeleton.
    ClipCursor ca, cb;
    ca.reset(wuson.skeleton.size());
    cb.reset(m.skeleton.size());
    LocalPose a, b;
    float worst = 0.0f;
    for (int i = 0; i < 400; ++i) {
      const float t = 2.0f * original.duration * static_cast<float>(i) / 400.0f + 0.0013f;
      sample_clip(original, t, ca, a);
      sample_clip(sub, t, cb, b);
      for (std::size_t j = 0; j < wuson.skeleton.size(); ++j) {
        const int k = m.skeleton.find(wuson.skeleton.names[j]);
        ASSERT_GE(k, 0) << wuson.skeleton.names[j];
        const std::size_t jk = static_cast<std::size_t>(k);
        worst = std::max(worst, (a.translation[j] - b.translation[jk]).norm());
        worst = std::max(worst, std::abs(std::abs(a.rotation[j].dot(b.rotation[jk])) - 1.0f));
        worst = std::max(worst, (a.rotation[j].coeffs() - (a.rotation[j].dot(b.rotation[jk]) < 0.0f ? -1.0f : 1.0f) *
                                                             b.rotation[jk].coeffs()).norm());
        worst = std::max(worst, (a.scale[j] - b.scale[jk]).norm());
      }
    }
    EXPECT_LT(worst, kSameSample) << role;
  }
}

TEST(ClipSources, AWalkWithRootMotionIsMadeInPlaceAndWalksAtItsTravelSpeed) {
  TempDir dir("ballpit_clip_sources_root_motion");
  // The Wuson's walk plays in place. Its gait speed from the feet, in model units per second:
  const Model& wuson = *test::wuson();
  const std::size_t walk_index = wuson.clip_index("Wuson_Walk");
  const Gait feet_gait = measure_gait(wuson, walk_index, find_feet(wuson), 1.0f, Vec3::UnitZ());
  // Root motion 10% faster than the feet's estimate, so the test tells the two figures apart
  // (a travel the feet follow that closely is still a cycle: its slip stays under the bound).
  const float speed = 1.1f * feet_gait.speed;  // (unit: model units/s)
  const int root = wuson.skeleton.find("Root");
  ASSERT_GE(root, 0);
  // The root's parent's linear part in model space (the rest pose: its ancestors do not move).
  Affine3 parent = Affine3::Identity();
  const std::vector<std::int32_t>& parents = wuson.skeleton.parents;
  std::vector<int> chain;
  for (int p = parents[static_cast<std::size_t>(root)]; p >= 0; p = parents[static_cast<std::size_t>(p)]) chain.push_back(p);
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
    Affine3 l;
    const std::size_t j = static_cast<std::size_t>(*it);
    l.fromPositionOrientationScale(wuson.skeleton.rest_translation[j], wuson.skeleton.rest_rotation[j],
                                   wuson.skeleton.rest_scale[j]);
    parent = parent * l;
  }
  const Mat3 to_local = parent.linear().inverse();
  write_clip_file("Wuson_Walk", dir.path / "walk_travelling.glb", [&](aiAnimation& a) {
    for (unsigned c = 0; c < a.mNumChannels; ++c) {
      aiNodeAnim& ch = *a.mChannels[c];
      if (std::string(ch.mNodeName.C_Str()) != "Root") continue;
      // One position key per frame, travelling forward (+z, the Wuson's facing) at `speed`.
      const aiVector3D p0 = ch.mPositionKeys[0].mValue;
      const unsigned n = static_cast<unsigned>(a.mDuration / kTicksPerFrame) + 1;
      delete[] ch.mPositionKeys;
      ch.mPositionKeys = new aiVectorKey[n];
      ch.mNumPositionKeys = n;
      for (unsigned k = 0; k < n; ++k) {
        const double ticks = k * kTicksPerFrame;
        const Vec3 d = to_local * (Vec3::UnitZ() * speed * static_cast<float>(ticks / a.mTicksPerSecond));
        ch.mPositionKeys[k] = aiVectorKey(ticks, p0 + aiVector3D(d.x(), d.y(), d.z()));
      }
    }
  });
  const std::string wuson_clips = R"("idle": "Wuson_Bind", "run": "Wuson_Run")";
  const SceneFile scene = scene_in(dir, R"({"populations": [{"count": 20}], "character": {"model": ")" +
                                            std::string(kWusonModelPath) + R"(", "clips": {)" + wuson_clips +
                                            R"(, "walk": {"file": "walk_travelling.glb"}}}})");
  SceneRun run(scene);
  ASSERT_EQ(run.world.characters.size(), 1u);
  const CharacterSetup& setup = run.world.characters.setup(0);
  const Clip& walk = setup.model->clips[setup.clips[kWalk]];
  EXPECT_NEAR(walk.root_speed, speed, 1e-4f * speed);
  // In place: every root key is back where the walk started, to float rounding of the travel.
  const JointTrack& track = walk.tracks[static_cast<std::size_t>(root)];
  ASSERT_GT(track.translations.size(), 100u);
  for (const Vec3& p : track.translations)
    EXPECT_LT((p - track.translations.front()).norm(), 1e-4f * wuson.bind_height());
  // The gait speed is the travel's, in metres per second at the character's scale; the feet's
  // estimate (10% slower, by construction) is not used.
  EXPECT_NEAR(setup.gaits[kWalk].speed, speed * setup.scale, kSpeedTolerance * speed * setup.scale);
  std::printf("root-motion walk: travel %.4f m/s, the feet's estimate %.4f m/s, slip at the travel %.3f\n",
              speed * setup.scale, feet_gait.speed * setup.scale, setup.gaits[kWalk].slip);
  // Kept as it is, the walk carries its feet along with the root: no foot stays planted at any
  // ground speed, so it is not a locomotion cycle (why walk and run default to in place).
  const SceneFile kept = scene_in(dir, R"({"populations": [{"count": 20}], "character": {"model": ")" +
                                           std::string(kWusonModelPath) + R"(", "clips": {)" + wuson_clips +
                                           R"(, "walk": {"file": "walk_travelling.glb", "root_motion": "keep"}}}})");
  const std::string m = error_of([&] { SceneRun k(kept); });
  EXPECT_NE(m.find("character.clips.walk: character from model file '" + std::string(kWusonModelPath) +
                   "': walk clip 'walk from walk_travelling.glb (its only clip)' is not a locomotion cycle"),
            std::string::npos)
      << m;
}

TEST(ClipSources, EachClipThatCannotServeIsRefusedNamingFieldFileClipAndWhy) {
  TempDir dir("ballpit_clip_sources_errors");
  write_split_wuson(dir);
  {
    // Another rig: the walk on a skeleton whose every joint has another name.
    ScenePtr s = wuson_scene();
    aiAnimation* a = s->mAnimations[animation_index(*s, "Wuson_Walk")];
    set_animations(*s, {a});
    drop_meshes(*s);
    auto other = [](aiString& name) { name = aiString(std::string("other:") + name.C_Str()); };
    for (unsigned c = 0; c < a->mNumChannels; ++c) other(a->mChannels[c]->mNodeName);
    std::function<void(aiNode*)> rename = [&](aiNode* n) {
      other(n->mName);
      for (unsigned i = 0; i < n->mNumChildren; ++i) rename(n->mChildren[i]);
    };
    rename(s->mRootNode);
    write_glb(*s, dir.path / "strange.glb");
  }
  const std::string skin = dir.file("skin.glb");
  auto refusal = [&](const std::string& clips) {
    return error_of([&] {
      const std::string head = R"({"populations": [{"count": 20}], "character": {"model": "skin.glb", "clips": )";
      SceneRun run(scene_in(dir, head + clips + "}}"));
    });
  };
  const std::string scene = dir.file("scene.json");
  const std::string ok = R"("idle": {"file": "idle.glb"}, "run": {"file": "run.glb"})";

  std::string m = refusal(R"({"walk": {"file": "missing.glb"}, )" + ok + "}");
  EXPECT_NE(m.find(scene + ": character.clips.walk.file: expected an existing clip file, '" + dir.file("missing.glb") +
                   "' does not exist"),
            std::string::npos)
      << m;

  m = refusal(R"({"walk": {"file": "walk.glb", "clip": "Moonwalk"}, )" + ok + "}");
  EXPECT_NE(m.find(scene + ": character.clips.walk: file '" + dir.file("walk.glb") +
                   "' has no clip named 'Moonwalk' (its clips: 'Wuson_Walk')"),
            std::string::npos)
      << m;

  m = refusal(R"({"walk": {"file": "strange.glb"}, )" + ok + "}");
  EXPECT_NE(m.find(scene + ": character.clips.walk: file '" + dir.file("strange.glb") +
                   "' clip 'Wuson_Walk': none of the 39 joints it animates ('other:"),
            std::string::npos)
      << m;
  EXPECT_NE(m.find("is a joint of the model's skeleton ('$dummy_root', 'Root', "), std::string::npos) << m;

  m = refusal(R"({"walk": {"file": "walk.glb", "range": [2, 5]}, )" + ok + "}");
  EXPECT_NE(m.find(scene + ": character.clips.walk: file '" + dir.file("walk.glb") +
                   "' clip 'Wuson_Walk': range [2, 5] s lies outside the take (0 to 3.6 s)"),
            std::string::npos)
      << m;

  m = refusal(R"({"walk": {"file": "walk.glb", "root_joint": "Hips"}, )" + ok + "}");
  EXPECT_NE(m.find(scene + ": character.clips.walk: file '" + dir.file("walk.glb") +
                   "' clip 'Wuson_Walk': root_joint 'Hips' is not a joint of the model's skeleton"),
            std::string::npos)
      << m;

  // Not a cycle: the bind pose as the walk (the existing spawn check, naming the field).
  m = refusal(R"({"walk": {"file": "idle.glb"}, )" + ok + "}");
  EXPECT_NE(m.find(scene + ": character.clips.walk: "), std::string::npos) << m;
  EXPECT_NE(m.find("walk clip 'walk from idle.glb (its only clip)' is not a locomotion cycle"), std::string::npos) << m;

  // A file of several clips needs the name of one.
  m = error_of([&] {
    const std::string clips = R"("clips": {"idle": "Wuson_Bind", "walk": {"range": [0, 1]}, "run": "Wuson_Run"})";
    SceneRun run(scene_in(dir, R"({"populations": [{"count": 20}], "character": {"model": ")" +
                                   std::string(kWusonModelPath) + "\", " + clips + "}}"));
  });
  EXPECT_NE(m.find(": character.clips.walk: file '" + std::string(kWusonModelPath) + "' holds 3 clips ("), std::string::npos)
      << m;
  EXPECT_NE(m.find("name one with \"clip\""), std::string::npos) << m;

  // Scene-file mistakes are refused as the file is read.
  m = refusal(R"({"walk": {"file": "walk.glb", "range": [3, 1]}, )" + ok + "}");
  EXPECT_NE(m.find("character.clips.walk.range: expected an end after the start, got [3,1]"), std::string::npos) << m;
  m = refusal(R"({"walk": {"file": "walk.glb", "root_motion": "drop"}, )" + ok + "}");
  EXPECT_NE(m.find("character.clips.walk.root_motion: expected \"auto\", \"keep\" or \"in_place\", got string \"drop\""),
            std::string::npos)
      << m;
  m = refusal(R"({"walk": 3, )" + ok + "}");
  EXPECT_NE(m.find("character.clips.walk: expected a clip name or {"), std::string::npos) << m;
  m = refusal(R"({"walk": "", )" + ok + "}");
  EXPECT_NE(m.find("character.clips.walk: expected a clip name"), std::string::npos) << m;
}

TEST(ClipSources, TheCharacterSectionRoundTripsWithEveryClipForm) {
  TempDir dir("ballpit_clip_sources_json");
  write_split_wuson(dir);
  const SceneFile scene = scene_in(dir, R"({"character": {"model": "skin.glb", "clips": {
      "idle": {"file": "idle.glb"},
      "walk": {"file": "walk.glb", "clip": "Wuson_Walk", "range": [0.5, 2.5], "root_motion": "in_place", "root_joint": "Root"},
      "run": {"file": "run.glb", "range": [0, 29], "range_unit": "frames", "fps": 30, "root_motion": "keep"},
      "jump": "", "kick": {"file": "walk.glb"}}}})");
  const RoleClips& c = scene.character->clips;
  EXPECT_EQ(c[1].file, dir.file("walk.glb"));  // beside the scene file
  EXPECT_EQ(c[1].range.value()[1], 2.5);
  EXPECT_EQ(c[1].root_motion, ClipSource::RootMotion::InPlace);
  EXPECT_EQ(c[2].unit, ClipSource::Unit::Frames);
  EXPECT_EQ(c[2].fps, 30.0);
  EXPECT_TRUE(c[3].none());
  EXPECT_EQ(c[4].root_motion, ClipSource::RootMotion::Auto);
  const auto j = scene_to_json(scene);
  const SceneFile again = parse_scene(j, "again");
  EXPECT_EQ(scene_to_json(again), j);
  EXPECT_TRUE(again.character->clips == c);
  // The description names the derived clips; jump is none, kick plays once.
  const CharacterDesc d = character_desc(*scene.character);
  EXPECT_TRUE(is_clip_sources_name(d.model_path));
  EXPECT_EQ(d.jump_clip, "");
  EXPECT_EQ(d.kick_clip, "kick from walk.glb (its only clip)");
  const auto model = load_model(d.model_path);
  EXPECT_FALSE(model->clips[model->clip_index(d.kick_clip)].looping);
  EXPECT_TRUE(model->clips[model->clip_index(d.walk_clip)].looping);
  EXPECT_NEAR(model->clips[model->clip_index(d.walk_clip)].duration, 2.0f, 1e-6f);
}
