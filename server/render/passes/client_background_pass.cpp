#include "server/render/passes/client_background_pass.hpp"

#include "server/render/cpu/client_background.hpp"
#include "server/render/cpu/glass_view.hpp"

namespace downpour::render {
void ClientBackgroundPass::execute(const FrameContext&, const FrameResources& r) {
  const TargetTexture& picture = r.client_colour;
  // (Before the first picture a 1 x 1 black one: the view's clear colour stays.)
  if (picture.width != r.view_colour.width || picture.height != r.view_colour.height) return;
  glCopyImageSubData(picture.texture, GL_TEXTURE_2D, 0, 0, 0, 0, r.view_colour.texture,
                     GL_TEXTURE_2D, 0, 0, 0, 0, picture.width, picture.height, 1);
  if (r.client_depth.texture) {
    glCopyImageSubData(r.client_depth.texture, GL_TEXTURE_2D, 0, 0, 0, 0, r.view_depth.texture,
                       GL_TEXTURE_2D, 0, 0, 0, 0, picture.width, picture.height, 1);
  }
}

ClientHazePass::ClientHazePass(SharedResources& shared)
    : shared_(shared),
      program_("fullscreen_ray.vert", "client_haze.frag"),
      u_forward_(program_.uniform("u_forward")),
      u_ground_(program_.uniform("u_ground")),
      u_has_depth_(program_.uniform("u_has_depth")),
      u_near_(program_.uniform("u_near")) {}

bool ClientHazePass::wanted(const FrameContext& frame) const {
  return frame.spec.haze && frame.atmosphere.fog_density > 0.0f;
}

void ClientHazePass::execute(const FrameContext& frame, const FrameResources& r) {
  if (r.client_colour.width != r.view_colour.width ||
      r.client_colour.height != r.view_colour.height)
    return;  // no picture yet
  const Camera& camera = frame.picture_camera_or_own();
  const GroundPlane g = ground_plane(camera, frame.scene.vehicle);
  program_.use();
  u_forward_.set(picture_camera(camera).forward);
  u_ground_.set(glm::vec4(g.normal, g.camera_height_m));
  u_has_depth_.set(r.client_depth.texture ? 1 : 0);
  u_near_.set(camera.near_m);
  shared_.fullscreen.draw();
}

ClientEnvironmentPass::ClientEnvironmentPass(SharedResources& shared)
    : shared_(shared),
      program_("fullscreen_ray.vert", "client_environment.frag"),
      u_forward_(program_.uniform("u_forward")),
      u_right_(program_.uniform("u_right")),
      u_up_(program_.uniform("u_up")),
      u_tan_(program_.uniform("u_tan")),
      u_ground_(program_.uniform("u_ground")),
      u_has_depth_(program_.uniform("u_has_depth")),
      u_glass_depth_(program_.uniform("u_glass_depth")),
      u_near_(program_.uniform("u_near")) {}

void ClientEnvironmentPass::execute(const FrameContext& frame, const FrameResources& r) {
  // The picture's camera: the view's, not the face's that this draws from.
  const Camera& view_camera = frame.picture_camera_or_own();
  const PictureCamera c = picture_camera(view_camera);
  const GroundPlane g = ground_plane(view_camera, frame.scene.vehicle);
  program_.use();
  u_forward_.set(c.forward);
  u_right_.set(c.right);
  u_up_.set(c.up);
  u_tan_.set(glm::vec2(c.tan_x, c.tan_y));
  u_glass_depth_.set(GlassView(view_camera, frame.scene.glass, 1).depth_over_image());
  u_near_.set(view_camera.near_m);
  u_ground_.set(glm::vec4(g.normal, g.camera_height_m));
  u_has_depth_.set(r.client_depth.texture ? 1 : 0);
  shared_.fullscreen.draw();
}

}  // namespace downpour::render
