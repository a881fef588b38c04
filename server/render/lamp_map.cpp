#include "server/render/lamp_map.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "server/render/cpu/shader_interface.hpp"

namespace downpour::render {

LampRings place_lamp_rings(const glm::vec3& camera, const glm::vec3& forward) {
  LampRings r;
  glm::vec2 ahead(forward.x, forward.y);
  const float len = glm::length(ahead);
  ahead = len > 1e-3f ? ahead / len : glm::vec2(0.0f);
  for (int l = 0; l < LampRings::kRings; ++l) {
    const float cell = LampRings::kCellM[l];
    const float side = cell * LampRings::kCells;
    const glm::vec2 centre = glm::vec2(camera) + ahead * side * (0.5f - LampRings::kCameraAt);
    const glm::vec2 corner = glm::floor((centre - 0.5f * side) / cell) * cell;
    r.windows[l] = glm::vec4(corner, 1.0f / side, cell);
  }
  return r;
}

LampMap::LampMap()
    : program_("lamp_map.vert", "lamp_map.frag"),
      u_ring_(program_.uniform("u_ring")),
      u_boxes_(program_.uniform("u_boxes")),
      texture_(make_texture_2d_array(GL_RGBA16F, LampRings::kCells, LampRings::kCells,
                                     LampRings::kRings)) {
  vao_ = make_vertex_array();
  glTextureParameteri(texture_.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(texture_.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  for (int l = 0; l < LampRings::kRings; ++l) {
    GLuint fb = 0;
    glCreateFramebuffers(1, &fb);
    fbo_[l] = Framebuffer(fb);
    glNamedFramebufferTextureLayer(fb, GL_COLOR_ATTACHMENT0, texture_.id(), 0, l);
    if (glCheckNamedFramebufferStatus(fb, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("lamp map framebuffer incomplete");
  }
  // Dark until first drawn (a view that reads it unweighted reads 0, never what the memory held).
  const float black[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  glClearTexImage(texture_.id(), 0, GL_RGBA, GL_FLOAT, black);
}

void LampMap::draw(const std::vector<glm::vec4>& ground_boxes) {
  // Unbound while it is drawn into: a texture both read and written is undefined.
  glBindTextureUnit(texture_unit::kLampMap, 0);
  program_.use();
  const auto count = static_cast<GLsizei>(std::min<std::size_t>(ground_boxes.size(), kMaxLamps));
  if (count > 0) u_boxes_.set(ground_boxes.data(), count);
  glViewport(0, 0, LampRings::kCells, LampRings::kCells);
  glBindVertexArray(vao_.id());
  const float black[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  for (int l = 0; l < LampRings::kRings; ++l) {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_[l].id());
    glClearNamedFramebufferfv(fbo_[l].id(), GL_COLOR, 0, black);
    u_ring_.set(l);
    if (count > 0) glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, count);
  }
  glBindTextureUnit(texture_unit::kLampMap, texture_.id());
}

}  // namespace downpour::render
