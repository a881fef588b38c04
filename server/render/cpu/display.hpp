// The scene's display transform, as the shaders apply it (common.glsl's to_display): a gentle
// shoulder, then gamma 2 (sqrt). For what the CPU draws into the frame, and the tests' references.
#pragma once

#include <cmath>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

namespace downpour::render {

inline glm::vec3 to_display(glm::vec3 c) {
  c = glm::clamp(c / (1.0f + 0.15f * c), 0.0f, 1.0f);
  return glm::vec3(std::sqrt(c.x), std::sqrt(c.y), std::sqrt(c.z));
}

}  // namespace downpour::render
