// The clear sky's colour by the sun's place on the GPU (Resource-free: bound to its own unit,
// texture_unit::kSky, for every shader's sky_gradient): the scattered sky (cpu/sky_scattering.hpp)
// scaled to the frame's exposure, stored as its difference from the frame block's zenith-to-
// horizon gradient, times the clear share of the sky (1 - overcast). Under full cloud it is 0 and
// the gradient alone shows.
#pragma once

#include <map>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "server/render/cpu/atmosphere.hpp"
#include "server/render/gl/gl_objects.hpp"

namespace downpour::render {

class SkyTable {
 public:
  SkyTable();  // bound to its unit
  // The table for this frame's air (the scattering computed once per quarter degree of the sun's
  // altitude, some 3 ms, and kept), made and uploaded where the air changed.
  void show(const Atmosphere& atmosphere);

 private:
  // What the table shown was made from.
  struct Shown {
    int quarter_degrees = 0;
    float overcast = 0.0f;
    glm::vec3 clear_zenith{0.0f}, clear_horizon{0.0f};
    bool operator==(const Shown&) const = default;
  };
  const std::vector<glm::vec3>& scattered(int quarter_degrees);
  Texture texture_;
  std::map<int, std::vector<glm::vec3>> cache_;
  std::vector<float> texels_;
  std::optional<Shown> shown_;
};

}  // namespace downpour::render
