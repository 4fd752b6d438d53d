// The per-frame uniform block every program reads (camera, sun, pit, fill height), and the
// lighting model they share, as GLSL text to paste into each program. Written once per frame
// into one uniform buffer at binding 0.
// Decision: one light model for balls, pit and character (a sun, a sky/ground ambient and
// occlusion that darkens with depth in the pit) so all three read as one scene; no shadow
// maps and no textures, which keeps llvmpipe fast enough at a million balls.
#pragma once

#include "engine/math.h"

namespace ballpit {

// Mirrors the std140 block below; every member is 16-byte aligned.
struct FrameUniforms {
  Mat4 view;
  Mat4 projection;
  Mat4 view_inverse;
  Vec4 eye;       // xyz: eye position (unit: m)
  Vec4 sun;       // xyz: unit direction towards the sun
  Vec4 pit;       // x: half width (unit: m), y: drawn wall height (unit: m), z: fill height (unit: m)
  Vec4 viewport;  // x, y: size (unit: pixel)
};
static_assert(sizeof(FrameUniforms) == 3 * 64 + 4 * 16, "FrameUniforms must match the std140 block");

inline constexpr const char* kFrameGlsl = R"glsl(
layout(std140, binding = 0) uniform Frame {
  mat4 u_view;
  mat4 u_projection;
  mat4 u_view_inverse;
  vec4 u_eye;
  vec4 u_sun;
  vec4 u_pit;
  vec4 u_viewport;
};

vec3 srgb_to_linear(vec3 c) { return pow(c, vec3(2.2)); }
vec3 linear_to_srgb(vec3 c) { return pow(clamp(c, 0.0, 1.0), vec3(1.0 / 2.2)); }

// Light from the sky above, bounce from the floor below.
vec3 ambient(vec3 n) {
  return mix(vec3(0.16, 0.15, 0.14), vec3(0.42, 0.47, 0.56), 0.5 + 0.5 * n.y);
}

// Occlusion-like darkening by depth: light reaching a point low in the pit passes the balls
// and walls above it, so it fades from 1 at the fill height to 0.35 on the floor.
float depth_occlusion(vec3 p) {
  float reference = max(u_pit.z, 0.25);
  return mix(0.35, 1.0, smoothstep(0.0, reference, p.y));
}

// Lambert sun plus ambient, with a Blinn-Phong highlight; occlusion dims the ambient fully
// and the sun by half (a pile shades itself, but the top of a ball still catches the sun).
vec3 shade(vec3 albedo, vec3 n, vec3 p, float occlusion, float shininess, float specular) {
  vec3 l = u_sun.xyz;
  vec3 v = normalize(u_eye.xyz - p);
  float ndl = max(dot(n, l), 0.0);
  vec3 h = normalize(l + v);
  float spec = ndl > 0.0 ? pow(max(dot(n, h), 0.0), shininess) * specular : 0.0;
  vec3 sun = vec3(1.0, 0.95, 0.88) * 0.9;
  return albedo * (sun * ndl * mix(1.0, occlusion, 0.5) + ambient(n) * occlusion) + sun * spec * occlusion;
}
)glsl";

}  // namespace ballpit
