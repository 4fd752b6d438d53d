// What the app draws, checked on images rendered offscreen: the default scene shows the pit,
// coloured balls in it and the character where it stands; impostors and meshes agree on
// coverage and depth; a walking character moves on screen; drawing never changes the
// simulation; a broken shader is an error carrying the driver's log.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>

#include "app/camera.h"
#include "app/controls.h"
#include "app/icosphere.h"
#include "app/render_target.h"
#include "app/renderer.h"
#include "app/session.h"
#include "app/shader.h"
#include "engine/state_hash.h"
#include "gl_fixture.h"

using namespace ballpit;

namespace {

constexpr Viewport kView{480, 270};

SessionOptions scene(const char* name, std::size_t spheres) {
  SessionOptions o;
  o.scene = name;
  o.spheres = spheres;
  o.threads = 2;
  return o;
}

Image draw(Renderer& renderer, RenderTarget& target, const Session& s, const OrbitCamera& camera,
           const RenderSettings& settings) {
  target.bind();
  renderer.render(s, camera, target.viewport(), settings);
  renderer.end_frame();
  return target.read();
}

bool differs(const Image& a, const Image& b, int x, int y) {
  const std::uint8_t* p = a.pixel(x, y);
  const std::uint8_t* q = b.pixel(x, y);
  return std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]) > 12;
}

// Hue (degrees) and saturation of an sRGB pixel.
std::pair<float, float> hue_saturation(const std::uint8_t* p) {
  const float r = p[0] / 255.0f, g = p[1] / 255.0f, b = p[2] / 255.0f;
  const float hi = std::max({r, g, b}), lo = std::min({r, g, b}), c = hi - lo;
  if (c <= 0.0f) return {0.0f, 0.0f};
  float h = hi == r ? std::fmod((g - b) / c, 6.0f) : hi == g ? (b - r) / c + 2.0f : (r - g) / c + 4.0f;
  h *= 60.0f;
  if (h < 0.0f) h += 360.0f;
  return {h, c / hi};
}

// The pour palette (engine/pour_scene.cpp): red, yellow, blue, green, orange, purple.
constexpr std::array<float, 6> kPaletteHue = {0.0f, 47.0f, 215.0f, 120.0f, 32.0f, 283.0f};
int palette_entry(const std::uint8_t* p) {
  auto [h, s] = hue_saturation(p);
  if (s < 0.4f || std::max({p[0], p[1], p[2]}) < 40) return -1;
  int best = -1;
  float best_d = 9.0f;  // degrees: shading keeps hue; 9 separates orange (32) from yellow (47)
  for (int i = 0; i < 6; ++i) {
    float d = std::abs(h - kPaletteHue[static_cast<std::size_t>(i)]);
    d = std::min(d, 360.0f - d);
    if (d < best_d) best_d = d, best = i;
  }
  return best;
}

// Is pixel (x, y) inside the convex quad q (in order around it)?
bool inside(const std::array<Vec2, 4>& q, float x, float y) {
  float sign = 0.0f;
  for (int i = 0; i < 4; ++i) {
    const Vec2& a = q[static_cast<std::size_t>(i)];
    const Vec2& b = q[static_cast<std::size_t>((i + 1) % 4)];
    float c = (b.x() - a.x()) * (y - a.y()) - (b.y() - a.y()) * (x - a.x());
    if (c * sign < 0.0f) return false;
    if (c != 0.0f) sign = c;
  }
  return true;
}

struct Mask {
  std::size_t count = 0;
  Vec2 centroid = Vec2::Zero();
  Vec2 min = Vec2::Constant(1e9f), max = Vec2::Constant(-1e9f);
};

Mask difference(const Image& a, const Image& b) {
  Mask m;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      if (differs(a, b, x, y)) {
        ++m.count;
        m.centroid += Vec2(x, y);
        m.min = m.min.cwiseMin(Vec2(x, y));
        m.max = m.max.cwiseMax(Vec2(x, y));
      }
  if (m.count) m.centroid /= static_cast<float>(m.count);
  return m;
}

class Render : public test::GlTest {};

}  // namespace

