// Scene files: every field round-trips and is reachable by --set, list elements included; each
// kind of mistake is refused with the file, the field path and what was expected; a scene
// builds exactly what it describes (the default scene is the canonical pour bit for bit) and
// nothing it does not use.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/error.h"
#include "engine/pour_scene.h"
#include "engine/scene_file.h"
#include "engine/scheduler.h"
#include "engine/state_hash.h"
#include "engine/world.h"
#include "character_fixture.h"
#include "systems/character_pipeline.h"
#include "systems/physics_pipeline.h"
#include "systems/pit_character_scene.h"
#include "systems/scene_setup.h"

using namespace ballpit;
using Json = nlohmann::ordered_json;

namespace {

// The message parse_scene throws for j, or "" if it accepts it.
std::string refusal(const Json& j) {
  try {
    parse_scene(j, "test.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// The complete JSON of a default scene with its optional sections present (a character, a
// pit material), so every field of the format appears in it.
Json complete_default() {
  SceneFile s;
  s.character = SceneCharacter{};
  return scene_to_json(s);
}

// A scene with every field moved off its default, each variant in one population: fixed,
// uniform and normal radii; mass and density; every colour scheme; lattice and box placement.
SceneFile every_field_moved() {
  SceneFile s;
  s.dt = 1.0f / 120.0f;
  s.steps = 90;
  s.seed = 7;
  s.gravity = Vec3(1.0f, -3.0f, 0.5f);
  s.pit.half_width = 1.9f;
  s.pit.wall_height = 5.0f;
  s.pit.closed = true;
  s.pit.material = Material{0.25f, 0.75f};
  Population& a = s.populations[0];
  a.count = 1234;
  a.radius.value = 0.03f;
  a.mass = 0.07f;
  a.material = {0.3f, 0.0f};
  a.color.kind = ColorScheme::Kind::ByHeight;
  a.color.from = 0xff010203u;
  a.color.to = 0xff040506u;
  a.placement.kind = Placement::Kind::Box;
  a.placement.spacing_r = 2.5f;
  a.placement.jitter_r = 0.1f;
  a.placement.min = Vec3(-1.0f, 0.0f, -1.0f);
  a.placement.max = Vec3(1.0f, 2.0f, 1.0f);
  a.velocity = Vec3(0.5f, -1.0f, 2.0f);
  a.velocity_jitter = 0.25f;
  a.spin = Vec3(1.0f, 2.0f, -3.0f);
  Population b;
  b.count = 40;
  b.radius.kind = RadiusSpec::Kind::Uniform;
  b.radius.min = 0.02f;
  b.radius.max = 0.05f;
  b.density = 300.0f;
  b.color.palette = {0xff0000ffu, 0xff00ff00u};
  Population c;
  c.count = 41;
  c.radius.kind = RadiusSpec::Kind::Normal;
  c.radius.mean = 0.04f;
  c.radius.sd = 0.01f;
  c.radius.min = 0.03f;
  c.radius.max = 0.06f;
  c.color.kind = ColorScheme::Kind::ByRadius;
  c.color.from = 0xff010203u;
  c.color.to = 0xff040506u;
  Population d = c;
  d.color.kind = ColorScheme::Kind::Solid;
  d.color.color = 0xff102030u;
  s.populations.insert(s.populations.end(), {b, c, d});
  SceneCharacter ch;
  ch.model = test::kEpilepticPath;
  ch.scale = 0.02f;
  ch.clips = {ClipSource::named("Stand"), ClipSource::named("Walk"), ClipSource{}, ClipSource::named("Stand"), ClipSource{}};
  // A clip from a file, cut by frames, its root motion made in place (engine/clip_sources.h).
  ClipSource& run = ch.clips[kRun];
  run.file = test::kEpilepticPath;
  run.clip = "Run";
  run.range = std::array<double, 2>{2.0, 30.0};
  run.unit = ClipSource::Unit::Frames;
  run.fps = 24.0;
  run.root_motion = ClipSource::RootMotion::InPlace;
  run.root_joint = "Bip01";
  ClipSource& kick = ch.clips[4];  // a range in seconds of the model's own clip, root motion left to the role
  kick.clip = "Walk";
  kick.range = std::array<double, 2>{0.25, 0.75};
  kick.root_motion = ClipSource::RootMotion::Auto;
  ch.forward = Vec3(1.0f, 0.25f, 0.0f);
  ch.colliders = ColliderKind::Spheres;
  ch.scripted = false;
  ch.path = {{1.5f, {-0.5f, -0.25f, true}}, {1.0f, {0.5f, -1.0f, true}}};
  ch.settle_steps = 12;
  ch.foot_clearance_r = 3.0f;
  ch.controller = {0.4f, 1.2f, 0.3f, 1.0f, 2.0f, 0.3f, 0.2f};
  s.character = ch;
  s.features.angular = FeatureSwitch::On;
  s.features.character = FeatureSwitch::Off;
  s.solver.substeps = 3;
  s.solver.solve_sweeps = 2;
  s.solver.push_out_rate = 0.3f;
  s.solver.push_out_speed = 2.0f;
  s.solver.restitution_threshold = 0.0f;
  s.solver.linear_damping = 0.1f;
  s.solver.angular_damping = 0.2f;
  s.solver.narrowphase = NarrowphaseMode::Naive;
  s.solver.sleeping = true;
  s.solver.sleep_speed = 0.03f;
  s.solver.sleep_time = 0.7f;
  s.solver.wake_speed = 0.09f;
  return s;
}

// "a.b.c=value" for every field of j: objects are entered, populations by index; a value
// whose shape selects its keys (a radius, colour scheme, placement, the pit material) or a
// list is set whole.
void overrides_for(const Json& j, const std::string& path, std::vector<std::string>& out) {
  const std::string last = path.substr(path.rfind('.') + 1);
  // A clip source is a name or an object: set whole, like the radius.
  const bool whole = last == "radius" || last == "color" || last == "placement" || path == "pit.material" ||
                     path.rfind("character.clips.", 0) == 0;
  if (j.is_object() && !whole) {
    for (const auto& [key, value] : j.items()) overrides_for(value, path.empty() ? key : path + "." + key, out);
  } else if (j.is_array() && path == "populations") {
    for (std::size_t i = 0; i < j.size(); ++i) overrides_for(j[i], path + "." + std::to_string(i), out);
  } else {
    out.push_back(path + "=" + j.dump());
  }
}

// Pairs of spheres that overlap, by checking every pair (the worlds here are small).
std::size_t overlapping_pairs(const World& w) {
  auto x = w.spheres.position();
  auto r = w.spheres.radius();
  std::size_t overlapping = 0;
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = i + 1; j < x.size(); ++j)
      if ((x[i] - x[j]).squaredNorm() < (r[i] + r[j]) * (r[i] + r[j])) ++overlapping;
  return overlapping;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

bool scheduled(Scheduler& s, std::string_view name) {
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.system(i).name() == name) return true;
  return false;
}

}  // namespace

TEST(SceneFile, EveryFieldRoundTrips) {
  const SceneFile s = every_field_moved();
  const Json j = scene_to_json(s);
  EXPECT_EQ(scene_to_json(parse_scene(j, "test.json")), j);
  // Every field of the format (the default's complete JSON, flattened to its leaves) is moved:
  // its leaf is either gone (a different shape: a distribution for a number) or different.
  const Json moved = j.flatten();
  const Json defaults = complete_default().flatten();
  for (const auto& [leaf, value] : defaults.items())
    EXPECT_TRUE(!moved.contains(leaf) || moved[leaf] != value) << leaf << " keeps its default " << value;
  // A file with no keys at all is the default scene.
  EXPECT_EQ(scene_to_json(parse_scene(Json::object(), "test.json")), scene_to_json(SceneFile{}));
  // Alternative spellings come back in the canonical one: a width as a half width.
  const SceneFile w = parse_scene(Json::parse(R"({"pit": {"width": 3.0}})"), "test.json");
  EXPECT_EQ(w.pit.half_width, 1.5f);
}

TEST(SceneFile, TheShippedScenesAreTheBuiltInOnes) {
  EXPECT_EQ(scene_to_json(load_scene(BALLPIT_SCENES_DIR "/pour.json")), scene_to_json(SceneFile{}));
  EXPECT_EQ(scene_to_json(load_scene(BALLPIT_SCENES_DIR "/pit_character.json")),
            scene_to_json(builtin_scene("pit-character")));
  EXPECT_EQ(scene_to_json(load_scene("pit-character")), scene_to_json(builtin_scene("pit-character")));
  // The second model's scene: the Wuson with its own clips and no actions, which builds.
  const SceneFile wuson = load_scene(BALLPIT_SCENES_DIR "/pit_character_wuson.json", {"populations.0.count=200"});
  ASSERT_TRUE(wuson.character.has_value());
  EXPECT_EQ(wuson.character->model, kWusonModelPath);
  World w;
  EXPECT_TRUE(setup_scene(wuson, w, test::wuson()).character.valid());
  const SceneFile mixed = load_scene(BALLPIT_SCENES_DIR "/mixed.json");
  ASSERT_EQ(mixed.populations.size(), 3u);
  EXPECT_EQ(mixed.populations[0].radius.kind, RadiusSpec::Kind::Normal);
  EXPECT_EQ(mixed.populations[1].radius.kind, RadiusSpec::Kind::Uniform);
  EXPECT_EQ(mixed.populations[2].placement.kind, Placement::Kind::Box);
  // The canonical path is defined once: the scene file's default is the pit-character scene's.
  const auto a = SceneCharacter::default_path(), b = PitCharacterScene::scripted_path();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].duration, b[i].duration);
    EXPECT_EQ(a[i].input.forward, b[i].input.forward);
    EXPECT_EQ(a[i].input.turn, b[i].input.turn);
    EXPECT_EQ(a[i].input.run, b[i].input.run);
  }
}

