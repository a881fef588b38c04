#include "server/render/wiper_blades.hpp"

#include <algorithm>
#include <cmath>

namespace downpour::render {

void set_wiper_blade_uniforms(ShaderProgram& program, const std::array<sim::BladePose, 2>& blades) {
  static constexpr const char* kPivotDir[] = {"u_blade_pivot_dir[0]", "u_blade_pivot_dir[1]"};
  static constexpr const char* kSize[] = {"u_blade_size[0]", "u_blade_size[1]"};
  for (int i = 0; i < 2; ++i) {
    const sim::BladePose& b = blades[i];
    program.set(kPivotDir[i], glm::vec4(b.pivot_mm, std::cos(b.angle_rad), std::sin(b.angle_rad)));
    program.set(kSize[i], glm::vec2(std::max(b.length_mm, 0.0f), std::max(b.width_mm, 0.0f)));
  }
}

}  // namespace downpour::render
