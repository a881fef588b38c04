#include "server/render/frame_lamps.hpp"

#include "server/render/lamp_map.hpp"
#include "server/render/world.hpp"

namespace downpour::render {

FrameLamps::FrameLamps() {
  ubo_ = make_buffer();
  glNamedBufferStorage(ubo_.id(), sizeof(LampBlock), nullptr, GL_DYNAMIC_STORAGE_BIT);
  glBindBufferBase(GL_UNIFORM_BUFFER, kLampBlockBinding, ubo_.id());
}

void FrameLamps::prepare(FrameContext& f, bool on, bool map) {
  lights_.clear();
  // By day the lamps' light is lost in the sun's (a low beam's 1,000 lux 4 m ahead shows as
  // 0.014 of white at noon): none is drawn until the exposure makes it count. Their lit lenses
  // still show (vehicle.frag).
  constexpr float kLampsFromExposure = 2e-4f;
  if (on && f.atmosphere.lux_exposure >= kLampsFromExposure)
    lights_ = build_lights(f.scene, f.world->street_lights, f.camera.position);
  f.lights = &lights_;
  const glm::mat4& view = f.camera.view;
  const glm::vec3 forward(-view[0][2], -view[1][2], -view[2][2]);
  packed_ = pack_lamps(lights_, f.camera.position, forward, block_);
  const std::size_t bytes = sizeof(glm::vec4) * (1 + 4 * static_cast<std::size_t>(packed_.count));
  glNamedBufferSubData(ubo_.id(), 0, static_cast<GLsizeiptr>(bytes), &block_);
  fields_.rings = place_lamp_rings(f.camera.position, forward).windows;
  const bool drawn = map && packed_.count > 0;
  fields_.params =
      glm::vec4(drawn ? static_cast<float>(LampRings::kRings) : 0.0f, f.atmosphere.lux_exposure,
                static_cast<float>(packed_.ego), static_cast<float>(packed_.count));
}

}  // namespace downpour::render