TEST(SceneFile, AnUnknownKeyIsAnErrorNamingItsPath) {
  const std::string m = refusal(Json::parse(R"({"populations": [{"count": 3, "colour": "red"}]})"));
  EXPECT_NE(m.find("test.json: populations.0.colour: unknown key"), std::string::npos) << m;
  EXPECT_NE(m.find("color"), std::string::npos) << "the message lists the known keys: " << m;
  EXPECT_NE(refusal(Json::parse(R"({"pour": {"spheres": 3}})")).find("test.json: pour: unknown key: the pour section of older"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"character": {"hieght": 2}})")).find("test.json: character.hieght: unknown key"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"populations": [{"color": {"scheme": "solid", "palette": []}}]})"))
                .find("populations.0.color.palette: unknown key (known keys here: scheme, color)"),
            std::string::npos);
}

TEST(SceneFile, AWrongTypeIsAnErrorNamingWhatWasExpected) {
  EXPECT_NE(refusal(Json::parse(R"({"populations": [{"radius": "big"}]})"))
                .find("test.json: populations.0.radius: expected a number (m) or a distribution"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"populations": [{"count": 2.5}]})")).find("populations.0.count: expected an integer"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"populations": {"count": 2}})")).find("populations: expected a list of at least one"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"features": {"sleeping": 1}})")).find("features.sleeping: expected true or false"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"features": {"angular": "yes"}})")).find("features.angular: expected \"auto\", true or false"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"gravity": [0, -9.81]})")).find("gravity: expected [x, y, z]"), std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"solver": 8})")).find("solver: expected an object"), std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"populations": [{"color": {"scheme": "solid", "color": "red"}}]})"))
                .find("populations.0.color.color: expected a colour \"#rrggbb\""),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"character": {"height": "tall"}})")).find("character.height: expected a number (m)"),
            std::string::npos);
}

