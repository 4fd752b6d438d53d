// Populations that start moving: a population's velocity, velocity jitter and spin reach every
// sphere it adds, default to rest, are checked like every other field (file, field path, what
// was expected), and make scenes/volley.json, 500 balls fired at 100 m/s into a resting pile.
// What the solver makes of such a volley is tested with the solver; here only that the scene
// says what it means.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "engine/error.h"
#include "engine/scene_file.h"
#include "engine/state_hash.h"
#include "engine/world.h"
#include "systems/scene_setup.h"
#include "tiny_world.h"

using namespace ballpit;
using Json = nlohmann::ordered_json;

namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

// The message parse_scene throws for a scene whose only population is `population`.
std::string refusal(const std::string& population) {
  return error_of([&] { parse_scene(Json::parse(R"({"populations": [)" + population + "]}"), "test.json"); });
}

void expect_contains(const std::string& message, const std::string& part) {
  EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
}

// The row of the i-th sphere added, in a world not yet stepped: spheres are added population by
// population, and rows stay in that order until the first step sorts them by cell.
std::uint32_t row_of(const World& w, std::size_t i) {
  const std::uint32_t row = static_cast<std::uint32_t>(i);
  EXPECT_EQ(w.spheres.row(w.spheres.entity_at(row)), row);
  return row;
}

// A pile of 60 balls at rest and 40 fired from a box above it, spinning.
const char* const kTwoPopulations = R"({
  "pit": {"half_width": 0.5, "wall_height": 3.0},
  "populations": [
    {"count": 60},
    {"count": 40, "placement": {"kind": "box", "min": [-0.3, 1.5, -0.3], "max": [0.3, 2.0, 0.3]},
     "velocity": [1.5, -20.0, 0.25], "spin": [0.0, 6.0, -3.0]}
  ]})";

}  // namespace

TEST(Populations, VelocityAndSpinReachEverySphereOfThePopulationAndNoOther) {
  World w;
  build_scene(parse_scene(Json::parse(kTwoPopulations), "test.json"), w);
  ASSERT_EQ(w.spheres.size(), 100u);
  ASSERT_TRUE(w.spheres.has_angular());
  for (std::size_t i = 0; i < 100; ++i) {
    const std::uint32_t row = row_of(w, i);
    const bool fired = i >= 60;
    // Copied from the file, not computed: exact.
    EXPECT_EQ(w.spheres.velocity()[row], fired ? Vec3(1.5f, -20.0f, 0.25f) : Vec3::Zero()) << "sphere " << i;
    EXPECT_EQ(w.spheres.angular_velocity()[row], fired ? Vec3(0.0f, 6.0f, -3.0f) : Vec3::Zero()) << "sphere " << i;
  }
}

TEST(Populations, AbsentFieldsAreAtRest) {
  const SceneFile s = parse_scene(Json::object(), "test.json");
  EXPECT_EQ(s.populations[0].velocity, Vec3::Zero());
  EXPECT_EQ(s.populations[0].velocity_jitter, 0.0f);
  EXPECT_EQ(s.populations[0].spin, Vec3::Zero());
  // The complete JSON writes them out (so --set reaches them) and reads them back.
  const Json j = scene_to_json(s);
  EXPECT_EQ(j["populations"][0]["velocity"], Json::parse("[0.0, 0.0, 0.0]"));
  EXPECT_EQ(j["populations"][0]["spin"], Json::parse("[0.0, 0.0, 0.0]"));
  EXPECT_EQ(j["populations"][0]["velocity_jitter"], 0.0);
  World w;
  build_scene(load_scene("", {"populations.0.count=200"}), w);
  for (const Vec3& v : w.spheres.velocity()) EXPECT_EQ(v, Vec3::Zero());
  for (const Vec3& v : w.spheres.angular_velocity()) EXPECT_EQ(v, Vec3::Zero());
}

