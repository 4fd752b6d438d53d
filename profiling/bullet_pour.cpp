// The canonical pour (shared/SCENES.md) in Bullet and in ballpit, in one run, side by side:
// ms/step, max and mean penetration, kinetic energy and escapes after the same number of steps,
// measured for both by the same code (engine/metrics.h) on the same sphere order.
//
// Bullet runs at its defaults (btDiscreteDynamicsWorld, btDbvtBroadphase, sequential impulse
// solver with 10 iterations and split impulse, one step of 1/60 s per stepSimulation, no CCD),
// single-threaded as Debian builds it. Differences from the scene that Bullet forces:
// - Bullet multiplies the two bodies' restitution and friction; each body and plane gets
//   sqrt(0.5), so every pair has the scene's 0.5 and 0.5.
// - The walls are infinite planes rather than 20 m tall: no pour sphere comes near 20 m.
// - Deactivation (sleeping) is disabled, as the scene measures without sleeping.
// ballpit runs through the same library call as `ballpit run` (app/headless_run.h), at 1 and at
// 2 threads.
//
// Bullet needs about 0.8 s a step at 10k spheres and 2.6 s at 100k on a small machine, so runs
// are shortened (--steps); the table says how many steps both engines ran. The pit has
// collapsed after about 1 s (60 steps) at any N, because the pit is as deep for every N. So
// that "kinetic energy after settling" means what it says, both engines' kinetic energy is
// followed every step (outside the timing) and each line gives settle_s, the time from which
// the rms speed stays under 1 cm/s to the end of the run (omitted when it never does).
#include <btBulletDynamicsCommon.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "app/headless_run.h"
#include "engine/error.h"
#include "engine/metrics.h"
#include "engine/pour_scene.h"
#include "engine/world.h"

namespace {

using namespace ballpit;

// rms speed below which the pit counts as settled, as profiling/cases.cpp's pour (unit: m/s).
constexpr double kSettleSpeed = 0.01;

// The step after which the kinetic energy stayed under the settled level to the end.
class SettleWatch {
 public:
  SettleWatch(std::size_t spheres, double mass)
      : limit_(static_cast<double>(spheres) * 0.5 * mass * kSettleSpeed * kSettleSpeed) {}
  void after_step(double kinetic_energy) {
    if (kinetic_energy > limit_) last_moving_ = steps_;
    ++steps_;
  }
  // Writes settle_s when the run ended settled.
  void report(nlohmann::ordered_json& j, double dt) const {
    if (last_moving_ + 1 < steps_) j["settle_s"] = (last_moving_ + 1) * dt;
  }

 private:
  double limit_;
  int steps_ = 0;
  int last_moving_ = -1;
};

std::string settled_text(const nlohmann::ordered_json& r) {
  if (!r.contains("settle_s")) return "no";
  char text[32];
  std::snprintf(text, sizeof text, "%.2f s", r["settle_s"].get<double>());
  return text;
}

struct Halves {
  double pour_mean = 0, pour_median = 0, settled_mean = 0, settled_median = 0;
};

// As the headless runner splits: steps 0-299 / 300-599 for 600 steps, halves otherwise.
Halves split_times(const std::vector<double>& ms) {
  auto summary = [](std::vector<double> v, double& mean, double& median) {
    if (v.empty()) return;
    double sum = 0;
    for (double x : v) sum += x;
    mean = sum / static_cast<double>(v.size());
    std::sort(v.begin(), v.end());
    median = v[v.size() / 2];
  };
  const std::size_t split = ms.size() == 600 ? 300 : ms.size() / 2;
  Halves h;
  summary({ms.begin(), ms.begin() + static_cast<std::ptrdiff_t>(split)}, h.pour_mean, h.pour_median);
  summary({ms.begin() + static_cast<std::ptrdiff_t>(split), ms.end()}, h.settled_mean, h.settled_median);
  return h;
}

nlohmann::ordered_json run_bullet(const PourScene& scene, int steps) {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &configuration);
  world.setGravity(btVector3(0, -9.81f, 0));

