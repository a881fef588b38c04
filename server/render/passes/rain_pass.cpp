#include "server/render/passes/rain_pass.hpp"

#include <algorithm>
#include <chrono>
#include <tuple>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "server/model/default_models.hpp"
#include "server/render/cpu/cabin_tiles.hpp"
#include "server/render/cpu/client_background.hpp"
#include "server/render/cpu/light_set.hpp"
#include "server/render/cpu/shader_interface.hpp"
#include "server/sim/car_body.hpp"
#include "server/sim/pose.hpp"

namespace downpour::render {

RainPass::RainPass(SharedResources& shared)
    : shared_(shared),
      program_("rain.vert", "rain.frag"),
      u_plane_depth_(program_.uniform("u_plane_depth")) {
  vao_ = make_vertex_array();
}

bool RainPass::wanted(const FrameContext& frame) const {
  // The inputs say whether it rains; only then wait for the step's drops.
  return frame.scene.weather.rain_rate_mm_h > 0.0 && !frame.rain().drops.empty();
}

bool is_driver_view(sim::View view) {
  return view == sim::View::kCockpit || view == sim::View::kRain;
}

namespace {

std::span<const RainLamp> rain_lamps(const FrameContext& frame, std::vector<RainLamp>& out) {
  out.clear();
  if (!frame.lights) return out;
  // The ego car's headlights, then the lamps that give the camera's surroundings the most light.
  std::vector<std::tuple<bool, float, const Light*>> order;  // (not the ego's, -light, lamp)
  for (const Light& l : *frame.lights) {
    if (l.kind != LampKind::kHeadlight && l.kind != LampKind::kStreet) continue;
    const glm::vec3 to = l.position - frame.camera.position;
    order.emplace_back(l.vehicle >= 0, -l.intensity_cd.g / std::max(glm::dot(to, to), 1.0f), &l);
  }
  std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) {
    return std::tie(std::get<0>(a), std::get<1>(a)) < std::tie(std::get<0>(b), std::get<1>(b));
  });
  const glm::mat3 rotate(frame.camera.view);
  // A drop sends this share of the light on it towards the camera, times its phase function
  // (rain_layer.cpp: 0.06 sideways to 2 straight on).
  constexpr float kScatter = 1.0f;
  for (const auto& [other, light, l] : order) {
    if (out.size() >= RainLayerInputs::kMaxLamps) break;
    RainLamp r;
    r.position = glm::vec3(frame.camera.view * glm::vec4(l->position, 1.0f));
    r.axis = rotate * l->direction;
    const glm::vec2 side(-l->direction.y, l->direction.x);
    const float len = glm::length(side);
    r.left = rotate * (len > 1e-4f ? glm::vec3(side / len, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f));
    r.intensity = l->intensity_cd.g * frame.atmosphere.lux_exposure * kScatter;
    r.cos_outer = l->cos_outer;
    r.cos_inner = l->cos_inner;
    r.low_beam = l->low_beam;
    out.push_back(r);
  }
  return out;
}

}  // namespace

