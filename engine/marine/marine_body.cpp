// The marine's body, built from a signed distance field: a smooth union (polynomial smooth-min)
// of round cones, ellipsoids and rounded boxes laid along his bones (a real 1.8 m man's limb
// radii) plus his gear (helmet, plate carrier, pack, belt), polygonised with naive surface nets,
// the vertices then projected onto the surface and given the field's gradient as normal.
// Each primitive carries a material (its colour) and a region (core, a limb, a piece of gear),
// and the dominant primitive at a vertex chooses both; skin weights come from the region's bone
// chain, blended across each joint by a smooth step over a few centimetres.
// Decision: surface nets on a grid whose checkerboard faces have been removed gives a closed
// mesh by construction (every dual edge lies in exactly two quads), with no lookup tables.
#include "engine/marine/marine_body.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/marine/camouflage.h"
#include "engine/marine/marine_skeleton.h"

namespace ballpit::marine {

namespace {

// Grid cell of the polygonisation (unit: m): ~1.7 cm gives some 20k triangles.
constexpr float kCell = 0.017f;
// Region-to-region skin blending: a vertex takes weight from a second region while that
// region's nearest primitive is within this much of the dominant one (unit: m).
constexpr float kRegionBlend = 0.05f;

// Eyes: dark brown spots on the face (the other colours are in marine_body.h and camouflage.h).
constexpr Srgb8 kEye = {0x3a, 0x2a, 0x20, 0xff};

enum class Shape : std::uint8_t { kRoundCone, kEllipsoid, kRoundBox };
enum class Material : std::uint8_t { kSkin, kUniform, kBoot, kGear, kHelmet };
// Skin regions, each with its bone chain: the body's core (and belt), each limb, and the two
// rigid pieces of gear, which follow their bones (carrier and pack: Spine1/Spine2; helmet: Head).
enum Region : std::uint8_t {
  kCore, kLeftArmRegion, kRightArmRegion, kLeftLegRegion, kRightLegRegion, kCarrier, kHelmetRegion, kRegions
};

struct Primitive {
  Shape shape;
  Material material;
  Region region;
  Vec3 a = Vec3::Zero(), b = Vec3::Zero();  // round cone: end centres; others: a is the centre
  float ra = 0.0f, rb = 0.0f;               // round cone: end radii; round box: rounding radius
  Vec3 size = Vec3::Zero();                 // ellipsoid radii / box half extents, local axes
  Mat3 axes = Mat3::Identity();             // columns: local axes in model space
  float blend = 0.0f;                       // smooth-union radius with what came before (unit: m)
  bool cut = false;                         // keep only dot(cut_n, p) >= cut_c (helmet rim)
  Vec3 cut_n = Vec3::UnitY();
  float cut_c = 0.0f;
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // bounds, widened by the blend and two cells
};

float sign(float x) { return x > 0.0f ? 1.0f : (x < 0.0f ? -1.0f : 0.0f); }

// Inigo Quilez's round cone between two spheres (exact distance).
float round_cone(const Vec3& p, const Vec3& a, const Vec3& b, float r1, float r2) {
  const Vec3 ba = b - a;
  const float l2 = ba.squaredNorm(), rr = r1 - r2, a2 = l2 - rr * rr, il2 = 1.0f / l2;
  const Vec3 pa = p - a;
  const float y = pa.dot(ba), z = y - l2;
  const float x2 = (pa * l2 - ba * y).squaredNorm(), y2 = y * y * l2, z2 = z * z * l2;
  const float k = sign(rr) * rr * rr * x2;
  if (sign(z) * a2 * z2 > k) return std::sqrt(x2 + z2) * il2 - r2;
  if (sign(y) * a2 * y2 < k) return std::sqrt(x2 + y2) * il2 - r1;
  return (std::sqrt(x2 * a2 * il2) + y * rr) * il2 - r1;
}

float distance(const Primitive& s, const Vec3& p) {
  float d = 0.0f;
  if (s.shape == Shape::kRoundCone) {
    d = round_cone(p, s.a, s.b, s.ra, s.rb);
  } else {
    const Vec3 q = s.axes.transpose() * (p - s.a);
    if (s.shape == Shape::kEllipsoid) {  // Quilez's bound, good near the surface
      const float k0 = q.cwiseQuotient(s.size).norm();
      const float k1 = q.cwiseQuotient(s.size.cwiseProduct(s.size)).norm();
      d = k1 > 1e-9f ? k0 * (k0 - 1.0f) / k1 : -s.size.minCoeff();
    } else {
      const Vec3 e = q.cwiseAbs() - s.size;
      d = e.cwiseMax(0.0f).norm() + std::min(e.maxCoeff(), 0.0f) - s.ra;
    }
  }
  if (s.cut) d = std::max(d, s.cut_c - s.cut_n.dot(p));
  return d;
}

// Polynomial smooth minimum (Quilez): equals min(a, b) once they differ by more than k.
float smooth_min(float a, float b, float k) {
  if (k <= 0.0f) return std::min(a, b);
  const float h = std::max(k - std::abs(a - b), 0.0f) / k;
  return std::min(a, b) - h * h * k * 0.25f;
}

Primitive cone(const Vec3& a, float ra, const Vec3& b, float rb, float blend, Material m, Region r) {
  Primitive s{Shape::kRoundCone, m, r};
  s.a = a, s.b = b, s.ra = ra, s.rb = rb, s.blend = blend;
  const float rmax = std::max(ra, rb);
  s.lo = a.cwiseMin(b) - Vec3::Constant(rmax);
  s.hi = a.cwiseMax(b) + Vec3::Constant(rmax);
  return s;
}

Primitive solid(Shape shape, const Vec3& centre, const Vec3& size, float rounding, float blend, Material m, Region r,
                const Mat3& axes = Mat3::Identity()) {
  Primitive s{shape, m, r};
  s.a = centre, s.size = size, s.ra = rounding, s.axes = axes, s.blend = blend;
  const Vec3 extent = axes.cwiseAbs() * (size + Vec3::Constant(rounding));
  s.lo = centre - extent;
  s.hi = centre + extent;
  return s;
}

// Every primitive of the body, in union order. Positions from the bind pose (metres).
std::vector<Primitive> make_primitives() {
  const auto P = bind_positions();
  std::vector<Primitive> v;
  using S = Shape;
  using M = Material;
  // Torso: pelvis, abdomen, chest, the shoulder line, then neck and head.
  v.push_back(solid(S::kEllipsoid, Vec3(0.0f, 0.925f, -0.015f), Vec3(0.165f, 0.115f, 0.115f), 0, 0.0f, M::kUniform, kCore));
  v.push_back(solid(S::kEllipsoid, Vec3(0.0f, 1.07f, 0.0f), Vec3(0.15f, 0.13f, 0.105f), 0, 0.05f, M::kUniform, kCore));
  v.push_back(solid(S::kEllipsoid, Vec3(0.0f, 1.27f, -0.01f), Vec3(0.175f, 0.16f, 0.115f), 0, 0.05f, M::kUniform, kCore));
  for (float s : {1.0f, -1.0f})  // trapezius to the shoulder
    v.push_back(cone(Vec3(0.0f, 1.43f, -0.025f), 0.07f, Vec3(s * 0.16f, 1.42f, -0.02f), 0.062f, 0.04f, M::kUniform, kCore));
  v.push_back(cone(Vec3(0.0f, 1.42f, -0.015f), 0.07f, Vec3(0.0f, 1.485f, -0.012f), 0.062f, 0.02f, M::kUniform, kCore));  // collar
  v.push_back(cone(Vec3(0.0f, 1.42f, -0.015f), 0.066f, Vec3(0.0f, 1.60f, 0.0f), 0.058f, 0.03f, M::kSkin, kCore));
  v.push_back(solid(S::kEllipsoid, Vec3(0.0f, 1.665f, 0.015f), Vec3(0.08f, 0.105f, 0.098f), 0, 0.03f, M::kSkin, kCore));
  v.push_back(solid(S::kEllipsoid, Vec3(0.0f, 1.605f, 0.04f), Vec3(0.06f, 0.05f, 0.06f), 0, 0.03f, M::kSkin, kCore));  // jaw
  v.push_back(solid(S::kEllipsoid, Vec3(0.0f, 1.655f, 0.112f), Vec3(0.014f, 0.024f, 0.02f), 0, 0.01f, M::kSkin, kCore));  // nose
  for (float s : {1.0f, -1.0f})  // ears
    v.push_back(solid(S::kEllipsoid, Vec3(s * 0.08f, 1.66f, 0.0f), Vec3(0.012f, 0.028f, 0.018f), 0, 0.01f, M::kSkin, kCore));
  // Helmet: a dome whose rim rises from the nape to the brow; its top is the stature.
  {
    const Vec3 r(0.112f, 0.132f, 0.13f);
    Primitive h = solid(S::kEllipsoid, Vec3(0.0f, kStature - r.y(), 0.01f), r, 0, 0.008f, M::kHelmet, kHelmetRegion);
    h.cut = true;
    h.cut_n = Vec3(0.0f, 1.0f, -0.5f).normalized();
    h.cut_c = h.cut_n.dot(Vec3(0.0f, 1.66f, 0.0f));
    v.push_back(h);
  }
  // Plate carrier with its magazine pouches and shoulder straps; a small pack; a belt.
  v.push_back(solid(S::kRoundBox, Vec3(0.0f, 1.235f, -0.005f), Vec3(0.14f, 0.135f, 0.105f), 0.025f, 0.01f, M::kGear, kCarrier));
  v.push_back(solid(S::kRoundBox, Vec3(0.0f, 1.14f, 0.135f), Vec3(0.12f, 0.04f, 0.02f), 0.012f, 0.008f, M::kGear, kCarrier));
  for (float s : {1.0f, -1.0f}) {
    v.push_back(cone(Vec3(s * 0.10f, 1.38f, 0.10f), 0.022f, Vec3(s * 0.11f, 1.47f, -0.02f), 0.022f, 0.008f, M::kGear, kCarrier));
    v.push_back(cone(Vec3(s * 0.11f, 1.47f, -0.02f), 0.022f, Vec3(s * 0.10f, 1.38f, -0.13f), 0.022f, 0.008f, M::kGear, kCarrier));
  }
  v.push_back(solid(S::kRoundBox, Vec3(0.0f, 1.24f, -0.185f), Vec3(0.10f, 0.12f, 0.04f), 0.025f, 0.01f, M::kGear, kCarrier));
  v.push_back(solid(S::kEllipsoid, Vec3(0.0f, 1.0f, -0.005f), Vec3(0.148f, 0.028f, 0.118f), 0, 0.01f, M::kGear, kCore));

  for (int side = 0; side < 2; ++side) {
    const int o = side == 0 ? 0 : kRightUpLeg - kLeftUpLeg;
    const Region leg = side == 0 ? kLeftLegRegion : kRightLegRegion;
    const Vec3 hip = P[kLeftUpLeg + o], knee = P[kLeftLeg + o], ankle = P[kLeftFoot + o];
    const float x = hip.x();
    v.push_back(cone(hip, 0.088f, knee, 0.056f, 0.04f, M::kUniform, leg));                               // thigh
    v.push_back(cone(knee, 0.054f, Vec3(x, 0.14f, ankle.z()), 0.042f, 0.03f, M::kUniform, leg));         // shin
    v.push_back(solid(S::kEllipsoid, Vec3(x, 0.36f, -0.02f), Vec3(0.05f, 0.10f, 0.052f), 0, 0.03f, M::kUniform, leg));  // calf
    v.push_back(cone(Vec3(x, 0.09f, 0.0f), 0.052f, Vec3(x, 0.20f, -0.005f), 0.05f, 0.015f, M::kBoot, leg));  // boot shaft
    // Boot foot, heel to toe, cut flat by the sole: the floor, y = 0.
    Primitive foot = cone(Vec3(x, 0.052f, -0.035f), 0.052f, Vec3(x, 0.042f, 0.185f), 0.042f, 0.02f, M::kBoot, leg);
    foot.cut = true;
    foot.cut_n = Vec3::UnitY();
    foot.cut_c = 0.0f;
    v.push_back(foot);
  }
  for (int side = 0; side < 2; ++side) {
    const int o = side == 0 ? 0 : kRightShoulder - kLeftShoulder;
    const Region arm = side == 0 ? kLeftArmRegion : kRightArmRegion;
    const Vec3 shoulder = P[kLeftArm + o], elbow = P[kLeftForeArm + o], wrist = P[kLeftHand + o];
    const Vec3 dir = (wrist - elbow).normalized();
    v.push_back(solid(S::kEllipsoid, shoulder + 0.02f * dir, Vec3::Constant(0.062f), 0, 0.03f, M::kUniform, arm));  // deltoid
    v.push_back(cone(shoulder, 0.056f, elbow, 0.044f, 0.03f, M::kUniform, arm));
    v.push_back(cone(elbow, 0.045f, wrist - 0.01f * dir, 0.034f, 0.03f, M::kUniform, arm));
    Mat3 hand_axes;
    hand_axes.col(0) = dir;
    hand_axes.col(1) = Vec3::UnitZ();
    hand_axes.col(2) = dir.cross(Vec3::UnitZ());
    v.push_back(solid(S::kEllipsoid, wrist + 0.08f * dir, Vec3(0.085f, 0.045f, 0.026f), 0, 0.02f, M::kSkin, arm, hand_axes));
    v.push_back(cone(wrist + 0.03f * dir + Vec3(0, 0, 0.035f), 0.014f, wrist + 0.09f * dir + Vec3(0, 0, 0.05f), 0.012f,
                     0.015f, M::kSkin, arm));  // thumb
  }
  for (Primitive& s : v) {
    const Vec3 margin = Vec3::Constant(s.blend + 2.0f * kCell);
    s.lo -= margin;
    s.hi += margin;
  }
  return v;
}

// The field at one point: the smooth union in primitive order, the nearest primitive (it
// chooses material and region) and each region's nearest distance. Primitives whose widened
// bounds miss the point are skipped; grid and point evaluation use the same test.
struct Sample {
  float d = 1.0f;
  int dominant = -1;
  std::array<float, kRegions> region_d{1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f};
};

bool inside(const Primitive& s, const Vec3& p) {
  return p.x() >= s.lo.x() && p.x() <= s.hi.x() && p.y() >= s.lo.y() && p.y() <= s.hi.y() && p.z() >= s.lo.z() &&
         p.z() <= s.hi.z();
}

Sample sample(const std::vector<Primitive>& prims, const Vec3& p) {
  Sample out;
  float best = 1.0f;
  for (std::size_t i = 0; i < prims.size(); ++i) {
    const Primitive& s = prims[i];
    if (!inside(s, p)) continue;
    const float d = distance(s, p);
    out.d = smooth_min(out.d, d, s.blend);
    if (d < best) best = d, out.dominant = static_cast<int>(i);
    out.region_d[s.region] = std::min(out.region_d[s.region], d);
  }
  return out;
}

float field(const std::vector<Primitive>& prims, const Vec3& p) { return sample(prims, p).d; }

Vec3 gradient(const std::vector<Primitive>& prims, const Vec3& p) {
  constexpr float e = 5e-4f;  // central differences (unit: m)
  return Vec3(field(prims, p + Vec3(e, 0, 0)) - field(prims, p - Vec3(e, 0, 0)),
              field(prims, p + Vec3(0, e, 0)) - field(prims, p - Vec3(0, e, 0)),
              field(prims, p + Vec3(0, 0, e)) - field(prims, p - Vec3(0, 0, e))) /
         (2.0f * e);
}

// A bone chain (core, one arm, one leg): joints in order, each owning the segment after it.
// At each interior joint a plane through it (normal: the bisector of the two segments) splits
// parent from child, smoothed over +-width; the weights telescope, so they sum to 1.
struct ChainJoint {
  Joint bone;    // the bone owning the segment that starts here
  Vec3 at;       // the plane's point (the joint's bind position)
  Vec3 normal;   // towards the child
  float width;   // half-width of the blend zone (unit: m)
};
struct Chain {
  Joint root;    // the bone before the first plane
  std::vector<ChainJoint> joints;
};

float smoothstep(float e0, float e1, float x) {
  const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

std::array<Chain, kRegions> make_chains() {
  const auto P = bind_positions();
  auto bisector = [](const Vec3& a, const Vec3& b) { return (a.normalized() + b.normalized()).normalized(); };
  std::array<Chain, kRegions> c;
  const Vec3 down(0.0f, -1.0f, 0.0f), up(0.0f, 1.0f, 0.0f);
  c[kCore].root = kHips;
  c[kCore].joints = {{kSpine, P[kSpine], up, 0.05f},
                     {kSpine1, P[kSpine1], up, 0.05f},
                     {kSpine2, P[kSpine2], up, 0.05f},
                     {kNeck, P[kNeck], up, 0.03f},
                     {kHead, P[kHead], up, 0.03f}};
  c[kCarrier].root = kSpine1;
  c[kCarrier].joints = {{kSpine2, P[kSpine2], up, 0.08f}};
  c[kHelmetRegion].root = kHead;
  for (int side = 0; side < 2; ++side) {
    const int a = side == 0 ? 0 : kRightShoulder - kLeftShoulder;
    const Vec3 clav = P[kLeftArm + a] - P[kLeftShoulder + a], upper = P[kLeftForeArm + a] - P[kLeftArm + a];
    const Vec3 fore = P[kLeftHand + a] - P[kLeftForeArm + a];
    Chain& arm = c[side == 0 ? kLeftArmRegion : kRightArmRegion];
    arm.root = kSpine2;
    arm.joints = {{static_cast<Joint>(kLeftShoulder + a), P[kLeftShoulder + a], clav.normalized(), 0.04f},
                  {static_cast<Joint>(kLeftArm + a), P[kLeftArm + a], bisector(clav, upper), 0.05f},
                  {static_cast<Joint>(kLeftForeArm + a), P[kLeftForeArm + a], bisector(upper, fore), 0.05f},
                  {static_cast<Joint>(kLeftHand + a), P[kLeftHand + a], fore.normalized(), 0.03f}};
    const int l = side == 0 ? 0 : kRightUpLeg - kLeftUpLeg;
    const Vec3 thigh = P[kLeftLeg + l] - P[kLeftUpLeg + l], shin = P[kLeftFoot + l] - P[kLeftLeg + l];
    const Vec3 foot = P[kLeftToeBase + l] - P[kLeftFoot + l], toe = Vec3::UnitZ();
    Chain& leg = c[side == 0 ? kLeftLegRegion : kRightLegRegion];
    leg.root = kHips;
    leg.joints = {{static_cast<Joint>(kLeftUpLeg + l), P[kLeftUpLeg + l], bisector(down, thigh), 0.05f},
                  {static_cast<Joint>(kLeftLeg + l), P[kLeftLeg + l], bisector(thigh, shin), 0.05f},
                  {static_cast<Joint>(kLeftFoot + l), P[kLeftFoot + l], bisector(shin, foot), 0.04f},
                  {static_cast<Joint>(kLeftToeBase + l), P[kLeftToeBase + l], bisector(foot, toe), 0.03f}};
  }
  return c;
}

// Adds `scale` x the chain's weights at p into w (indexed by joint).
void add_chain_weights(const Chain& chain, const Vec3& p, float scale, std::array<float, kJoints>& w) {
  float reach = 1.0f;  // how much of the weight has got past every plane so far
  Joint owner = chain.root;
  for (const ChainJoint& j : chain.joints) {
    const float past = smoothstep(-j.width, j.width, j.normal.dot(p - j.at));
    w[owner] += scale * reach * (1.0f - past);
    reach *= past;
    owner = j.bone;
  }
  w[owner] += scale * reach;
}

bool is_limb(int region) { return region >= kLeftArmRegion && region <= kRightLegRegion; }

}  // namespace

SkinnedMesh make_body(const Skeleton& skeleton) {
  (void)skeleton;  // the body is laid along bind_positions(), which make_skeleton() also uses
  const std::vector<Primitive> prims = make_primitives();
  const std::array<Chain, kRegions> chains = make_chains();

  // The grid: covers him with two empty cells each side, so the surface never meets its edge.
  const Vec3 lo(-0.78f, -0.04f, -0.32f), hi(0.78f, 1.84f, 0.32f);
  const int nx = static_cast<int>(std::ceil((hi.x() - lo.x()) / kCell)) + 1;
  const int ny = static_cast<int>(std::ceil((hi.y() - lo.y()) / kCell)) + 1;
  const int nz = static_cast<int>(std::ceil((hi.z() - lo.z()) / kCell)) + 1;
  auto at = [&](int i, int j, int k) { return (static_cast<std::size_t>(k) * ny + j) * nx + i; };
  auto point = [&](int i, int j, int k) { return Vec3(lo.x() + i * kCell, lo.y() + j * kCell, lo.z() + k * kCell); };
  std::vector<float> value(static_cast<std::size_t>(nx) * ny * nz, 1.0f);
  // Primitive by primitive, over the grid points inside its bounds, in the same order and with
  // the same bounds test as sample(), so grid and point evaluation agree.
  for (const Primitive& s : prims) {
    const int i0 = std::max(0, static_cast<int>(std::floor((s.lo.x() - lo.x()) / kCell)));
    const int j0 = std::max(0, static_cast<int>(std::floor((s.lo.y() - lo.y()) / kCell)));
    const int k0 = std::max(0, static_cast<int>(std::floor((s.lo.z() - lo.z()) / kCell)));
    const int i1 = std::min(nx - 1, static_cast<int>(std::ceil((s.hi.x() - lo.x()) / kCell)));
    const int j1 = std::min(ny - 1, static_cast<int>(std::ceil((s.hi.y() - lo.y()) / kCell)));
    const int k1 = std::min(nz - 1, static_cast<int>(std::ceil((s.hi.z() - lo.z()) / kCell)));
    for (int k = k0; k <= k1; ++k)
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
          const Vec3 p = point(i, j, k);
          if (!inside(s, p)) continue;
          float& v = value[at(i, j, k)];
          v = smooth_min(v, distance(s, p), s.blend);
        }
  }
  // Remove checkerboard faces (two inside corners diagonal, two outside): turning the outside
  // corner nearest the surface inside joins the two sheets, after which every dual edge
  // borders exactly two quads. Only outside -> inside changes, so the loop ends.
  for (bool changed = true; changed;) {
    changed = false;
    for (int axis = 0; axis < 3; ++axis) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      const int n[3] = {nx, ny, nz};
      for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
          for (int i = 0; i < nx; ++i) {
            int c[3] = {i, j, k};
            if (c[u] + 1 >= n[u] || c[w] + 1 >= n[w]) continue;
            auto corner = [&](int du, int dw) -> float& {
              int q[3] = {c[0], c[1], c[2]};
              q[u] += du, q[w] += dw;
              return value[at(q[0], q[1], q[2])];
            };
            float& v00 = corner(0, 0);
            float& v11 = corner(1, 1);
            float& v10 = corner(1, 0);
            float& v01 = corner(0, 1);
            const bool a = v00 < 0, b = v11 < 0, e = v10 < 0, f = v01 < 0;
            if (a != b || e != f || a == e) continue;
            float& fix = a ? (v10 < v01 ? v10 : v01) : (v00 < v11 ? v00 : v11);
            fix = -1e-6f;
            changed = true;
          }
    }
  }

