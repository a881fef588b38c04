#include "server/render/passes/glass_quad.hpp"

#include <algorithm>

#include "server/sim/glass_water_surface.hpp"

namespace downpour::render {

GlassPlacement::GlassPlacement(const ShaderProgram& program)
    : origin_(program.uniform("u_glass_origin")),
      u_(program.uniform("u_glass_u")),
      v_(program.uniform("u_glass_v")),
      size_mm_(program.uniform("u_glass_mm")) {}

void GlassPlacement::set(const FrameContext& frame) const {
  const sim::GlassConfig& glass = frame.scene.glass;
  const glm::mat3 rotation(frame.vehicle_to_world);
  origin_.set(glm::vec3(frame.vehicle_to_world * glm::vec4(glm::vec3(glass.bottom_left_m), 1.0f)));
  u_.set(rotation * glm::vec3(glass.u_axis()));
  v_.set(rotation * glm::vec3(glass.v_axis()));
  size_mm_.set(glm::vec3(glass.bottom_width_mm, glass.top_width_mm, glass.height_mm));
}

GlassSurfaceGrid::GlassSurfaceGrid(const ShaderProgram& program)
    : cells_(program.uniform("u_cells")) {
  program.uniform("u_cell_mm").set(static_cast<float>(sim::GlassWaterSurface::kCellMm));
  program.uniform("u_count_bits").set(static_cast<unsigned>(sim::GlassWaterSurface::kCountBits));
}

void GlassSurfaceGrid::set(const sim::WindshieldState& water) const {
  const sim::GlassWaterSurface* surface = water.surface.get();
  cells_.set(surface ? glm::ivec2(surface->cells_u, surface->cells_v) : glm::ivec2(0));
}

GlassQuad::GlassQuad(const ShaderProgram& program) : placement_(program) {
  empty_vao_ = make_vertex_array();
}

void GlassQuad::draw(const FrameContext& frame) const {
  placement_.set(frame);
  glBindVertexArray(empty_vao_.id());
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
}

bool glass_has_water_or_blades(const sim::WindshieldState& water) {
  const bool any_blade =
      std::any_of(water.blades.begin(), water.blades.end(),
                  [](const sim::BladePose& b) { return b.length_mm > 0.0f && b.width_mm > 0.0f; });
  return any_blade || water.glass_wet_fraction > 0.0 || !water.metaballs.empty() ||
         (water.surface && !water.surface->bodies.empty());
}

}  // namespace downpour::render
