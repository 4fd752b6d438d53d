#include "app/renderer.h"

#include <chrono>

#include "app/frame_uniforms.h"

namespace ballpit {

Renderer::Renderer() {
  glNamedBufferStorage(frame_uniforms_.id(), sizeof(FrameUniforms), nullptr, GL_DYNAMIC_STORAGE_BIT);
}

void Renderer::render(const Session& session, const OrbitCamera& camera, const Viewport& viewport,
                      const RenderSettings& settings) {
  gpu_timer_.begin();
  const World& world = session.world();
  const float fill = session.fill_height();
  const float wall = drawn_wall_height(world.pit, fill);

  FrameUniforms f;
  f.view = camera.view();
  f.projection = camera.projection(viewport.aspect());
  f.view_inverse = f.view.inverse();
  const Vec3 eye = camera.eye();
  const Vec3 sun = Vec3(0.45f, 0.8f, 0.35f).normalized();
  f.eye = Vec4(eye.x(), eye.y(), eye.z(), 1.0f);
  f.sun = Vec4(sun.x(), sun.y(), sun.z(), 0.0f);
  f.pit = Vec4(world.pit.half_width, wall, fill, 0.0f);
  f.viewport = Vec4(static_cast<float>(viewport.width), static_cast<float>(viewport.height), 0.0f, 0.0f);
  glNamedBufferSubData(frame_uniforms_.id(), 0, sizeof f, &f);
  glBindBufferBase(GL_UNIFORM_BUFFER, 0, frame_uniforms_.id());

  glClearColor(settings.clear_color.x(), settings.clear_color.y(), settings.clear_color.z(), 1.0f);
  glClearDepth(1.0);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glDisable(GL_SCISSOR_TEST);
  glFrontFace(GL_CCW);
  glCullFace(GL_BACK);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

  if (settings.draw_pit) pit_.draw_opaque(world.pit, wall);
  if (settings.draw_spheres) {
    SphereRenderState state = session.sphere_render_state();
    const auto t0 = std::chrono::steady_clock::now();
    spheres_.upload(state);
    upload_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    spheres_.draw(settings.sphere_mode, state.alpha);
  }
  if (settings.show_colliders) colliders_.draw(session);
  if (settings.draw_character) character_.draw(session, settings.show_colliders);
  if (settings.draw_pit) pit_.draw_glass();
  gpu_timer_.end();
}

}  // namespace ballpit
