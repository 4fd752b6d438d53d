// The low-poly sphere of the mesh path (and the collider debug draw): a subdivided icosahedron.
// Decision: vertices sit slightly outside the unit sphere, scaled so the mesh's volume equals
// the sphere's; an inscribed mesh would draw every ball visibly smaller than its impostor,
// while equal volume keeps their on-screen coverage within a few percent (tested).
#pragma once

#include <cstdint>
#include <vector>

#include "engine/math.h"

namespace ballpit {

struct IcosphereMesh {
  std::vector<Vec3> positions;          // also the outward normals, once normalised
  std::vector<std::uint16_t> indices;   // counter-clockwise triangles seen from outside
  float scale = 1.0f;                   // the factor applied to put the vertices off the unit sphere
};

// subdivisions 0: 20 triangles, 1: 80, 2: 320.
IcosphereMesh make_icosphere(int subdivisions);

}  // namespace ballpit
