#include "server/render/passes/spray_mirror_pass.hpp"

#include <algorithm>

#include "server/render/cpu/shader_interface.hpp"
#include "server/render/passes/spray_pass.hpp"

namespace downpour::render {

SprayMirrorPass::SprayMirrorPass(SharedResources&)
    : program_("spray_mirror.vert", "spray_mirror.frag"),
      u_light_(program_.uniform("u_light")),
      u_near_(program_.uniform("u_near")) {
  vao_ = make_vertex_array();
}

bool SprayMirrorPass::wanted(const FrameContext& frame) const {
  // The clean frame (ground truth) is taken after the road, which shows the mirror: where a client
  // asks for it, the mirror holds no spray.
  return on_ && frame.scene.spray && !frame.scene.spray->points.empty() &&
         !frame.spec.outputs.needs_clean();
}

void SprayMirrorPass::execute(const FrameContext& frame, const FrameResources& resources) {
  if (!wanted(frame)) return;
  const TargetTexture& mirror = resources.transient(Resource::kRoadReflection).colour;
  const int width = std::max(1, mirror.width / 2), height = std::max(1, mirror.height / 2);
  if (width != width_ || height != height_) {
    haze_ = make_texture_2d(GL_RG32F, width, height);
    glTextureParameteri(haze_.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(haze_.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(haze_.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(haze_.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    width_ = width;
    height_ = height;
  }
  // The clouds in the mirrored camera's view space, culled to its view (as SprayPass::cull).
  const sim::SprayImage& image = *frame.scene.spray;
  const Camera& camera = frame.camera;
  const auto tan_x = static_cast<float>(camera.tan_half_fov_x);
  const auto tan_y = static_cast<float>(camera.tan_half_fov_y);
  const float px_per_tan = 0.5f * static_cast<float>(height) / tan_y;
  const glm::mat3 rotation(camera.view);
  const glm::vec3 origin(camera.view * glm::vec4(glm::vec3(image.origin_m), 1.0f));
  clouds_.clear();
  for (const sim::SprayImage::Point& p : image.points) {
    const glm::vec3 v = origin + rotation * glm::vec3(p.x, p.y, p.z);
    const float z = -v.z;
    if (z <= camera.near_m + 0.05f) continue;
    const float pixel_m = z / px_per_tan;
    SprayHazeBall cloud;
    if (!spray_cloud(p, v, pixel_m, cloud)) continue;
    const float reach = cloud.ball.radius / pixel_m + 1.0f;
    const glm::vec2 centre((v.x / z / tan_x * 0.5f + 0.5f) * width,
                           (v.y / z / tan_y * 0.5f + 0.5f) * height);
    if (centre.x < -reach || centre.y < -reach || centre.x > width + reach ||
        centre.y > height + reach)
      continue;
    clouds_.push_back(cloud);
  }
  if (clouds_.empty()) return;
  splat_haze({width, height, {tan_x, tan_y}}, clouds_, pixels_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(haze_.id(), 0, 0, 0, width, height, GL_RG, GL_FLOAT, pixels_.data());
  glBindTextureUnit(texture_unit::kSprayMirrorHaze, haze_.id());
  program_.use();
  u_light_.set(spray_haze_light(frame.atmosphere));
  u_near_.set(camera.near_m);
  glBindVertexArray(vao_.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

}  // namespace downpour::render
