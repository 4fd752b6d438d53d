// Scene files: every field round-trips, and each kind of mistake is refused with the file, the
// field path and what was expected.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "engine/error.h"
#include "engine/scene_file.h"
#include "engine/world.h"

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

}  // namespace

TEST(SceneFile, EveryFieldRoundTrips) {
  SceneFile s;  // every field away from its default
  s.pour.spheres = 1234;
  s.pour.radius = 0.03f;
  s.pour.mass = 0.07f;
  s.pour.restitution = 0.3f;
  s.pour.friction = 0.0f;
  s.pour.wall_height = 5.0f;
  s.pour.seed = 7;
  s.pour.dt = 1.0f / 120.0f;
  s.pour.steps = 90;
  s.solver.substeps = 3;
  s.solver.push_out_rate = 0.4f;
  s.solver.push_out_speed = 2.0f;
  s.solver.restitution_threshold = 0.0f;
  s.solver.linear_damping = 0.1f;
  s.solver.angular_damping = 0.2f;
  s.solver.narrowphase = NarrowphaseMode::Naive;
  s.solver.sleeping = true;
  s.solver.sleep_speed = 0.03f;
  s.solver.sleep_time = 0.7f;
  s.solver.wake_speed = 0.09f;
  s.gravity = Vec3(1.0f, -3.0f, 0.5f);
  const Json j = scene_to_json(s);
  EXPECT_EQ(scene_to_json(parse_scene(j, "test.json")), j);
  EXPECT_NE(j, scene_to_json(SceneFile{})) << "the test must move every field off its default";
  // A file with no keys at all is the default scene.
  EXPECT_EQ(scene_to_json(parse_scene(Json::object(), "test.json")), scene_to_json(SceneFile{}));
}

TEST(SceneFile, TheShippedPourSceneIsTheDefaultScene) {
  EXPECT_EQ(scene_to_json(load_scene(BALLPIT_SCENES_DIR "/pour.json")), scene_to_json(SceneFile{}));
}

TEST(SceneFile, AnUnknownKeyIsAnErrorNamingItsPath) {
  const std::string m = refusal(Json::parse(R"({"pour": {"spheerss": 3}})"));
  EXPECT_NE(m.find("test.json: pour.spheerss: unknown key"), std::string::npos) << m;
  EXPECT_NE(m.find("spheres"), std::string::npos) << "the message lists the known keys: " << m;
  EXPECT_NE(refusal(Json::parse(R"({"colour": 3})")).find("test.json: colour: unknown key"), std::string::npos);
}

TEST(SceneFile, AWrongTypeIsAnErrorNamingWhatWasExpected) {
  EXPECT_NE(refusal(Json::parse(R"({"pour": {"radius": "big"}})"))
                .find("test.json: pour.radius: expected a number (m), got string \"big\""),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"pour": {"spheres": 2.5}})")).find("pour.spheres: expected an integer"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"solver": {"sleeping": 1}})")).find("solver.sleeping: expected true or false"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"gravity": [0, -9.81]})")).find("gravity: expected [x, y, z]"), std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"solver": 8})")).find("solver: expected an object"), std::string::npos);
}

TEST(SceneFile, OutOfRangeValuesAreRefused) {
  EXPECT_NE(refusal(Json::parse(R"({"pour": {"radius": -0.1}})")).find("pour.radius: expected a number > 0 (m), got -0.1"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"pour": {"restitution": 1.5}})")).find("pour.restitution: expected a number >= 0 and <= 1"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"pour": {"mass": 1e-44}})")).find("pour.mass: expected a mass whose inverse is finite"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"solver": {"substeps": 0}})")).find("solver.substeps: expected an integer in [1, 64]"),
            std::string::npos);
  EXPECT_NE(refusal(Json::parse(R"({"solver": {"narrowphase": "fast"}})")).find("solver.narrowphase: expected \"grid\" or \"naive\""),
            std::string::npos);
}

TEST(SceneFile, APitSmallerThanOneSphereIsRefused) {
  // One sphere gets a pit sqrt(5.6e-4) = 2.4 cm wide: a 10 cm ball cannot fit.
  const std::string m = refusal(Json::parse(R"({"pour": {"spheres": 1, "radius": 0.1}})"));
  EXPECT_NE(m.find("test.json: pour.radius: a sphere of radius 0.1"), std::string::npos) << m;
  EXPECT_NE(m.find("does not fit in the pit"), std::string::npos) << m;
}

TEST(SceneFile, OverridesAreCheckedLikeTheFile) {
  Json j = Json::object();
  apply_override(j, "pour.spheres=500");
  apply_override(j, "solver.narrowphase=naive");  // a bare word is a string
  apply_override(j, "gravity=[0, -1.62, 0]");
  SceneFile s = parse_scene(j, "test.json");
  EXPECT_EQ(s.pour.spheres, 500u);
  EXPECT_EQ(s.solver.narrowphase, NarrowphaseMode::Naive);
  EXPECT_EQ(s.gravity.y(), -1.62f);

  try {
    apply_override(j, "pour.spheerss=5");
    ADD_FAILURE() << "a mistyped key must be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--set 'pour.spheerss=5': 'pour.spheerss' is not a field"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(apply_override(j, "pour.spheres"), Error);  // no value
  apply_override(j, "pour.radius=\"big\"");
  EXPECT_NE(refusal(j).find("pour.radius: expected a number"), std::string::npos);
}

TEST(SceneFile, BuildingASceneAppliesItsSolverAndGravity) {
  SceneFile s = load_scene("", {"pour.spheres=300", "solver.substeps=5", "solver.sleeping=true", "gravity=[0,-5,0]"});
  World w;
  build_scene(s, w);
  EXPECT_EQ(w.spheres.size(), 300u);
  EXPECT_EQ(w.solver.substeps, 5);
  EXPECT_TRUE(w.solver.sleeping);
  EXPECT_EQ(w.gravity().y(), -5.0f);
}

TEST(SceneFile, AMissingOrBrokenFileIsRefusedByName) {
  try {
    load_scene("/nonexistent/scene.json");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scene.json: cannot open"), std::string::npos) << e.what();
  }
}
