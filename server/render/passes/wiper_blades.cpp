#include "server/render/passes/wiper_blades.hpp"

#include <algorithm>
#include <cmath>

namespace downpour::render {

static_assert(kWiperBlades == 2, "the constructor names each blade's uniforms");

WiperBladeUniforms::WiperBladeUniforms(const ShaderProgram& program)
    : pivot_dir_{program.uniform("u_blade_pivot_dir[0]"), program.uniform("u_blade_pivot_dir[1]")},
      size_{program.uniform("u_blade_size[0]"), program.uniform("u_blade_size[1]")} {}

void WiperBladeUniforms::set(const std::array<sim::BladePose, kWiperBlades>& blades) const {
  for (int i = 0; i < kWiperBlades; ++i) {
    const sim::BladePose& b = blades[i];
    pivot_dir_[i].set(glm::vec4(b.pivot_mm, std::cos(b.angle_rad), std::sin(b.angle_rad)));
    size_[i].set(glm::vec2(std::max(b.length_mm, 0.0f), std::max(b.width_mm, 0.0f)));
  }
}

}  // namespace downpour::render