  // Bullet combines materials by product: sqrt gives the scene's pair values.
  const btScalar restitution = std::sqrt(scene.restitution);
  const btScalar friction = std::sqrt(scene.friction);
  const btScalar half = 0.5f * scene.pit_width();

  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  // Floor (y = 0) and four walls, normals pointing into the pit: n . x = constant.
  const btVector3 normals[] = {{0, 1, 0}, {1, 0, 0}, {-1, 0, 0}, {0, 0, 1}, {0, 0, -1}};
  for (int p = 0; p < 5; ++p) {
    shapes.push_back(std::make_unique<btStaticPlaneShape>(normals[p], p == 0 ? 0 : -half));
    btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, shapes.back().get());
    info.m_restitution = restitution;
    info.m_friction = friction;
    bodies.push_back(std::make_unique<btRigidBody>(info));
    world.addRigidBody(bodies.back().get());
  }
  auto sphere = std::make_unique<btSphereShape>(scene.radius);
  btVector3 inertia(0, 0, 0);
  sphere->calculateLocalInertia(scene.mass, inertia);
  const std::vector<Vec3> start = scene.initial_positions();
  std::vector<btRigidBody*> balls;
  balls.reserve(start.size());
  for (const Vec3& x : start) {
    btRigidBody::btRigidBodyConstructionInfo info(scene.mass, nullptr, sphere.get(), inertia);
    info.m_startWorldTransform.setOrigin(btVector3(x.x(), x.y(), x.z()));
    info.m_restitution = restitution;
    info.m_friction = friction;
    bodies.push_back(std::make_unique<btRigidBody>(info));
    bodies.back()->setActivationState(DISABLE_DEACTIVATION);
    world.addRigidBody(bodies.back().get());
    balls.push_back(bodies.back().get());
  }

  std::vector<double> ms;
  SettleWatch settle(balls.size(), scene.mass);
  // Bullet's inertia tensor of a solid sphere: 2/5 m r^2, as ballpit's.
  const double spin_inertia = 0.4 * scene.mass * scene.radius * scene.radius;
  auto started = std::chrono::steady_clock::now(), last_report = started;
  for (int s = 0; s < steps; ++s) {
    auto t0 = std::chrono::steady_clock::now();
    world.stepSimulation(scene.dt, 0);  // maxSubSteps 0: exactly one step of dt
    auto t1 = std::chrono::steady_clock::now();
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    double ke = 0.0;
    for (const btRigidBody* b : balls)
      ke += 0.5 * scene.mass * b->getLinearVelocity().length2() +
            0.5 * spin_inertia * b->getAngularVelocity().length2();
    settle.after_step(ke);
    if (t1 - last_report > std::chrono::seconds(5)) {
      last_report = t1;
      double elapsed = std::chrono::duration<double>(t1 - started).count();
      std::fprintf(stderr, "[bullet] step %d/%d, %.1f s elapsed, about %.0f s left\n", s + 1, steps, elapsed,
                   elapsed / (s + 1) * (steps - s - 1));
    }
  }

  // The same metrics as ballpit's: copy Bullet's state into a pour world (same sphere order).
  World mirror;
  scene.build(mirror);
  auto x = mirror.spheres.mut_position();
  auto v = mirror.spheres.mut_velocity();
  auto w = mirror.spheres.mut_angular_velocity();
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const btVector3& p = balls[i]->getWorldTransform().getOrigin();
    const btVector3& lv = balls[i]->getLinearVelocity();
    const btVector3& av = balls[i]->getAngularVelocity();
    x[i] = Vec3(p.x(), p.y(), p.z());
    v[i] = Vec3(lv.x(), lv.y(), lv.z());
    if (!w.empty()) w[i] = Vec3(av.x(), av.y(), av.z());
  }
  Metrics m = measure(mirror);
  // Bullet drops a removed body's pairs by scanning every pair: O(N x pairs) for the whole pit,
  // over ten minutes at 100k. Dropping each pair first (the last one, O(1)) keeps it linear.
  btOverlappingPairCache* pairs = world.getBroadphase()->getOverlappingPairCache();
  while (pairs->getNumOverlappingPairs() > 0) {
    btBroadphasePair& last = pairs->getOverlappingPairArray()[pairs->getNumOverlappingPairs() - 1];
    pairs->removeOverlappingPair(last.m_pProxy0, last.m_pProxy1, &dispatcher);
  }
  for (auto& b : bodies) world.removeRigidBody(b.get());

  Halves h = split_times(ms);
  nlohmann::ordered_json j;
  j["engine"] = "bullet-" + std::to_string(BT_BULLET_VERSION);
  j["scene"] = "pour";
  j["spheres"] = balls.size();
  j["threads"] = 1;
  j["steps"] = steps;
  j["dt"] = scene.dt;
  j["ms_per_step_pour_mean"] = h.pour_mean;
  j["ms_per_step_pour_median"] = h.pour_median;
  j["ms_per_step_settled_mean"] = h.settled_mean;
  j["ms_per_step_settled_median"] = h.settled_median;
  j["max_penetration_r"] = m.max_penetration_r;
  j["mean_penetration_r"] = m.mean_penetration_r;
  j["max_wall_penetration_r"] = m.max_wall_penetration_r;
  j["escaped"] = m.escaped;
  j["kinetic_energy_j"] = m.kinetic_energy_j;
  j["max_speed_mps"] = m.max_speed_mps;
  settle.report(j, scene.dt);
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The pour scene in Bullet and in ballpit, side by side"};
  std::size_t spheres = 10000;
  int steps = 120;
  std::vector<int> threads = {1, 2};
  app.add_option("--spheres", spheres, "Number of spheres N")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--steps", steps, "Steps both engines run (600 = the whole pour; shorter is stated)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--threads", threads, "ballpit thread counts to run (Bullet is single-threaded)")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  try {
    PourScene scene;
    scene.spheres = spheres;
    std::vector<nlohmann::ordered_json> rows;
    for (int t : threads) {
      RunOptions o;
      o.scene = "pour";
      o.spheres = spheres;
      o.steps = steps;
      o.threads = t;
      o.print_table = false;
      SettleWatch settle(spheres, scene.mass);
      o.after_step = [&settle](const World& w) { settle.after_step(kinetic_energy(w)); };
      nlohmann::ordered_json ours;
      ours["engine"] = "ballpit";
      const nlohmann::ordered_json report = run_headless(o);
      for (auto it = report.begin(); it != report.end(); ++it) ours[it.key()] = it.value();
      settle.report(ours, scene.dt);
      rows.push_back(ours);
    }
    rows.push_back(run_bullet(scene, steps));

    std::printf("pour, N = %zu, %d steps of 1/60 s%s\n", spheres, steps,
                steps < scene.steps ? " (SHORTENED: the canonical pour is 600 steps; both engines ran the same steps)" : "");
    std::printf("%-12s %7s %12s %12s %12s %12s %10s %10s %8s %10s %10s\n", "engine", "threads", "ms/step 1st",
                "ms/step 2nd", "max pen/r", "mean pen/r", "wall pen/r", "KE (J)", "escaped", "max v", "settled at");
    for (const auto& r : rows)
      std::printf("%-12s %7d %12.3f %12.3f %12.4f %12.5f %10.4f %10.5f %8zu %10.3f %10s\n",
                  r["engine"].get<std::string>().c_str(), r["threads"].get<int>(),
                  r["ms_per_step_pour_median"].get<double>(), r["ms_per_step_settled_median"].get<double>(),
                  r["max_penetration_r"].get<double>(), r["mean_penetration_r"].get<double>(),
                  r["max_wall_penetration_r"].get<double>(), r["kinetic_energy_j"].get<double>(),
                  r["escaped"].get<std::size_t>(), r["max_speed_mps"].get<double>(), settled_text(r).c_str());
    std::printf("(ms/step: medians of the first and second half of the run)\n");
    for (const auto& r : rows) std::cout << r.dump() << "\n";
  } catch (const ballpit::Error& e) {
    std::fprintf(stderr, "bullet_pour: %s\n", e.what());
    return 2;
  }
  return 0;
}
