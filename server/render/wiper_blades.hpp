// The wiper blades as windshield_common.glsl draws them, from the simulation's blade poses.
#pragma once

#include <array>

#include "server/render/gl_objects.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::render {

// Sets u_blade_pivot_dir[i] (pivot mm, unit direction) and u_blade_size[i] (length, width mm) of a
// program that includes windshield_common.glsl. A blade of zero length is not drawn.
void set_wiper_blade_uniforms(ShaderProgram& program, const std::array<sim::BladePose, 2>& blades);

}  // namespace downpour::render