TEST(Populations, TheNewFieldsRoundTripAndAreReachedBySet) {
  const SceneFile moved = parse_scene(Json::parse(kTwoPopulations), "test.json");
  const Json j = scene_to_json(moved);
  EXPECT_EQ(scene_to_json(parse_scene(j, "test.json")), j);
  EXPECT_EQ(j["populations"][1]["velocity"], Json::parse("[1.5, -20.0, 0.25]"));

  const SceneFile s = load_scene("", {"populations.0.count=100", "populations.0.velocity=[0,-5,0]",
                                      "populations.0.spin=[1, 0, 0]", "populations.0.velocity_jitter=0.5"});
  EXPECT_EQ(s.populations[0].velocity, Vec3(0.0f, -5.0f, 0.0f));
  EXPECT_EQ(s.populations[0].spin, Vec3(1.0f, 0.0f, 0.0f));
  EXPECT_EQ(s.populations[0].velocity_jitter, 0.5f);
}

TEST(Populations, VelocityJitterIsUniformPerAxisDeterministicAndLeavesPlacesAlone) {
  const std::vector<std::string> base = {"populations.0.count=500", "populations.0.velocity=[0,0,-10]"};
  std::vector<std::string> jittered = base;
  jittered.push_back("populations.0.velocity_jitter=2");
  World still, a, b;
  build_scene(load_scene("", base), still);
  build_scene(load_scene("", jittered), a);
  build_scene(load_scene("", jittered), b);
  auto same = [](auto x, auto y) { return std::equal(x.begin(), x.end(), y.begin(), y.end()); };
  // Its own random stream: the places are those of the scene without jitter, bit for bit.
  EXPECT_TRUE(same(still.spheres.position(), a.spheres.position()));
  // From the scene's seed: two builds are the same state.
  EXPECT_TRUE(same(a.spheres.velocity(), b.spheres.velocity()));
  EXPECT_EQ(state_hash(a), state_hash(b));
  Vec3 lo = Vec3::Constant(1e9f), hi = Vec3::Constant(-1e9f);
  for (const Vec3& v : a.spheres.velocity()) {
    const Vec3 d = v - Vec3(0.0f, 0.0f, -10.0f);
    EXPECT_LE(d.cwiseAbs().maxCoeff(), 2.0f + 1e-5f);  // within +-2 m/s, to float rounding near 10 m/s
    lo = lo.cwiseMin(d);
    hi = hi.cwiseMax(d);
  }
  // 500 uniform draws on [-2, 2] per axis: the extremes come within 0.1 m/s of the bounds but
  // for a chance of 2 x (0.975^500) ~ 6e-6 (and the draws are fixed by the seed).
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_LT(lo[axis], -1.9f) << "axis " << axis;
    EXPECT_GT(hi[axis], 1.9f) << "axis " << axis;
  }
}

TEST(Populations, SpinNeedsTheAngularState) {
  // A frictionless scene has no angular columns, unless a population starts spinning.
  World smooth, spinning;
  build_scene(load_scene("", {"populations.0.count=100", "populations.0.material.friction=0"}), smooth);
  EXPECT_FALSE(smooth.spheres.has_angular());
  build_scene(load_scene("", {"populations.0.count=100", "populations.0.material.friction=0", "populations.0.spin=[0,0,4]"}),
              spinning);
  ASSERT_TRUE(spinning.spheres.has_angular());
  EXPECT_EQ(spinning.spheres.angular_velocity()[0], Vec3(0.0f, 0.0f, 4.0f));
  // Turned off by name, it is an error naming the field, not a spin dropped without a word.
  const std::string m = error_of([] {
    parse_scene(Json::parse(R"({"populations": [{"spin": [0, 0, 4]}], "features": {"angular": false}})"), "test.json");
  });
  expect_contains(m, "test.json: populations.0.spin: expected [0, 0, 0] with features.angular false");
  expect_contains(m, "got [0, 0, 4]");
}

