// Speculative margins: how far apart two bodies may be and still be listed as a contact for the
// coming step (or pass of a step, engine/step_passes.h), and the most a margin may be. The
// narrowphase lists pairs by these; the fixed-step loop splits a step into passes short enough
// that no margin exceeds the cap, so both must agree on one formula, which lives here.
#pragma once

namespace ballpit {

// Every awake sphere lists neighbours within this fraction of its radius, however slow: a
// resting row must already know its touching pairs when a blow lands mid-step, or the blow
// cannot pass along it within the step (Newton's cradle). Touching is what it must cover: at
// 0.05 r a settled 100k pile listed 72,650 pairs (21%) 0.01 to 0.15 r apart that carried
// nothing and cost a lane in every pass; at 0.02 r its settled step is about 8% cheaper, and
// every case of profiling/reports/speed_error.md keeps its bound.
inline constexpr float kMinMarginFraction = 0.02f;

// The largest pair margin, as a fraction of the sphere's own radius. It bounds what a sphere
// lists: partners whose centres lie within r_i + r_j + m_i + m_j, at most (2 + 2 x 2.5) r = 7 r
// for equal radii, so at most 0.74 x 7^3 = 254 partners even if every ball near it moved at the
// cap (0.74: the densest packing of equal spheres); one fast ball in a resting pile reaches
// 4.52 r, 68 at most. It is no smaller because the canonical pour must run as before, in one
// pass a step: its fastest ball (about 4.7 m/s after a 1.1 m fall) has a margin of 1.97 r at
// 1/60 s, and the pit character's flung balls reach about the same. Faster motion is split
// into passes instead (engine/step_passes.h), each with margins within the cap.
inline constexpr float kMostMarginFraction = 2.5f;

// Speculative margin of a sphere moving at `speed` for one step dt under gravity g, against
// another sphere: the distance it can cover, plus the minimum above, plus a quarter of g dt^2.
// Gravity moves both spheres alike, so a pair closes under it only where one sphere falls and
// the other is held up: by at most 1/2 g dt^2, half of which each side's margin covers.
float pair_margin(float speed, float dt, float gravity, float radius);

// pair_margin held to the cap, kMostMarginFraction x radius: what the narrowphase lists by in a
// world without joint colliders (one with them runs whole steps, engine/step_passes.h). It
// differs from pair_margin only in a step that needed more passes than the loop allows, which
// the loop warns of.
float capped_pair_margin(float speed, float dt, float gravity, float radius);

// What a margin against a pit plane or a joint collider adds to the pair margin: those do not
// fall with the sphere, so it covers the whole gravity drop twice over, for the velocity the
// sphere gains (g dt^2 in all).
float static_margin_extra(float dt, float gravity);

// The same sphere's margin against a pit plane or a joint collider.
float speculative_margin(float speed, float dt, float gravity, float radius);

}  // namespace ballpit
