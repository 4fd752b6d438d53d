// Bad input is refused at the API boundary with a message naming what is wrong.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "engine/error.h"
#include "tiny_world.h"

using namespace ballpit;

namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

void expect_mentions(const std::string& message, std::initializer_list<const char*> words) {
  for (const char* w : words) EXPECT_NE(message.find(w), std::string::npos) << "'" << w << "' not in: " << message;
}

}  // namespace

TEST(Validation, NonFinitePositionsAndVelocitiesAreRefusedNamingTheEntity) {
  World w;
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  test::add_ball(w, Vec3(0, 1, 0));  // entity 0 is fine
  expect_mentions(error_of([&] { test::add_ball(w, Vec3(nan, 0, 0)); }), {"entity 1", "position", "finite"});
  expect_mentions(error_of([&] { test::add_ball(w, Vec3(0, inf, 0)); }), {"position", "finite"});
  expect_mentions(error_of([&] { test::add_ball(w, Vec3(0, 1, 0), Vec3(0, 0, -inf)); }), {"velocity", "finite"});
  EXPECT_EQ(w.spheres.size(), 1u);  // refused spheres leave nothing behind
  EXPECT_EQ(w.entities.live_count(), 1u);
}

TEST(Validation, ANonFiniteSpinOrOneWithoutAngularColumnsIsRefused) {
  World w;
  SphereDesc d;
  d.angular_velocity = Vec3(0, 5, 0);
  // Without angular columns the spin would be dropped without a word.
  expect_mentions(error_of([&] { w.add_sphere(d); }), {"entity 0", "angular velocity", "angular columns"});
  w.enable_angular(true);
  d.angular_velocity = Vec3(0, std::numeric_limits<float>::infinity(), 0);
  expect_mentions(error_of([&] { w.add_sphere(d); }), {"angular velocity", "finite"});
  d.angular_velocity = Vec3(0, 5, 0);
  const Entity e = w.add_sphere(d);
  EXPECT_EQ(w.spheres.angular_velocity()[w.spheres.row(e)], Vec3(0, 5, 0));
}

TEST(Validation, NonPositiveRadiusAndMassAreRefused) {
  World w;
  expect_mentions(error_of([&] { test::add_ball(w, Vec3::Zero(), Vec3::Zero(), 0.0f); }), {"radius", "> 0"});
  expect_mentions(error_of([&] { test::add_ball(w, Vec3::Zero(), Vec3::Zero(), -0.1f); }), {"radius", "-0.1"});
  expect_mentions(error_of([&] { test::add_ball(w, Vec3::Zero(), Vec3::Zero(), 0.04f, 0.0f); }), {"mass", "> 0"});
  expect_mentions(error_of([&] { test::add_ball(w, Vec3::Zero(), Vec3::Zero(), 0.04f, std::nanf("")); }), {"mass"});
  expect_mentions(error_of([&] { test::add_ball(w, Vec3::Zero(), Vec3::Zero(), 0.04f, 1e-44f); }), {"mass", "inverse"});
}

TEST(Validation, ZeroNegativeOrNonFiniteStepIsRefusedNamingDt) {
  World w;
  for (float dt : {0.0f, -0.01f, std::numeric_limits<float>::infinity(), std::nanf("")})
    expect_mentions(error_of([&] { w.set_step(dt); }), {"dt", "> 0"});
  EXPECT_NO_THROW(w.set_step(0.01f));
}

TEST(Validation, UnknownMaterialAndBadSettingsAreRefused) {
  World w;
  SphereDesc d;
  d.material = 3;
  expect_mentions(error_of([&] { w.add_sphere(d); }), {"material 3", "does not exist"});
  w.solver.substeps = 0;
  expect_mentions(error_of([&] { w.validate_settings(); }), {"solver.substeps"});
  w.solver.substeps = 8;
  w.solver.solve_sweeps = 0;
  expect_mentions(error_of([&] { w.validate_settings(); }), {"solver.solve_sweeps", "[1, 16]", "got 0"});
  expect_mentions(error_of([&] { w.set_solve_sweeps(17); }), {"solver.solve_sweeps", "got 17"});
  EXPECT_EQ(w.solver.solve_sweeps, 0) << "a refused count changes nothing";
  w.solver.solve_sweeps = 1;
  w.pit.half_width = -1;
  expect_mentions(error_of([&] { w.validate_settings(); }), {"pit.half_width"});
  expect_mentions(error_of([&] { w.set_gravity(Vec3(0, std::nanf(""), 0)); }), {"gravity", "finite"});
}

// A long substep or step is allowed (the speed-error study runs them) but warned of, with the
// substeps that would do.
TEST(Validation, ALongSubstepOrStepIsWarnedOfWithTheSubstepsNeeded) {
  World w;
  EXPECT_EQ(w.step_warnings().substep, "");  // 1/60 s at 4 substeps: exactly 1/240 s
  EXPECT_EQ(w.step_warnings().step, "");
  EXPECT_EQ(accurate_substeps(1.0f / 60.0f), 4);
  w.set_substeps(3);
  expect_mentions(w.step_warnings().substep, {"5.56 ms", "3 substeps", "1/240 s", "4 substeps keep it within"});
  // A Solve sweep beyond the first stands in for one substep, up to two of them: 3 substeps of 2
  // sweeps and 2 of 3 keep a pile within 1% of r at 1/60 s, 2 of 2 and 1 of 8 do not.
  EXPECT_EQ(accurate_substeps(1.0f / 60.0f, 2), 3);
  EXPECT_EQ(accurate_substeps(1.0f / 60.0f, 3), 2);
  EXPECT_EQ(accurate_substeps(1.0f / 60.0f, 8), 2);
  w.set_solve_sweeps(2);
  EXPECT_EQ(w.step_warnings().substep, "");
  w.set_substeps(2);
  expect_mentions(w.step_warnings().substep, {"8.33 ms", "2 substeps of 2 Solve sweeps", "3 substeps keep it within"});
  w.set_solve_sweeps(8);
  EXPECT_EQ(w.step_warnings().substep, "");
  w.set_substeps(1);
  expect_mentions(w.step_warnings().substep, {"1 substep of 8 Solve sweeps", "at most 2", "2 substeps keep it within"});
  w.set_solve_sweeps(1);
  w.set_substeps(8);
  w.set_step(1.0f / 30.0f);  // the longest step without a cost warning, at substeps of 1/240 s
  EXPECT_EQ(w.step_warnings().substep, "");
  EXPECT_EQ(w.step_warnings().step, "");
  w.set_substeps(4);
  w.set_step(0.1f);
  expect_mentions(w.step_warnings().substep, {"25 ms", "dt 0.1 s", "24 substeps keep it within", "--tolerance"});
  expect_mentions(w.step_warnings().step, {"dt 0.1 s", "longer than 1/30 s", "wider box"});
  w.set_substeps(24);
  EXPECT_EQ(w.step_warnings().substep, "");
  EXPECT_NE(w.step_warnings().step, "");  // more substeps do not make a long step cheap
  w.set_step(1.0f);
  expect_mentions(w.step_warnings().substep, {"No substep count up to 64", "0.2667 s"});
  w.set_step(3e38f);  // still finite: the count saturates instead of overflowing
  EXPECT_GT(accurate_substeps(3e38f), 64);
  EXPECT_NE(w.step_warnings().substep, "");
}