TEST_F(Render, TheDefaultSceneShowsColouredBallsInThePitAndTheCharacterWhereItStands) {
  Session s(scene("play", 12000));
  for (int i = 0; i < 90; ++i) s.single_step();  // the pour's top layers have landed by 1.5 s
  Renderer renderer;
  RenderTarget target(kView.width, kView.height);
  OrbitCamera camera;
  camera.frame_pit(s.world().pit.half_width, s.fill_height());
  RenderSettings all;
  const Image full = draw(renderer, target, s, camera, all);
  keep(full, "default_scene");

  // Not blank: many distinct colours.
  std::vector<std::uint32_t> colours;
  for (std::size_t i = 0; i < full.rgba.size(); i += 4)
    colours.push_back(full.rgba[i] | full.rgba[i + 1] << 8 | full.rgba[i + 2] << 16);
  std::sort(colours.begin(), colours.end());
  EXPECT_GT(std::unique(colours.begin(), colours.end()) - colours.begin(), 1000);

  // Ball colours where the pit is: the pit's floor outline, projected, and its outline at the
  // height the balls fill it to (the pile's top shows beyond the floor's outline).
  const float h = s.world().pit.half_width, fill = s.fill_height();
  std::array<Vec2, 4> pit, pit_top;
  const Vec3 corners[4] = {{-h, 0, -h}, {h, 0, -h}, {h, 0, h}, {-h, 0, h}};
  for (int i = 0; i < 4; ++i) {
    pit[static_cast<std::size_t>(i)] = camera.project(corners[i], kView).pixel;
    pit_top[static_cast<std::size_t>(i)] = camera.project(corners[i] + Vec3(0.0f, fill, 0.0f), kView).pixel;
  }
  RenderSettings no_balls = all;
  no_balls.draw_spheres = false;
  const Image empty = draw(renderer, target, s, camera, no_balls);
  keep(empty, "default_scene_without_balls");
  std::size_t pit_pixels = 0, ball_pixels = 0, outside_changed = 0;
  std::array<std::size_t, 6> hues{};
  for (int y = 0; y < kView.height; ++y)
    for (int x = 0; x < kView.width; ++x) {
      const bool in_pit = inside(pit, x + 0.5f, y + 0.5f);
      const bool over_pit = in_pit || inside(pit_top, x + 0.5f, y + 0.5f);
      const bool ball = differs(full, empty, x, y);
      if (in_pit) {
        ++pit_pixels;
        if (ball) {
          ++ball_pixels;
          int e = palette_entry(full.pixel(x, y));
          if (e >= 0) ++hues[static_cast<std::size_t>(e)];
        }
      } else if (ball && !over_pit) {
        ++outside_changed;
      }
    }
  ASSERT_GT(pit_pixels, 5000u);
  // Three or four layers of balls hide most of the floor; the character hides some of them.
  EXPECT_GT(ball_pixels, pit_pixels / 2);
  // Balls stay in the pit: only the top layer's balls poke over its projected outline, at
  // most a ball's height beyond it.
  EXPECT_LT(outside_changed, pit_pixels / 20);
  // Every palette colour shows, in roughly its share (a sixth; shading and the character's
  // hidden balls skew it): at least a twentieth of the ball pixels each.
  for (std::size_t i = 0; i < 6; ++i) EXPECT_GT(hues[i], ball_pixels / 20) << "palette colour " << i;

  // The character where it stands: drawing it changes pixels around its projected body.
  RenderSettings no_character = all;
  no_character.draw_character = false;
  const Image without = draw(renderer, target, s, camera, no_character);
  const Mask body = difference(full, without);
  const float height = s.world().characters.setup(0).model->bind_height() * s.world().characters.setup(0).scale;
  const Vec3 root = s.character_position();
  const Vec2 feet = camera.project(root, kView).pixel;
  const Vec2 top = camera.project(root + Vec3(0, height, 0), kView).pixel;
  const Vec2 middle = camera.project(root + Vec3(0, 0.5f * height, 0), kView).pixel;
  const float height_px = (feet - top).norm();
  ASSERT_GT(height_px, 20.0f);  // big enough on screen to judge
  // A body about as tall as the model is on screen, most of it near the projected root. A
  // man's silhouette covers about a fifth of his height squared; the pit hides his legs.
  EXPECT_GT(body.count, static_cast<std::size_t>(0.08f * height_px * height_px));
  EXPECT_LT((body.centroid - middle).norm(), 0.5f * height_px) << "centroid " << body.centroid.transpose()
                                                               << " projected " << middle.transpose();
  EXPECT_TRUE(differs(full, without, static_cast<int>(middle.x()), static_cast<int>(middle.y())));

  // He is the marine in his camouflage: where he is drawn, many pixels are the uniform's olive
  // greens (hue 65-110 degrees, muted: saturation 0.15-0.65; the balls' green is saturated
  // 0.67+, the Wuson's brown is hue 30) and some its khaki and the gear's coyote (hue 30-60).
  std::size_t olive = 0, tan = 0, drawn = 0;
  for (int y = 0; y < kView.height; ++y)
    for (int x = 0; x < kView.width; ++x) {
      if (!differs(full, without, x, y)) continue;
      ++drawn;
      const auto [hue, saturation] = hue_saturation(full.pixel(x, y));
      if (hue >= 65.0f && hue <= 110.0f && saturation >= 0.15f && saturation <= 0.65f) ++olive;
      if (hue >= 30.0f && hue < 60.0f && saturation >= 0.15f && saturation <= 0.65f) ++tan;
    }
  std::printf("[ marine ] %zu pixels drawn: %zu olive, %zu khaki or coyote\n", drawn, olive, tan);
  EXPECT_GT(olive, drawn / 10);
  EXPECT_GT(tan, drawn / 20);
}

