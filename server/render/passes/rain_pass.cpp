#include "server/render/passes/rain_pass.hpp"

#include <chrono>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "server/render/shader_interface.hpp"
#include "server/sim/car_body.hpp"
#include "server/sim/pose.hpp"

namespace downpour::render {

RainPass::RainPass(SharedResources& shared)
    : shared_(shared),
      program_("fullscreen.vert", "rain.frag"),
      u_near_(program_.uniform("u_near")) {}

bool RainPass::wanted(const FrameContext& frame) const {
  // The inputs say whether it rains; only then wait for the step's drops.
  return frame.scene.weather.rain_rate_mm_h > 0.0 && !frame.rain().drops.empty();
}

void RainPass::execute(const FrameContext& frame, const FrameResources&) {
  const sim::RainState& rain = frame.rain();
  const int width = (frame.spec.width + kLayerDivisor - 1) / kLayerDivisor;
  const int height = (frame.spec.height + kLayerDivisor - 1) / kLayerDivisor;
  RainLayerInputs in;
  in.view = frame.camera.view;
  in.tan_half_fov_x = frame.camera.tan_half_fov_x;
  in.tan_half_fov_y = frame.camera.tan_half_fov_y;
  in.camera_velocity = frame.scene.vehicle.velocity_mps;
  in.vehicle_to_world = sim::vehicle_to_world(frame.scene.vehicle);
  // The cars in the rain hide what falls behind them: each as its hull and its cabin, the shape
  // VehiclePass draws (scaled to a traffic car's size); the ego car too, seen from outside.
  namespace body = sim::car_body;
  occluders_.clear();  // kept from frame to frame: no allocation once it has grown
  auto add_car = [&](const glm::dmat4& to_world) {
    occluders_.push_back({to_world, glm::vec3(-0.95f, -0.9f, 0.28f),
                          glm::vec3(3.65f, 0.9f, static_cast<float>(body::kHullTopZ))});
    occluders_.push_back(
        {to_world,
         glm::vec3(static_cast<float>(body::kCabinRearX),
                   -static_cast<float>(body::kCabinHalfWidth), static_cast<float>(body::kHullTopZ)),
         glm::vec3(static_cast<float>(body::kCabinFrontX),
                   static_cast<float>(body::kCabinHalfWidth), static_cast<float>(body::kRoofZ))});
  };
  for (const sim::TrafficVehicle& other : frame.scene.traffic) {
    const glm::dvec3 scale(other.size_m.x / 4.6, other.size_m.y / 1.8, other.size_m.z / 1.47);
    add_car(glm::scale(sim::vehicle_to_world(other.state), scale));
  }
  if (frame.spec.view == sim::View::kRoad) add_car(in.vehicle_to_world);
  in.occluders = occluders_;
  in.dt_s = frame.scene.sim_time_s - rain.time_s;
  in.exposure_s = frame.spec.exposure_s.value_or(in.exposure_s);  // else the layer's default
  // A drop refracts a wide cone of what is around it: it carries the sky's and the scene's light
  // (not white paint), dimmed a little, and the haze between it and the camera.
  const Atmosphere& atm = frame.atmosphere;
  in.light = glm::mix(atm.sky_horizon, atm.ambient, 0.4f) * 0.95f + atm.sun_radiance * 0.05f;
  in.haze = atm.fog_colour;
  in.haze_per_m = atm.fog_density;
  in.pixels_per_texel = static_cast<float>(frame.spec.height) / static_cast<float>(height);
  const auto t0 = std::chrono::steady_clock::now();
  drawn_.streaks = layer_.build(rain, in, width, height);
  drawn_.layer_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  if (width != texture_width_ || height != texture_height_) {
    for (int i = 0; i < kTexturePairs; ++i) {
      colour_[i] = make_texture_2d(GL_RGBA8, width, height);
      depth_[i] = make_texture_2d(GL_R32F, width, height);
      glTextureParameteri(colour_[i].id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTextureParameteri(colour_[i].id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTextureParameteri(colour_[i].id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTextureParameteri(colour_[i].id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      glTextureParameteri(depth_[i].id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTextureParameteri(depth_[i].id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    texture_width_ = width;
    texture_height_ = height;
  }
  const int pair = next_pair_;
  next_pair_ = (next_pair_ + 1) % kTexturePairs;
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(colour_[pair].id(), 0, 0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE,
                      layer_.colour().data());
  glTextureSubImage2D(depth_[pair].id(), 0, 0, 0, width, height, GL_RED, GL_FLOAT,
                      layer_.depth().data());
  glBindTextureUnit(texture_unit::kRainLayer, colour_[pair].id());
  glBindTextureUnit(texture_unit::kRainDepth, depth_[pair].id());
  const RainLayer::Bounds& b = layer_.bounds();
  if (b.empty()) return;
  program_.use();
  u_near_.set(frame.camera.near_m);
  // Only where the layer has rain: the composite's fragments are most of its cost on llvmpipe.
  glEnable(GL_SCISSOR_TEST);
  glScissor(b.x0 * kLayerDivisor - 1, b.y0 * kLayerDivisor - 1, (b.x1 - b.x0) * kLayerDivisor + 2,
            (b.y1 - b.y0) * kLayerDivisor + 2);
  shared_.fullscreen.draw();
  glDisable(GL_SCISSOR_TEST);
}

void RainMaskPass::execute(const FrameContext&, const FrameResources& resources) {
  const float black[4] = {0.0f, 0.0f, 0.0f, 1.0f};
  glClearNamedFramebufferfv(resources.view_fbo, GL_COLOR, 0, black);
}

}  // namespace downpour::render
