#include "server/render/passes/glass_composite_pass.hpp"

namespace downpour::render {

GlassCompositePass::GlassCompositePass(SharedResources&)
    : program_("glass.vert", "glass_composite.frag"),
      quad_(program_),
      u_inv_viewport_(program_.uniform("u_inv_viewport")),
      blade_program_("glass_blades.vert", "glass_blades.frag"),
      blades_(blade_program_),
      blade_placement_(blade_program_),
      u_blur_mm_(blade_program_.uniform("u_blur_mm")),
      u_margin_mm_(blade_program_.uniform("u_margin_mm")) {
  empty_vao_ = make_vertex_array();
}

bool GlassCompositePass::wanted(const FrameContext& frame) const {
  return glass_has_water_or_blades(frame.water());
}

void GlassCompositePass::execute(const FrameContext& frame, const FrameResources& resources) {
  program_.use();
  u_inv_viewport_.set(1.0f / glm::vec2(resources.view_colour.width, resources.view_colour.height));
  quad_.draw(frame);
  draw_blades(frame);
}

void GlassCompositePass::draw_blades(const FrameContext& frame) {
  // The blades on top, over their own footprints only.
  const float blur_mm = static_cast<float>(frame.glass.blur_mm());
  blade_program_.use();
  blade_placement_.set(frame);
  u_blur_mm_.set(blur_mm);
  u_margin_mm_.set(2.0f * blur_mm + 4.0f);
  blades_.set(frame.water().blades);
  glBindVertexArray(empty_vao_.id());
  glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, 2);
}

}  // namespace downpour::render