namespace {

struct Coverage {
  std::size_t impostor = 0, mesh = 0, only_one = 0, both = 0, depth_close = 0;
};

// Draws the session's balls alone as impostors and as meshes and compares the two depth
// buffers pixel by pixel; depth agreement is counted within `depth_tolerance` (unit: m).
Coverage compare_paths(const Session& s, const OrbitCamera& camera, float depth_tolerance, const char* name) {
  Renderer renderer;
  RenderTarget target(kView.width, kView.height);
  RenderSettings settings;
  settings.draw_pit = false;
  settings.draw_character = false;
  settings.sphere_mode = SphereMode::Impostor;
  test::GlTest::keep(draw(renderer, target, s, camera, settings), std::string(name) + "_impostor");
  const std::vector<float> di = target.read_depth();
  settings.sphere_mode = SphereMode::Mesh;
  test::GlTest::keep(draw(renderer, target, s, camera, settings), std::string(name) + "_mesh");
  const std::vector<float> dm = target.read_depth();
  const float n = camera.near_plane(), f = camera.far_plane();
  auto linear = [&](float d) { return 2.0f * n * f / (f + n - (2.0f * d - 1.0f) * (f - n)); };  // (unit: m)
  Coverage c;
  for (std::size_t i = 0; i < di.size(); ++i) {
    const bool ci = di[i] < 1.0f, cm = dm[i] < 1.0f;  // covered: not the cleared far plane
    c.impostor += ci;
    c.mesh += cm;
    c.only_one += ci != cm;
    if (ci && cm) {
      ++c.both;
      c.depth_close += std::abs(linear(di[i]) - linear(dm[i])) < depth_tolerance;
    }
  }
  std::printf("[ measured ] %s: impostor %zu px, mesh %zu px (ratio %.4f), %.2f%% covered by only one, "
              "%.2f%% of shared pixels agree in depth\n",
              name, c.impostor, c.mesh, static_cast<double>(c.mesh) / static_cast<double>(c.impostor),
              100.0 * static_cast<double>(c.only_one) / static_cast<double>(c.impostor),
              100.0 * static_cast<double>(c.depth_close) / static_cast<double>(c.both));
  return c;
}

// Stated agreement of the two paths' coverage. A single ball's mesh silhouette lies between
// circles of 0.977 r and 1.046 r (the nearest faces and the vertices of the volume-matched
// icosphere, checked below), so its area is within -4.5% / +9.4% of the disc's; volume
// matching centres that band on the disc, and over hundreds of balls at random orientations
// the difference averages to about 1%. 3% allows for pixel rounding of small balls while still
// failing a radius error of 2% (4% in area).
constexpr double kCoverageTolerance = 0.03;

}  // namespace

