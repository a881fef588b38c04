// The wiper blades as wiper_blades.glsl draws them, from the simulation's blade poses.
#pragma once

#include <array>

#include "server/render/cpu/shader_interface.hpp"
#include "server/render/gl/gl_objects.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::render {

// u_blade_pivot_dir[i] (pivot mm, unit direction) and u_blade_size[i] (length, width mm) of a
// program that includes wiper_blades.glsl, looked up once. A blade of zero length is not drawn.
class WiperBladeUniforms {
 public:
  explicit WiperBladeUniforms(const ShaderProgram& program);
  void set(const std::array<sim::BladePose, kWiperBlades>& blades) const;

 private:
  std::array<Uniform, kWiperBlades> pivot_dir_;
  std::array<Uniform, kWiperBlades> size_;
};

}  // namespace downpour::render