RainLayerInputs rain_layer_inputs(const FrameContext& frame, int layer_height,
                                  std::vector<RainOccluder>& occluders,
                                  std::vector<RainLamp>& lamps) {
  RainLayerInputs in;
  in.view = frame.camera.view;
  in.tan_half_fov_x = frame.camera.tan_half_fov_x;
  in.tan_half_fov_y = frame.camera.tan_half_fov_y;
  in.camera_velocity = frame.scene.vehicle.velocity_mps;
  in.vehicle_to_world = sim::vehicle_to_world(frame.scene.vehicle);
  // The cars in the rain hide what falls behind them: each as its hull and its cabin, the shape
  // VehiclePass draws (scaled to a traffic car's size).
  namespace body = sim::car_body;
  occluders.clear();  // kept from frame to frame: no allocation once it has grown
  const float hull_top = static_cast<float>(body::kHullTopZ);
  auto add_car = [&](const glm::dmat4& to_world) {
    occluders.push_back(
        {to_world, glm::vec3(-0.95f, -0.9f, 0.28f), glm::vec3(3.65f, 0.9f, hull_top)});
    occluders.push_back(
        {to_world,
         glm::vec3(static_cast<float>(body::kCabinRearX),
                   -static_cast<float>(body::kCabinHalfWidth), hull_top),
         glm::vec3(static_cast<float>(body::kCabinFrontX),
                   static_cast<float>(body::kCabinHalfWidth), static_cast<float>(body::kRoofZ))});
  };
  for (const sim::TrafficVehicle& other : frame.scene.traffic) {
    const glm::dvec3 scale(other.size_m.x / 4.6, other.size_m.y / 1.8, other.size_m.z / 1.47);
    add_car(glm::scale(sim::vehicle_to_world(other.state), scale));
  }
  // The driver sees the rain over the road ahead, not over the bonnet: its box from the glass's
  // foot forward. Seen from outside, the whole ego car.
  const bool picture = frame.spec.background == sim::Background::kClient;
  if (is_driver_view(frame.spec.view)) {
    // Over a client's picture, the picture says where the bonnet is.
    if (!picture)
      occluders.push_back({in.vehicle_to_world,
                           glm::vec3(static_cast<float>(body::kCabinFrontX), -0.9f, 0.28f),
                           glm::vec3(3.65f, 0.9f, hull_top)});
  } else {
    add_car(in.vehicle_to_world);
  }
  in.occluders = occluders;
  in.dt_s = frame.scene.sim_time_s - frame.rain().time_s;
  in.exposure_s = frame.spec.exposure_s.value_or(in.exposure_s);  // else the layer's default
  // A drop refracts a wide cone of what is around it: it carries the sky's and the scene's light
  // (not white paint), dimmed a little, and the haze between it and the camera.
  const Atmosphere& atm = frame.atmosphere;
  in.light = glm::mix(atm.sky_horizon, atm.ambient, 0.4f) * 0.95f + atm.sun_radiance * 0.05f;
  in.haze = atm.fog_colour;
  in.lamps = rain_lamps(frame, lamps);
  in.up = glm::mat3(frame.camera.view) * glm::vec3(0.0f, 0.0f, 1.0f);
  in.haze_per_m = atm.fog_density;
  in.pixels_per_texel = static_cast<float>(frame.spec.height) / static_cast<float>(layer_height);
  return in;
}

RainPass::Lane* RainPass::lane_of(const FrameContext& frame) const {
  for (const auto& lane : lanes_) {
    if (lane->frame == &frame) return lane.get();
  }
  return nullptr;
}