TEST(SceneFile, ANegativeRadiusIsRefused) {
  EXPECT_NE(refusal(Json::parse(R"({"populations": [{"radius": -0.1}]})"))
                .find("test.json: populations.0.radius: expected a number > 0 (m), got -0.1"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"populations": [{"radius": {"distribution": "uniform", "min": -0.01, "max": 0.05}}]})"))
                .find("populations.0.radius.min: expected a number > 0 (m), got -0.01"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"populations": [{"radius": {"distribution": "uniform", "min": 0.05, "max": 0.01}}]})"))
                .find("populations.0.radius.max: expected a number >= 0.05 (m), got 0.01"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"populations": [{"radius": {"distribution": "normal", "mean": 0.04, "min": 0.02, "max": 0.06}}]})"))
                .find("populations.0.radius.sd: missing: expected a number >= 0 (m)"),
            std::string::npos);
}

TEST(SceneFile, OutOfRangeValuesAreRefused) {
  EXPECT_NE(refusal(Json::parse(R"({"populations": [{"material": {"restitution": 1.5}}]})"))
                .find("populations.0.material.restitution: expected a number >= 0 and <= 1"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"populations": [{"mass": 1e-44}]})")).find("populations.0.mass: expected a mass whose inverse is finite"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"populations": [{"mass": 0.1, "density": 200}]})"))
                .find("populations.0.density: expected either mass or density, not both"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"populations": [{"placement": {"spacing_r": 2.05}}]})"))
                .find("populations.0.placement.spacing_r: expected a number >= 2 + 2 x jitter_r = 2.1"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"populations": [{"placement": {"kind": "box", "min": [0, 0, 0], "max": [9, 1, 1]}}]})"))
                .find("populations.0.placement: expected a box inside the pit"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"solver": {"substeps": 0}})")).find("solver.substeps: expected an integer in [1, 64]"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"solver": {"solve_sweeps": 0}})")).find("solver.solve_sweeps: expected an integer in [1, 16]"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"solver": {"narrowphase": "fast"}})")).find("solver.narrowphase: expected \"grid\" or \"naive\""),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"features": {"character": true}})"))
                .find("features.character: expected \"auto\" or false: the scene has no character section"),
            std::string::npos);
}