  // One vertex per cell the surface crosses: the mean of its edges' crossings.
  SkinnedMesh mesh;
  mesh.name = "marine";
  std::vector<std::int32_t> cell_vertex(static_cast<std::size_t>(nx) * ny * nz, -1);
  static constexpr int kEdges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                        {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  for (int k = 0; k + 1 < nz; ++k)
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i) {
        float v[8];
        int inside_count = 0;
        for (int c = 0; c < 8; ++c) {
          v[c] = value[at(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))];
          inside_count += v[c] < 0;
        }
        if (inside_count == 0 || inside_count == 8) continue;
        Vec3 sum = Vec3::Zero();
        int crossings = 0;
        for (const auto& e : kEdges) {
          if ((v[e[0]] < 0) == (v[e[1]] < 0)) continue;
          const float t = v[e[0]] / (v[e[0]] - v[e[1]]);
          const Vec3 p0((e[0] & 1), ((e[0] >> 1) & 1), ((e[0] >> 2) & 1));
          const Vec3 p1((e[1] & 1), ((e[1] >> 1) & 1), ((e[1] >> 2) & 1));
          sum += p0 + t * (p1 - p0);
          ++crossings;
        }
        cell_vertex[at(i, j, k)] = static_cast<std::int32_t>(mesh.positions.size());
        mesh.positions.push_back(point(i, j, k) + kCell * sum / static_cast<float>(crossings));
      }
  // One quad per grid edge the surface crosses, around the edge, wound so its normal points
  // from the inside end to the outside end; split along its shorter diagonal.
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, w = (axis + 2) % 3;
    for (int k = 1; k + 1 < nz; ++k)
      for (int j = 1; j + 1 < ny; ++j)
        for (int i = 1; i + 1 < nx; ++i) {
          int c[3] = {i, j, k};
          int d[3] = {i, j, k};
          d[axis] += 1;
          const bool in0 = value[at(c[0], c[1], c[2])] < 0, in1 = value[at(d[0], d[1], d[2])] < 0;
          if (in0 == in1) continue;
          auto cell = [&](int du, int dw) {
            int q[3] = {c[0], c[1], c[2]};
            q[u] -= du, q[w] -= dw;
            return static_cast<std::uint32_t>(cell_vertex[at(q[0], q[1], q[2])]);
          };
          std::uint32_t q[4] = {cell(0, 0), cell(1, 0), cell(1, 1), cell(0, 1)};
          if (!in0) std::swap(q[1], q[3]);
          const float d02 = (mesh.positions[q[0]] - mesh.positions[q[2]]).squaredNorm();
          const float d13 = (mesh.positions[q[1]] - mesh.positions[q[3]]).squaredNorm();
          if (d02 <= d13) {
            mesh.indices.insert(mesh.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
          } else {
            mesh.indices.insert(mesh.indices.end(), {q[1], q[2], q[3], q[1], q[3], q[0]});
          }
        }
  }

  // Onto the surface: a few Newton steps along the gradient, each at most half a cell.
  mesh.normals.resize(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    Vec3& p = mesh.positions[v];
    for (int it = 0; it < 4; ++it) {
      const float d = field(prims, p);
      const Vec3 g = gradient(prims, p);
      const float g2 = g.squaredNorm();
      if (g2 < 1e-6f) break;
      Vec3 step = g * (d / g2);
      const float len = step.norm();
      if (len > 0.5f * kCell) step *= 0.5f * kCell / len;
      p -= step;
    }
    const Vec3 g = gradient(prims, p);
    mesh.normals[v] = g.squaredNorm() > 1e-12f ? Vec3(g.normalized()) : Vec3::UnitY();
  }

  // Colour and skin weights from the dominant primitive and its region.
  const Vec3 eyes[2] = {Vec3(0.031f, 1.681f, 0.104f), Vec3(-0.031f, 1.681f, 0.104f)};
  mesh.colors.resize(mesh.positions.size());
  mesh.bones.resize(mesh.positions.size());
  mesh.weights.resize(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const Vec3& p = mesh.positions[v];
    const Sample s = sample(prims, p);
    const Primitive& dom = prims[static_cast<std::size_t>(std::max(s.dominant, 0))];
    Srgb8 col = kCamoKhaki;
    switch (dom.material) {
      case Material::kSkin:
        col = kSkinTone;
        for (const Vec3& e : eyes)
          if ((p - e).norm() < 0.014f) col = kEye;
        break;
      case Material::kUniform: col = marpat_woodland(p); break;
      case Material::kBoot: col = kBootTan; break;
      case Material::kGear: col = kGearCoyote; break;
      case Material::kHelmet: col = marpat_woodland(p, 17U); break;
    }
    mesh.colors[v] = col;

    // Region affinities: 1 for the dominant region, fading to 0 for a region whose nearest
    // primitive is kRegionBlend farther; a limb never takes weight from another limb.
    const int home = dom.region;
    std::array<float, kJoints> w{};
    for (int r = 0; r < kRegions; ++r) {
      if (r != home && is_limb(home) && is_limb(r)) continue;
      const float gap = s.region_d[r] - s.region_d[home];
      const float affinity = r == home ? 1.0f : 1.0f - smoothstep(0.0f, kRegionBlend, gap);
      if (affinity > 0.0f) add_chain_weights(chains[r], p, affinity, w);
    }
    // The four largest, largest first (ties: lower joint first), renormalised.
    std::array<int, kJoints> order;
    for (int j = 0; j < kJoints; ++j) order[j] = j;
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return w[a] > w[b]; });
    float total = 0.0f;
    for (int k = 0; k < kMaxInfluences; ++k) total += w[order[k]];
    for (int k = 0; k < kMaxInfluences; ++k) {
      const float wk = w[order[k]] / total;
      mesh.bones[v][k] = wk > 0.0f ? static_cast<std::uint16_t>(order[k]) : 0;
      mesh.weights[v][k] = wk;
    }
  }

  // Mesh bone k is joint k; bind rotations are identity, so the inverse bind is a translation.
  const auto bind = bind_positions();
  for (int j = 0; j < kJoints; ++j) {
    mesh.bone_joint.push_back(static_cast<std::uint16_t>(j));
    mesh.inverse_bind.push_back(Affine3(Eigen::Translation3f(-bind[j])));
  }
  return mesh;
}

}  // namespace ballpit::marine