void RainPass::start(const FrameContext& frame) {
  finish_build(frame);
  if (!wanted(frame)) return;
  // A free lane, or a new one, up to a lane for each of a session's views; past that (views
  // begun and never ended) the one least recently started, its build dropped (its frame's rain
  // pass builds again).
  const int width = (frame.spec.width + kLayerDivisor - 1) / kLayerDivisor;
  const int height = (frame.spec.height + kLayerDivisor - 1) / kLayerDivisor;
  Lane* free = nullptr;  // one whose layer has the size first: another size clears all of it
  for (const auto& l : lanes_) {
    if (!l->frame && (!free || (l->layer.width() == width && l->layer.height() == height)))
      free = l.get();
  }
  if (!free && lanes_.size() < kMaxLanes)
    free = lanes_.emplace_back(std::make_unique<Lane>()).get();
  if (!free) {
    free = std::min_element(lanes_.begin(), lanes_.end(), [](const auto& a, const auto& b) {
             return a->started < b->started;
           })->get();
    finish_build(*free->frame);
  }
  Lane& lane = *free;
  lane.started = ++starts_;
  const sim::RainState& rain = frame.rain();
  RainLayerInputs in = rain_layer_inputs(frame, height, lane.occluders, lane.lamps);
  if (frame.spec.background == sim::Background::kClient) {
    // Hidden by what the picture shows nearer; no cabin of ours. A picture's own depth is taken
    // once a picture (its serial); the ground's moves with the car, every frame.
    const sim::ClientImage* image =
        frame.scene.client_images[static_cast<std::size_t>(frame.spec.view)].get();
    const std::uint64_t serial = image && !image->depth_m.empty() ? image->serial : 0;
    if (serial == 0 || serial != lane.scene_depth_serial ||
        lane.scene_depth_cm.size() != static_cast<std::size_t>(width) * height) {
      picture_layer_depth_cm(image, picture_camera(frame.camera),
                             ground_plane(frame.camera, frame.scene.vehicle), width, height, 0xffff,
                             lane.scene_depth_cm);
      lane.scene_depth_serial = serial;
    }
    in.scene_depth_cm = lane.scene_depth_cm;
  } else if (is_driver_view(frame.spec.view)) {
    const std::vector<std::uint8_t>& tiles = cabin_tiles_for(frame, width, height);
    lane.cabin_tiles.assign(tiles.begin(), tiles.end());
    in.cabin_tiles = lane.cabin_tiles;
  }
  lane.rain = &rain;
  lane.in = in;
  lane.built.store(false, std::memory_order_relaxed);
  lane.failure = nullptr;
  lane.builder.start([&lane, width, height] {
    try {
      const auto t0 = std::chrono::steady_clock::now();
      lane.streaks = lane.layer.build(*lane.rain, lane.in, width, height);
      lane.ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    } catch (...) {
      lane.failure = std::current_exception();  // (an allocation), for execute() to throw
    }
    lane.built.store(true, std::memory_order_release);
  });
  lane.frame = &frame;  // once started (a start that throws leaves the lane free)
}

bool RainPass::built(const FrameContext& frame) const {
  const Lane* lane = lane_of(frame);
  return !lane || lane->built.load(std::memory_order_acquire);
}

void RainPass::finish_build(const FrameContext& frame) {
  Lane* lane = lane_of(frame);
  if (!lane) return;
  lane->builder.wait();
  lane->frame = nullptr;
}

void RainPass::execute(const FrameContext& frame, const FrameResources&) {
  Lane* lane = lane_of(frame);
  if (!lane) {  // not built ahead (a view alone, or a pass run alone, as the tests do)
    start(frame);
    lane = lane_of(frame);
    if (!lane) return;  // no rain after all
  }
  // The passes drawn so far go to llvmpipe's rasterizer threads now, rather than wait in its bins
  // while the layer is finished: the cores share the two.
  glFlush();
  lane->builder.wait();
  lane->frame = nullptr;
  if (lane->failure) std::rethrow_exception(std::exchange(lane->failure, nullptr));
  drawn_.streaks = lane->streaks;
  drawn_.layer_ms = lane->ms;
  RainLayer& layer = lane->layer;
  const int width = layer.width(), height = layer.height();
  Sized& sized = this->sized(width, height);

  const Texture& texture = sized.colour[sized.next];
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(texture.id(), 0, 0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE,
                      layer.colour().data());
  glBindTextureUnit(texture_unit::kRainLayer, texture.id());
  const std::vector<RainLayer::Bounds>& runs = layer.runs();
  const Buffer& buffer = sized.runs_buffer[sized.next];
  sized.next = (sized.next + 1) % kLayerCopies;
  if (runs.empty()) return;
  // Only the tiles with rain: on llvmpipe the composite's cost is the area it covers, lit or not.
  runs_uv_.clear();
  const glm::vec2 texel(1.0f / width, 1.0f / height);
  for (const RainLayer::Bounds& r : runs)
    runs_uv_.emplace_back(r.x0 * texel.x, r.y0 * texel.y, r.x1 * texel.x, r.y1 * texel.y);
  glNamedBufferSubData(buffer.id(), 0, static_cast<GLsizeiptr>(runs_uv_.size() * sizeof(glm::vec4)),
                       runs_uv_.data());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, storage_buffer::kRunsBuffer, buffer.id());
  program_.use();
  glBindVertexArray(vao_.id());
  // The tiles clear of the cabin (all of them but in the driver's views), then those the cabin
  // reaches into (decl_'s steps).
  const auto clear = static_cast<GLsizei>(layer.clear_runs());
  apply_step(kClearTiles);
  if (clear > 0) glDrawArrays(GL_TRIANGLES, 0, 6 * clear);
  const auto edge = static_cast<GLsizei>(runs_uv_.size()) - clear;
  if (edge == 0) return;
  u_plane_depth_.set(frame.glass.depth_over_image());
  apply_step(kCabinTiles);
  glDrawArrays(GL_TRIANGLES, 6 * clear, 6 * edge);
}