TEST_F(Render, ImpostorsAndMeshesCoverTheSamePixels) {
  // Balls laid out on the floor 3 r apart, seen from straight above: every ball a separate
  // disc about 7 pixels in radius, so coverage measures the silhouettes themselves.
  Session s(scene("pour", 600));
  std::span<Vec3> p = s.world().spheres.mut_position();
  constexpr int kColumns = 20, kRows = 12;
  constexpr float kSpacing = 3.0f * 0.04f;  // (unit: m)
  for (std::size_t i = 0; i < p.size(); ++i) {
    const int col = static_cast<int>(i) % kColumns, row = static_cast<int>(i) / kColumns;
    p[i] = row < kRows ? Vec3((col - 0.5f * (kColumns - 1)) * kSpacing, 0.04f, (row - 0.5f * (kRows - 1)) * kSpacing)
                       : Vec3(1000.0f, 0.0f, 0.0f);  // out of view
  }
  OrbitCamera camera;
  camera.pitch = OrbitCamera::kMaxPitch;
  camera.distance = 1.75f;
  const Coverage c = compare_paths(s, camera, 0.1f * 0.04f, "discs");
  ASSERT_GT(c.impostor, 20000u);
  EXPECT_NEAR(static_cast<double>(c.mesh) / static_cast<double>(c.impostor), 1.0, kCoverageTolerance);
  // Pixels covered by one path only are rim pixels: at most a 1-pixel ring of a 7-pixel disc,
  // about 30% of it, and only where the polygon's edge strays from the circle.
  EXPECT_LT(static_cast<double>(c.only_one) / static_cast<double>(c.impostor), 0.15);
  EXPECT_GT(static_cast<double>(c.depth_close) / static_cast<double>(c.both), 0.99);
}

TEST_F(Render, ImpostorsWriteTheDepthOfTheSphereSurface) {
  // A settled heap from the side: overlapping silhouettes are resolved by depth, so the two
  // paths agree only if the impostors write the ray-sphere hit's true depth.
  Session s(scene("pour", 3000));
  for (int i = 0; i < 60; ++i) s.single_step();
  OrbitCamera camera;
  camera.frame_pit(s.world().pit.half_width, s.fill_height());
  camera.distance *= 0.6f;
  // The mesh lies within 0.05 r of the sphere (vertices 4.6% outside, faces 2.3% inside), so
  // 0.1 r leaves room for a different ball winning an overlap across a seam.
  const Coverage c = compare_paths(s, camera, 0.1f * 0.04f, "heap");
  ASSERT_GT(c.impostor, 20000u);
  EXPECT_NEAR(static_cast<double>(c.mesh) / static_cast<double>(c.impostor), 1.0, kCoverageTolerance);
  EXPECT_GT(static_cast<double>(c.depth_close) / static_cast<double>(c.both), 0.95);
}

TEST_F(Render, TheIcosphereIsVolumeMatchedToTheSphere) {
  IcosphereMesh m = make_icosphere(1);
  EXPECT_EQ(m.indices.size(), 80u * 3u);
  double volume = 0.0, min_face = 1e9;
  for (std::size_t i = 0; i < m.indices.size(); i += 3) {
    const Vec3& a = m.positions[m.indices[i]];
    const Vec3& b = m.positions[m.indices[i + 1]];
    const Vec3& c = m.positions[m.indices[i + 2]];
    volume += a.dot(b.cross(c)) / 6.0;
    min_face = std::min<double>(min_face, (b - a).cross(c - a).normalized().dot(a));
  }
  EXPECT_NEAR(volume, 4.0 / 3.0 * M_PI, 1e-4);
  // The bounds the coverage tolerance above is derived from.
  EXPECT_LT(m.scale, 1.05f);
  EXPECT_GT(min_face, 0.95);
  std::printf("[ measured ] icosphere: vertices at %.4f r, nearest face at %.4f r\n", m.scale, min_face);
}

