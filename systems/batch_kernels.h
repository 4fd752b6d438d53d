// The solver's passes over batches of sixteen sphere pairs (systems/contact_batch.h), compiled
// for each instruction set this machine may have, and chosen once per process: AVX-512, AVX2,
// or plain code for any CPU. All three compute the same bits (systems/lanes.h), so the choice is
// speed only; BALLPIT_KERNELS=generic|avx2|avx512 forces one (tests run all three and compare).
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "systems/contact_batch.h"
#include "systems/solver_bodies.h"

namespace ballpit {

// Overlap (fraction of the smaller radius) beyond which a contact is not warm-started: its last
// impulse was found for a pair that has since moved deep into each other (a crowd spawned
// inside itself, a ball wedged under a limb), and re-applying impulses that cancelled each other
// in the old geometry fed each substep's impulses into the next (speeds grew 1.7x per substep,
// to 48 m/s in the speed-error crowd case). A resting pile overlaps by well under a tenth of r.
// An overlap this deep is also no impact unless one move at the pair's speed could have made it.
inline constexpr float kWarmStartReach = 0.5f;

// For a solid sphere r^2 / I = 5 / (2 m): a tangential impulse J at the surface changes r w by
// 2.5 J / m, while it changes v by J / m.
inline constexpr float kSphereSpinFactor = 2.5f;

// Spinning friction against a pit plane or a joint collider: the contact is a patch, not a point,
// so friction resists spin about the normal too, with a torque of at most mu N times this
// fraction of the ball's radius (MuJoCo's default torsional arm, 5 mm, is an eighth of a pit
// ball's). Without it nothing slows a ball spinning about the normal: a ball on the floor of a
// settled 1,000-ball pour (its pairs found at a 0.02 r minimum margin) turned at 0.76 rad/s for
// good and kept its pile from sleeping.
inline constexpr float kTwistArmFraction = 0.1f;

// The three passes of a substep (systems/solver.h).
enum class ContactPass { WarmStart, Solve, Relax };

struct PassParams {
  float h;                      // substep (unit: s)
  float inv_h;                  // (unit: 1/s)
  float push_rate;              // push_out_rate / h: how fast overlap is pushed out (unit: 1/s)
  float push_out_speed;         // cap on push-out (unit: m/s)
  float restitution_threshold;  // slower impacts are inelastic (unit: m/s)
};

struct BatchPassArgs {
  PassParams params;
  // Whether each batch's kept frames (nx.., gap) are those of the current positions; if not,
  // Solve computes them (WarmStart and Relax always do).
  bool frames_current = false;
  std::uint8_t* wake_requests = nullptr;  // per row; null when nothing sleeps
  float wake_speed = 0.0f;                // a blow that changes a mover's speed by more wakes a sleeper (m/s)
  float gravity[3] = {0.0f, 0.0f, 0.0f};  // (unit: m/s^2)
};

struct BatchPassResult {
  bool shifted = false;  // Relax moved spheres by impact shifts: kept frames are stale
};

using BatchPass = void (*)(ContactBatch* begin, ContactBatch* end, SolverBodies& bodies, const BatchPassArgs& args,
                           BatchPassResult& result);

// What the lanes of a batch touch: sphere pairs, or spheres against pit planes.
enum class BatchKind { Pairs, Planes };

struct BatchKernels {
  std::string_view name;
  BatchPass pass[2][3][2];  // [BatchKind][ContactPass][spheres spin]

  BatchPass get(BatchKind kind, ContactPass p, bool spin) const {
    return pass[static_cast<int>(kind)][static_cast<int>(p)][spin ? 1 : 0];
  }
};

// The kernels of this process: BALLPIT_KERNELS if set (an error naming the variable if this
// build or CPU lacks them), else the fastest this CPU runs.
const BatchKernels& batch_kernels();
// Every kernel set this build has and this CPU runs, plain first.
std::vector<const BatchKernels*> available_batch_kernels();

// One per instruction set, defined in systems/batch_kernels_<name>.cpp where built.
const BatchKernels& generic_batch_kernels();
const BatchKernels& avx2_batch_kernels();
const BatchKernels& avx512_batch_kernels();

}  // namespace ballpit