TEST(SceneFile, APitSmallerThanOneSphereIsRefused) {
  // One sphere gets an automatic pit sqrt(5.6e-4) = 2.4 cm wide: a 10 cm ball cannot fit.
  const std::string m = refusal(Json::parse(R"({"populations": [{"count": 1, "radius": 0.1}]})"));
  EXPECT_NE(m.find("test.json: populations.0.radius: a sphere of radius 0.1"), std::string::npos) << m;
  EXPECT_NE(m.find("does not fit in the pit"), std::string::npos) << m;
  // A pit given by size names the pit's field.
  EXPECT_NE(refusal(Json::parse(R"({"pit": {"half_width": 0.03}})"))
                .find("test.json: pit.half_width: expected a pit wider than one sphere (populations.0 has radius 0.04 m), got half width 0.03 m"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"pit": {"width": 0.06}})")).find("test.json: pit.width: expected a pit wider than one sphere"),
            std::string::npos);
}

TEST(SceneFile, AMissingModelFileIsRefused) {
  const std::string m = refusal(Json::parse(R"({"character": {"model": "/nonexistent/wuson.X"}})"));
  EXPECT_NE(m.find("test.json: character.model: expected an existing model file or \"builtin:marine\", '/nonexistent/wuson.X' does not exist"),
            std::string::npos)
      << m;
}

TEST(SceneFile, AnUnknownClipNameIsRefusedNamingTheField) {
  // The clip names are the model's, so they are checked when the scene is built (the model is
  // imported then), still naming the file and the field.
  const SceneFile s = parse_scene(Json::parse(R"({"character": {"clips": {"walk": "Moonwalk"}}})"), "test.json");
  World w;
  const std::string m = error_of([&] { setup_scene(s, w); });
  EXPECT_NE(m.find("test.json: character.clips.walk: expected a clip of model file 'builtin:marine' (its clips: "),
            std::string::npos)
      << m;
  EXPECT_NE(m.find("got 'Moonwalk'"), std::string::npos) << m;
  EXPECT_EQ(w.characters.size(), 0u);
}