RainPass::Sized& RainPass::sized(int width, int height) {
  const auto found = std::find_if(sized_.begin(), sized_.end(), [&](const auto& s) {
    return s->width == width && s->height == height;
  });
  if (found != sized_.end()) {
    std::rotate(found, found + 1, sized_.end());  // the most recently used, last
    return *sized_.back();
  }
  if (sized_.size() >= kSizesKept) sized_.erase(sized_.begin());
  auto s = std::make_unique<Sized>();
  s->width = width;
  s->height = height;
  for (Texture& texture : s->colour) {
    texture = make_texture_2d(GL_RGBA8, width, height);
    glTextureParameteri(texture.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(texture.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  }
  // Room for a run per tile, the most there can be (each covers a tile at least).
  const GLsizeiptr capacity = static_cast<GLsizeiptr>(sizeof(glm::vec4)) *
                              ((width + RainLayer::kTile - 1) / RainLayer::kTile) *
                              ((height + RainLayer::kTile - 1) / RainLayer::kTile);
  for (Buffer& buffer : s->runs_buffer) {
    buffer = make_buffer();
    glNamedBufferStorage(buffer.id(), capacity, nullptr, GL_DYNAMIC_STORAGE_BIT);
  }
  sized_.push_back(std::move(s));
  return *sized_.back();
}

const std::vector<std::uint8_t>& RainPass::cabin_tiles_for(const FrameContext& frame, int width,
                                                           int height) {
  const Camera& c = frame.camera;
  const sim::GlassConfig& g = frame.scene.glass;
  const sim::ModelPtr& cabin = frame.scene.ego.cabin_model;
  for (const CabinTiles& t : cabin_tiles_) {
    if (t.width == width && t.height == height && t.eye == c.position_vehicle &&
        t.axes == c.axes_vehicle && t.tan_x == c.tan_half_fov_x && t.tan_y == c.tan_half_fov_y &&
        t.cabin == cabin && (cabin || model::same_cabin(t.glass, g)))
      return t.hidden;
  }
  // Every driver's camera of the sessions at once, as a rule (a view's camera is fixed for its
  // session); past that the oldest goes. Rasterizing takes 0.6 ms for a 640x360 view, 20 ms at
  // 3840x2160, once per camera; an entry is a byte per tile (32 KB at 3840x2160).
  constexpr std::size_t kKept = 64;
  if (cabin_tiles_.size() >= kKept) cabin_tiles_.erase(cabin_tiles_.begin());
  cabin_tiles_.push_back({width, height, c.position_vehicle, c.axes_vehicle, c.tan_half_fov_x,
                          c.tan_half_fov_y, g, cabin,
                          cabin_tiles(cabin ? cabin->mesh : model::default_cabin(g).mesh, c, width,
                                      height, RainLayer::kTile)});
  return cabin_tiles_.back().hidden;
}

void RainMaskPass::execute(const FrameContext&, const FrameResources& resources) {
  const float black[4] = {0.0f, 0.0f, 0.0f, 1.0f};
  glClearNamedFramebufferfv(resources.view_fbo, GL_COLOR, 0, black);
}

}  // namespace downpour::render