TEST_F(Render, AWalkingCharacterMovesOnScreenWithItsProjectedPosition) {
  Session s(scene("play", 3000));
  Renderer renderer;
  RenderTarget target(kView.width, kView.height);
  OrbitCamera camera;
  camera.frame_pit(s.world().pit.half_width, s.fill_height());
  camera.yaw = 1.4f;  // from the side, so walking forward moves across the screen
  RenderSettings with, without;
  without.draw_character = false;
  auto body = [&] {
    Mask m = difference(draw(renderer, target, s, camera, with), draw(renderer, target, s, camera, without));
    return m;
  };
  const Mask before = body();
  const Vec2 before_px = camera.project(s.character_position(), kView).pixel;
  for (int frame = 0; frame < 120; ++frame) {  // 2 s with the forward key held
    s.set_character_input(controller_input({.forward = true}));
    s.single_step();
  }
  const Mask after = body();
  keep(draw(renderer, target, s, camera, with), "walked");
  const Vec2 after_px = camera.project(s.character_position(), kView).pixel;
  const Vec2 projected = after_px - before_px;
  const Vec2 drawn = after.centroid - before.centroid;
  ASSERT_GT(projected.norm(), 5.0f);
  // The drawn body moves with the projected root: same direction, similar distance (the
  // walk cycle shifts the legs, so the centroid wanders by a few pixels).
  EXPECT_GT(drawn.normalized().dot(projected.normalized()), 0.9f);
  EXPECT_NEAR(drawn.norm(), projected.norm(), 0.35f * projected.norm() + 2.0f);
}

TEST_F(Render, InterpolationAtTheStartOfAStepDrawsThePreviousStepExactly) {
  // Falling balls, so consecutive steps differ on screen.
  Session s(scene("pour", 2000));
  for (int i = 0; i < 5; ++i) s.single_step();
  Renderer renderer;
  RenderTarget target(kView.width, kView.height);
  const OrbitCamera camera = default_camera(s);
  RenderSettings settings;
  const Image previous = draw(renderer, target, s, camera, settings);  // step 5, as it is
  // Exactly one step of real time: the loop steps once and is at the start of the next
  // interval (alpha 0), so the GPU blend must give step 5's positions, looked up by entity
  // after the grid re-sorted the rows.
  ASSERT_EQ(s.advance(s.world().step()), 1);
  ASSERT_EQ(s.alpha(), 0.0f);
  const Image blended = draw(renderer, target, s, camera, settings);
  s.paused = true;  // alpha 1: step 6 as it is
  const Image latest = draw(renderer, target, s, camera, settings);
  EXPECT_EQ(blended.rgba, previous.rgba);  // mix(p, c, 0) is p, bit for bit
  EXPECT_GT(difference(latest, previous).count, 100u);  // and step 6 does look different
}

TEST_F(Render, DrawingNeverChangesTheSimulation) {
  Session drawn(scene("play", 2000)), undrawn(scene("play", 2000));
  Renderer renderer;
  RenderTarget target(kView.width, kView.height);
  OrbitCamera camera;
  camera.frame_pit(drawn.world().pit.half_width, drawn.fill_height());
  RenderSettings settings;
  settings.show_colliders = true;
  for (int i = 0; i < 10; ++i) {
    drawn.single_step();
    undrawn.single_step();
    draw(renderer, target, drawn, camera, settings);
  }
  EXPECT_EQ(state_hash(drawn.world()), state_hash(undrawn.world()));
}

TEST_F(Render, AShaderThatDoesNotCompileIsAnErrorWithTheDriversLog) {
  try {
    Program p("broken", {{GL_VERTEX_SHADER, "void main() { gl_Position = vec4(undeclared, 1.0); }\n"}});
    FAIL() << "expected ShaderError";
  } catch (const ShaderError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("shader 'broken'"), std::string::npos) << what;
    EXPECT_NE(what.find("vertex stage failed to compile"), std::string::npos) << what;
    EXPECT_NE(what.find("undeclared"), std::string::npos) << what;  // the driver's log names it
    EXPECT_FALSE(e.log().empty());
    EXPECT_NE(what.find("   2  void main()"), std::string::npos) << what;  // numbered source
  }
  // And a program that compiles but does not link.
  EXPECT_THROW(Program("unlinked", {{GL_FRAGMENT_SHADER, "out vec4 c; void f(); void main() { f(); c = vec4(1); }\n"}}),
               ShaderError);
}