TEST(Populations, BadValuesAreRefusedNamingTheFileAndTheField) {
  expect_contains(refusal(R"({"velocity": "fast"})"),
                  "test.json: populations.0.velocity: expected [x, y, z] (m/s), got string \"fast\"");
  expect_contains(refusal(R"({"velocity": [1, 2]})"), "test.json: populations.0.velocity: expected [x, y, z] (m/s), got array [1,2]");
  expect_contains(refusal(R"({"velocity": [0, "x", 0]})"), "test.json: populations.0.velocity[1]: expected a finite number, got string");
  // Finite as a double, infinite as the float the engine keeps.
  expect_contains(refusal(R"({"velocity": [1e300, 0, 0]})"), "test.json: populations.0.velocity[0]: expected a finite number");
  expect_contains(refusal(R"({"spin": [1, 2, 3, 4]})"), "test.json: populations.0.spin: expected [x, y, z] (rad/s)");
  expect_contains(refusal(R"({"spin": null})"), "test.json: populations.0.spin: expected [x, y, z] (rad/s)");
  expect_contains(refusal(R"({"velocity_jitter": -1})"),
                  "test.json: populations.0.velocity_jitter: expected a number >= 0 (m/s per axis), got -1");
  expect_contains(refusal(R"({"velocity_jitter": [1, 1, 1]})"), "test.json: populations.0.velocity_jitter: expected a number");
  // JSON has no NaN or infinity; 1e999 overflows the parser, in a file and in --set alike.
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "ballpit_infinite_velocity.json";
  std::ofstream(file) << R"({"populations": [{"velocity": [1e999, 0, 0]}]})";
  expect_contains(error_of([&] { load_scene(file.string()); }), file.string() + ": not valid JSON");
  std::filesystem::remove(file);
  expect_contains(error_of([] { load_scene("", {"populations.0.velocity=[1e999,0,0]"}); }),
                  "the default scene with --set overrides: populations.0.velocity: expected [x, y, z] (m/s)");
}

// scenes/volley.json: a pile of 3,000 balls stacked almost touching (at rest within a step) and
// 500 balls in a box 4 m above it fired straight down at 100 m/s.
TEST(Populations, TheVolleySceneFiresItsBallsAtTheirSpeed) {
  const SceneFile scene = load_scene(BALLPIT_SCENES_DIR "/volley.json");
  ASSERT_EQ(scene.populations.size(), 2u);
  EXPECT_EQ(scene.populations[0].velocity, Vec3::Zero());
  EXPECT_EQ(scene.populations[1].count, 500u);
  EXPECT_EQ(scene.populations[1].velocity.norm(), 100.0f);
  EXPECT_EQ(scene_to_json(parse_scene(scene_to_json(scene), "volley")), scene_to_json(scene));

  test::Sim sim;
  setup_scene(scene, sim.world);
  ASSERT_EQ(sim.world.spheres.size(), 3500u);
  const Vec3 fired = scene.populations[1].velocity;
  for (std::size_t i = 0; i < 3500; ++i)
    EXPECT_EQ(sim.world.spheres.velocity()[row_of(sim.world, i)], i < 3000 ? Vec3::Zero() : fired) << "sphere " << i;
  // The volley's lowest ball starts over 4 m above the pile's top, more than two steps' travel
  // (1.7 m a step at 100 m/s, so no speculative margin reaches the pile either): its first step
  // is free flight, and it ends at 100 m/s plus one step of gravity.
  float pile_top = 0.0f, volley_bottom = 1e9f;
  for (std::size_t i = 0; i < 3500; ++i) {
    const std::uint32_t row = row_of(sim.world, i);
    const float y = sim.world.spheres.position()[row].y(), r = sim.world.spheres.radius()[row];
    if (i < 3000) pile_top = std::max(pile_top, y + r);
    else volley_bottom = std::min(volley_bottom, y - r);
  }
  ASSERT_GT(volley_bottom - pile_top, 2.0f * fired.norm() * scene.dt);
  std::vector<std::uint32_t> volley;  // entity indices: the step sorts the rows by cell
  for (std::size_t i = 3000; i < 3500; ++i) volley.push_back(sim.world.spheres.entity_index()[row_of(sim.world, i)]);
  sim.start();
  sim.step();
  const Vec3 expected = fired + scene.gravity * scene.dt;
  for (std::uint32_t e : volley) {
    const std::uint32_t row = sim.world.spheres.row_of_index(e);
    ASSERT_NE(row, SphereTable::kNoRow);
    // Float rounding of 100 m/s plus 4 substeps of gravity: an ulp at 100 is 7.6e-6 m/s.
    EXPECT_NEAR((sim.world.spheres.velocity()[row] - expected).norm(), 0.0f, 1e-3f) << "entity " << e;
  }
}