TEST(SceneFile, OverridesReachEveryFieldIncludingListElements) {
  // Every field of the moved scene, set one by one on the default's complete JSON, gives the
  // moved scene: populations 1..3 are appended by their index.
  const SceneFile moved = every_field_moved();
  std::vector<std::string> assignments;
  overrides_for(scene_to_json(moved), "", assignments);
  Json j = complete_default();
  for (const std::string& a : assignments) apply_override(j, a);
  EXPECT_EQ(scene_to_json(parse_scene(j, "test.json")), scene_to_json(moved));

  // The command line's way: a built-in scene with --set, list elements by index.
  SceneFile s = load_scene("", {"populations.0.radius=0.05", "populations.0.count=500", "solver.narrowphase=naive",
                                "gravity=[0, -1.62, 0]", "populations.1={\"count\": 20, \"radius\": 0.02}",
                                "populations.0.density=150", "pit.width=4"});
  ASSERT_EQ(s.populations.size(), 2u);
  EXPECT_EQ(s.populations[0].radius.value, 0.05f);
  EXPECT_EQ(s.populations[0].count, 500u);
  EXPECT_EQ(s.populations[0].density, 150.0f);  // density replaced mass
  EXPECT_EQ(s.populations[1].count, 20u);
  EXPECT_EQ(s.pit.half_width, 2.0f);  // width replaced the automatic half width
  EXPECT_EQ(s.solver.narrowphase, NarrowphaseMode::Naive);  // a bare word is a string
  EXPECT_EQ(s.gravity.y(), -1.62f);
  EXPECT_TRUE(load_scene("", {"character.height=2"}).character.has_value()) << "--set can add a character";
  EXPECT_FALSE(load_scene("pit-character", {"character=null"}).character.has_value()) << "and take it away";

  // Mistakes name the assignment or the field.
  EXPECT_NE(error_of([] { load_scene("", {"populations.0.colour=3"}); })
                .find("the default scene with --set overrides: populations.0.colour: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of([] { load_scene("", {"populations.5.count=3"}); })
                .find("--set 'populations.5.count=3': 'populations.5' is past the end of the list 'populations' (1 elements)"),
            std::string::npos);
  EXPECT_NE(error_of([] { load_scene("", {"populations.first.count=3"}); }).find("names no element of the list"),
            std::string::npos);
  EXPECT_NE(error_of([] { load_scene("", {"populations.0.radius=\"big\""}); }).find("populations.0.radius: expected a number"),
            std::string::npos);
  Json empty = Json::object();
  EXPECT_THROW(apply_override(empty, "steps"), Error);  // no value
}

TEST(SceneFile, TheDefaultSceneBuildsExactlyThePourScene) {
  // The scene file's pour and the canonical PourScene: every column, bit for bit, and the
  // settings; so the scene file reproduces the canonical pour's state hash.
  for (std::size_t n : {20u, 2000u}) {
    PourScene pour;
    pour.spheres = n;
    World a, b;
    pour.build(a);
    build_scene(load_scene("", {"populations.0.count=" + std::to_string(n)}), b);
    ASSERT_EQ(a.spheres.size(), b.spheres.size());
    auto same = [](auto x, auto y) { return std::equal(x.begin(), x.end(), y.begin(), y.end()); };
    EXPECT_TRUE(same(a.spheres.position(), b.spheres.position()));
    EXPECT_TRUE(same(a.spheres.radius(), b.spheres.radius()));
    EXPECT_TRUE(same(a.spheres.inv_mass(), b.spheres.inv_mass()));
    EXPECT_TRUE(same(a.spheres.material(), b.spheres.material()));
    EXPECT_TRUE(same(a.spheres.color(), b.spheres.color()));
    EXPECT_EQ(a.pit.half_width, b.pit.half_width);
    EXPECT_EQ(a.pit.wall_height, b.pit.wall_height);
    EXPECT_EQ(a.pit.closed, b.pit.closed);
    EXPECT_EQ(a.pit.material.friction, b.pit.material.friction);
    ASSERT_EQ(a.materials.size(), b.materials.size());
    EXPECT_EQ(a.materials[0].restitution, b.materials[0].restitution);
    EXPECT_EQ(a.spheres.has_angular(), b.spheres.has_angular());
    EXPECT_EQ(a.solver.sleeping, b.solver.sleeping);
    EXPECT_EQ(a.solver.substeps, b.solver.substeps);
    EXPECT_EQ(a.step(), b.step());
    EXPECT_EQ(a.gravity(), b.gravity());
    EXPECT_EQ(state_hash(a), state_hash(b));
  }
}

TEST(SceneFile, ThePitCharacterSceneFileBuildsTheCanonicalScene) {
  PitCharacterScene canonical;
  canonical.pour.spheres = 500;
  World a, b;
  canonical.build(a);
  const SceneSetup setup = setup_scene(load_scene("pit-character", {"populations.0.count=500"}), b);
  ASSERT_TRUE(setup.character.valid());
  EXPECT_EQ(setup.settle_steps, canonical.settle_steps);
  EXPECT_EQ(setup.path.size(), canonical.path.size());
  EXPECT_EQ(a.pit.half_width, b.pit.half_width);
  ASSERT_EQ(a.colliders.size(), b.colliders.size());
  auto same = [](auto x, auto y) { return std::equal(x.begin(), x.end(), y.begin(), y.end()); };
  EXPECT_TRUE(same(a.colliders.a(), b.colliders.a()));
  EXPECT_TRUE(same(a.colliders.radius(), b.colliders.radius()));
  ASSERT_EQ(a.spheres.size(), 500u);
  EXPECT_TRUE(same(a.spheres.position(), b.spheres.position()));
  EXPECT_TRUE(same(a.spheres.color(), b.spheres.color()));
  EXPECT_EQ(state_hash(a), state_hash(b));
}

TEST(SceneFile, OnlyWhatASceneUsesIsBuiltAndScheduled) {
  auto systems = [](const World& w) {
    auto s = std::make_unique<Scheduler>(1);
    add_character_systems(*s, w);
    add_physics_systems(*s, w);
    return s;
  };
  // The pour: no character, no collider rows, no character system; friction, so spin state.
  World pour;
  setup_scene(load_scene("", {"populations.0.count=300"}), pour);
  EXPECT_EQ(pour.characters.size(), 0u);
  EXPECT_EQ(pour.colliders.size(), 0u);
  EXPECT_TRUE(pour.spheres.has_angular());
  auto s = systems(pour);
  for (std::string_view name : character_system_names()) EXPECT_FALSE(scheduled(*s, name)) << name;
  EXPECT_FALSE(scheduled(*s, "sleeping")) << "the pour measures without sleeping";

  // Frictionless: no angular column at all (12 bytes a sphere saved).
  World smooth;
  setup_scene(load_scene("", {"populations.0.count=300", "populations.0.material.friction=0"}), smooth);
  EXPECT_FALSE(smooth.spheres.has_angular());
  EXPECT_EQ(smooth.spheres.angular_velocity().size(), 0u);
  EXPECT_LT(smooth.spheres.bytes_per_sphere(), pour.spheres.bytes_per_sphere());
  // Stated features win over derived ones.
  World stated;
  setup_scene(load_scene("", {"populations.0.count=300", "populations.0.material.friction=0", "features.angular=true",
                              "features.sleeping=true"}),
              stated);
  EXPECT_TRUE(stated.spheres.has_angular());
  EXPECT_TRUE(scheduled(*systems(stated), "sleeping"));

  // A character section: the character, its collider rows and its systems; turned off, none.
  World walker;
  setup_scene(load_scene("pit-character", {"populations.0.count=200"}), walker);
  EXPECT_EQ(walker.characters.size(), 1u);
  EXPECT_GT(walker.colliders.size(), 0u);
  auto w = systems(walker);
  for (std::string_view name : character_system_names()) EXPECT_TRUE(scheduled(*w, name)) << name;
  World off;
  setup_scene(load_scene("pit-character", {"populations.0.count=200", "features.character=false"}), off);
  EXPECT_EQ(off.characters.size(), 0u);
  EXPECT_EQ(off.colliders.size(), 0u);
}

TEST(SceneFile, MixedPopulationsFollowTheirDescriptions) {
  const SceneFile scene = load_scene(BALLPIT_SCENES_DIR "/mixed.json");
  World w;
  setup_scene(scene, w);
  ASSERT_EQ(w.spheres.size(), scene.total_spheres());
  EXPECT_EQ(w.materials.size(), 3u);  // one per distinct population material
  // Spheres are added population by population (entity order); check each one's description.
  std::size_t first = 0;
  for (std::size_t k = 0; k < scene.populations.size(); ++k) {
    const Population& p = scene.populations[k];
    double sum = 0.0;
    for (std::size_t i = first; i < first + p.count; ++i) {
      const std::uint32_t row = w.spheres.row(w.spheres.entity_at(static_cast<std::uint32_t>(i)));
      const float r = w.spheres.radius()[row];
      EXPECT_GE(r, p.radius.smallest());
      EXPECT_LE(r, p.radius.largest());
      // 1/m of the density's mass, to float rounding of the volume and of the inverse.
      EXPECT_NEAR(1.0f / w.spheres.inv_mass()[row], p.mass_of(r), 1e-6f * p.mass_of(r) + 1e-12f);
      if (p.color.kind == ColorScheme::Kind::Solid) {
        EXPECT_EQ(w.spheres.color()[row], p.color.color);
      }
      if (p.placement.kind == Placement::Kind::Box) {
        const Vec3& x = w.spheres.position()[row];
        EXPECT_TRUE((x.array() - r >= p.placement.min.array()).all() && (x.array() + r <= p.placement.max.array()).all());
      }
      sum += r;
    }
    if (p.radius.kind == RadiusSpec::Kind::Normal) {
      // 4000 draws of sd 8 mm, clamped symmetrically: the mean is within 4 standard errors (0.5 mm).
      EXPECT_NEAR(sum / static_cast<double>(p.count), p.radius.mean, 4.0 * p.radius.sd / std::sqrt(p.count));
    }
    first += p.count;
  }
  // No two spheres start overlapping, whatever their radii (all pairs: 5,800 spheres).
  EXPECT_EQ(overlapping_pairs(w), 0u);
}

// A box may reach into what was placed before it: its lattice points skip those spheres, and a
// box left too little room says how much the earlier populations took.
TEST(SceneFile, ABoxPopulationSkipsTheSpheresPlacedBeforeIt) {
  const Json j = Json::parse(R"({
    "pit": {"half_width": 0.6, "wall_height": 3.0},
    "populations": [
      {"count": 600},
      {"count": 300, "radius": 0.03, "placement": {"kind": "box", "min": [-0.6, 0.0, -0.6], "max": [0.6, 0.9, 0.6]}}
    ]})");
  World w;
  build_scene(parse_scene(j, "box.json"), w);
  ASSERT_EQ(w.spheres.size(), 900u);
  EXPECT_EQ(overlapping_pairs(w), 0u);

  Json full = j;
  full["populations"][1]["count"] = 4000;  // of the 4,212 points of its lattice
  World w2;
  const std::string m = error_of([&] { build_scene(parse_scene(full, "box.json"), w2); });
  EXPECT_NE(m.find("box.json: populations.1.placement: the box holds only"), std::string::npos) << m;
  EXPECT_NE(m.find("points taken by earlier populations"), std::string::npos) << m;
}

TEST(SceneFile, BuildingASceneAppliesItsSolverAndGravity) {
  SceneFile s = load_scene("", {"populations.0.count=300", "solver.substeps=5", "solver.solve_sweeps=3", "features.sleeping=true", "gravity=[0,-5,0]",
                                "dt=0.01"});
  World w;
  build_scene(s, w);
  EXPECT_EQ(w.spheres.size(), 300u);
  EXPECT_EQ(w.solver.substeps, 5);
  EXPECT_EQ(w.solver.solve_sweeps, 3);
  EXPECT_TRUE(w.solver.sleeping);
  EXPECT_EQ(w.gravity().y(), -5.0f);
  EXPECT_EQ(w.step(), 0.01f);
  // A character scene needs the character systems' builder.
  EXPECT_NE(error_of([] { World c; build_scene(builtin_scene("pit-character"), c); }).find("setup_scene"),
            std::string::npos);
}

TEST(SceneFile, AMissingOrBrokenFileIsRefusedByName) {
  EXPECT_NE(error_of([] { load_scene("/nonexistent/scene.json"); }).find("/nonexistent/scene.json: cannot open"),
            std::string::npos);
}

TEST(SceneFile, ARelativeModelPathIsFoundBesideTheSceneFile) {
  // A scene folder with its own model, read from another working directory.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "ballpit_scene_model_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "models");
  std::filesystem::copy_file(kWusonModelPath, dir / "models" / "walker.X");
  std::ofstream(dir / "walker.json") << R"({"character": {"model": "models/walker.X"}})";
  const SceneFile s = load_scene((dir / "walker.json").string());
  ASSERT_TRUE(s.character);
  EXPECT_EQ(s.character->model, (dir / "models" / "walker.X").string());
  // From the command line a relative path stays the working directory's: here, none.
  const std::string m = error_of([&] { load_scene((dir / "walker.json").string(), {"character.model=models/walker.X"}); });
  EXPECT_NE(m.find("character.model: expected an existing model file or \"builtin:marine\", 'models/walker.X' does not exist"), std::string::npos)
      << m;
  std::filesystem::remove_all(dir);
}
