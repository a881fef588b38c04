#include "server/render/cpu/light_set.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "server/render/cpu/shader_interface.hpp"
#include "server/sim/pose.hpp"
#include "server/sim/vehicle_class.hpp"

namespace downpour::render {
namespace {

const glm::vec3 kWhite{1.0f, 1.0f, 1.0f};
const glm::vec3 kHeadlightWhite{1.0f, 0.97f, 0.9f};
const glm::vec3 kRed{1.0f, 0.05f, 0.02f};
const glm::vec3 kAmber{1.0f, 0.55f, 0.0f};

float range_for(const glm::vec3& intensity_cd, float cutoff_lux) {
  const float peak = std::max({intensity_cd.r, intensity_cd.g, intensity_cd.b});
  return std::sqrt(peak / std::max(cutoff_lux, 1e-6f));
}

// One vehicle's lit lamps. to_world: its frame to the world; scale: its size against its
// class's shape; head, tail: its left headlamp and tail lamp on that shape (y = 0: one of each).
void add_vehicle(const glm::dmat4& to_world, const glm::vec3& scale, const glm::vec3& head_m,
                 const glm::vec3& tail_m, const sim::VehicleLights& lit, bool flash_on,
                 std::int32_t index, const LightSetConfig& c, std::vector<Light>& out) {
  const glm::mat4 m(to_world);
  const glm::vec3 forward = glm::normalize(glm::vec3(m[0])), up = glm::normalize(glm::vec3(m[2]));
  auto lamp = [&](glm::vec3 at, glm::vec3 dir, glm::vec3 cd, float inner_deg, float outer_deg,
                  LampKind kind) {
    Light l;
    l.position = glm::vec3(m * glm::vec4(at * scale, 1.0f));
    l.direction = glm::normalize(dir);
    l.intensity_cd = cd;
    l.cos_inner = std::cos(glm::radians(inner_deg));
    l.cos_outer = std::cos(glm::radians(outer_deg));
    l.range_m = range_for(cd, c.cutoff_lux);
    l.ground_z = (m * glm::vec4(at.x * scale.x, at.y * scale.y, 0.0f, 1.0f)).z;
    l.kind = kind;
    l.vehicle = index;
    out.push_back(l);
  };
  const bool heads =
      lit.headlights == sim::Headlights::kLow || lit.headlights == sim::Headlights::kHigh;
  // A vehicle with one lamp each way (y = 0: a motorbike) still has an indicator each side.
  const bool single = head_m.y == 0.0f;
  constexpr float kSingleIndicatorY = 0.14f;
  for (float side : {1.0f, -1.0f}) {
    const glm::vec3 head(head_m.x, head_m.y * side, head_m.z);
    const glm::vec3 tail(tail_m.x, tail_m.y * side, tail_m.z);
    const bool indicator = side > 0 ? lit.left_indicator : lit.right_indicator;
    if (indicator && flash_on) {
      const glm::vec3 aside =
          single ? glm::vec3(0.0f, kSingleIndicatorY * side, 0.0f) : glm::vec3(0.0f);
      lamp(tail + aside, -forward, kAmber * c.indicator_cd, 20.0f, c.rear_lamp_outer_deg,
           LampKind::kIndicator);
      lamp(head + aside, forward, kAmber * c.indicator_cd, 20.0f, c.rear_lamp_outer_deg,
           LampKind::kIndicator);
    }
    if (single && side < 0.0f) break;
    if (lit.headlights == sim::Headlights::kLow) {
      const float down = glm::radians(c.low_beam_down_deg);
      lamp(head, forward * std::cos(down) - up * std::sin(down), kHeadlightWhite * c.low_beam_cd,
           c.low_beam_inner_deg, c.low_beam_outer_deg, LampKind::kHeadlight);
      out.back().low_beam = true;
    } else if (lit.headlights == sim::Headlights::kHigh) {
      lamp(head, forward, kHeadlightWhite * c.high_beam_cd, c.high_beam_inner_deg,
           c.high_beam_outer_deg, LampKind::kHeadlight);
    }
    if (heads)
      lamp(tail, -forward, kRed * c.tail_cd, 20.0f, c.rear_lamp_outer_deg, LampKind::kTail);
    if (lit.brake) {
      lamp(tail, -forward, kRed * c.brake_cd, 20.0f, c.rear_lamp_outer_deg, LampKind::kBrake);
    }
    if (lit.reverse) {
      lamp(tail, -forward, kWhite * c.reverse_cd, 20.0f, c.rear_lamp_outer_deg, LampKind::kReverse);
    }
  }
}

}  // namespace

sim::VehicleLights shown_lights(const sim::VehicleLights& lights, const sim::Weather& weather) {
  return sim::resolve_lights(lights, weather, lights.brake);
}

std::vector<Light> build_lights(const sim::SceneState& scene,
                                const std::vector<sim::StreetLight>& street,
                                const glm::vec3& camera_m, const LightSetConfig& c) {
  std::vector<Light> out;
  const bool flash_on = sim::indicator_lit(scene.sim_time_s);
  // The ego car's lamps where its shape, at the session's size, has them.
  add_vehicle(sim::vehicle_to_world(scene.vehicle),
              glm::vec3(scene.ego.size_m / sim::EgoGeometry{}.size_m), c.headlamp_m, c.tail_lamp_m,
              shown_lights(scene.ego_lights, scene.weather), flash_on, -1, c, out);
  for (std::size_t i = 0; i < scene.traffic.size(); ++i) {
    const sim::TrafficVehicle& t = scene.traffic[i];
    const sim::VehicleLayout& layout = sim::vehicle_layout(t.vehicle_class);
    // A car's lamps as the ego car's (the config's); the other classes' from their layouts.
    const bool car = t.vehicle_class == sim::VehicleClass::kCar;
    const sim::VehicleLights lights =
        i < scene.traffic_lights.size() ? scene.traffic_lights[i] : sim::VehicleLights{};
    add_vehicle(sim::vehicle_to_world(t.state), glm::vec3(sim::layout_scale(t)),
                car ? c.headlamp_m : glm::vec3(layout.headlamp_m),
                car ? c.tail_lamp_m : glm::vec3(layout.tail_lamp_m),
                shown_lights(lights, scene.weather), flash_on, static_cast<std::int32_t>(i), c,
                out);
  }
  if (sim::street_lights_on(scene.weather)) {
    std::vector<std::pair<float, std::size_t>> near;
    for (std::size_t i = 0; i < street.size(); ++i) {
      const float d = glm::length(glm::vec3(street[i].lamp_m) - camera_m);
      if (d <= c.street_within_m) near.emplace_back(d, i);
    }
    std::sort(near.begin(), near.end());
    near.resize(std::min(near.size(), static_cast<std::size_t>(std::max(c.max_street, 0))));
    for (const auto& [d, i] : near) {
      Light l;
      l.position = glm::vec3(street[i].lamp_m);
      l.direction = {0.0f, 0.0f, -1.0f};
      l.intensity_cd = glm::vec3(1.0f, 0.93f, 0.8f) * c.street_cd;
      l.cos_inner = std::cos(glm::radians(c.street_inner_deg));
      l.cos_outer = std::cos(glm::radians(c.street_outer_deg));
      l.range_m = range_for(l.intensity_cd, c.cutoff_lux);
      l.ground_z =
          static_cast<float>(street[i].lamp_m.z - sim::LightsConfig{}.street_light_height_m);
      l.kind = LampKind::kStreet;
      out.push_back(l);
    }
  }
  return out;
}

float beam_towards(const Light& l, const glm::vec3& dir, float stray) {
  const float t = std::clamp(
      (glm::dot(dir, l.direction) - l.cos_outer) / std::max(l.cos_inner - l.cos_outer, 1e-4f), 0.0f,
      1.0f);
  float beam = t * t * (3.0f - 2.0f * t);
  if (l.low_beam) {
    glm::vec2 left(-l.direction.y, l.direction.x);
    const float len = glm::length(left);
    left = len > 1e-4f ? left / len : glm::vec2(1.0f, 0.0f);
    beam *= stray + (1.0f - stray) * dipped_cut(-glm::dot(glm::vec2(dir), left), dir.z);
  }
  return beam;
}

float ground_lux(const Light& l, const glm::vec2& xy) {
  const glm::vec3 to = glm::vec3(xy, l.ground_z) - l.position;
  const float d2 = std::max(glm::dot(to, to), 0.25f);
  const glm::vec3 dir = to / std::sqrt(d2);
  return l.intensity_cd.g * beam_towards(l, dir) * std::max(-dir.z, 0.0f) / d2;
}

glm::vec4 lamp_footprint(const Light& l, float cut_lux) {
  const float h = l.position.z - l.ground_z;
  glm::vec4 box(1.0f, 1.0f, -1.0f, -1.0f);
  if (h <= 0.0f || cut_lux <= 0.0f) return box;
  const float peak = std::max({l.intensity_cd.r, l.intensity_cd.g, l.intensity_cd.b});
  const float reach = std::cbrt(peak * h / cut_lux);
  constexpr int kAzimuths = 16, kSteps = 16;
  const glm::vec2 at(l.position);
  bool any = false;
  for (int a = 0; a < kAzimuths; ++a) {
    const float phi = 6.2831853f * static_cast<float>(a) / kAzimuths;
    const glm::vec2 dir(std::cos(phi), std::sin(phi));
    // The furthest sample along the azimuth that gets more than the cut, and one step beyond.
    float last = -1.0f;
    for (int k = 0; k <= kSteps; ++k) {
      const float r = reach * static_cast<float>(k) / kSteps;
      if (ground_lux(l, at + dir * r) > cut_lux) last = r;
    }
    if (last < 0.0f) continue;
    const glm::vec2 p = at + dir * std::min(last + reach / kSteps, reach);
    if (!any) box = glm::vec4(at, at);
    any = true;
    box = glm::vec4(glm::min(glm::vec2(box), p), glm::max(glm::vec2(box.z, box.w), p));
  }
  return box;
}

PackedLamps pack_lamps(const std::vector<Light>& lights, const glm::vec3& camera_m,
                       const glm::vec3& camera_forward, LampBlock& out) {
  std::vector<std::pair<float, const Light*>> order;
  int ego = 0;
  for (const Light& l : lights) {
    if (l.kind == LampKind::kTail) continue;
    const bool ego_head = l.vehicle < 0 && l.kind == LampKind::kHeadlight;
    if (ego_head) ++ego;
    // The ego car's headlights sort before everything (negative keys), in their own order.
    const glm::vec3 to = l.position - camera_m;
    const float behind = glm::dot(to, camera_forward) < 0.0f ? 1e6f : 0.0f;
    order.emplace_back(ego_head ? -1e9f + static_cast<float>(ego) : glm::length(to) + behind, &l);
  }
  std::stable_sort(order.begin(), order.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  PackedLamps packed;
  packed.count = static_cast<int>(std::min<std::size_t>(order.size(), kMaxLamps));
  packed.ego = std::min(ego, packed.count);
  packed.ground_boxes.resize(packed.count);
  for (int i = 0; i < packed.count; ++i) {
    const Light& l = *order[i].second;
    packed.ground_boxes[i] = lamp_footprint(l, kGroundCutLux);
    out.lamp[4 * i + 0] = glm::vec4(l.position, l.ground_z);
    out.lamp[4 * i + 1] = glm::vec4(l.direction, l.cos_outer);
    out.lamp[4 * i + 2] = glm::vec4(l.intensity_cd, l.cos_inner);
    glm::vec2 left(-l.direction.y, l.direction.x);
    const float len = glm::length(left);
    left = len > 1e-4f ? left / len : glm::vec2(1.0f, 0.0f);
    out.lamp[4 * i + 3] = glm::vec4(l.low_beam ? 1.0f : 0.0f, left, 0.0f);
  }
  out.count =
      glm::vec4(static_cast<float>(packed.ego), static_cast<float>(packed.count), 0.0f, 0.0f);
  return packed;
}

std::uint32_t LightTiles::max_per_tile() const {
  return count.empty() ? 0 : *std::max_element(count.begin(), count.end());
}

double LightTiles::mean_per_tile() const {
  if (count.empty()) return 0.0;
  double sum = 0.0;
  for (std::uint32_t n : count) sum += n;
  return sum / static_cast<double>(count.size());
}

LightTiles bin_lights(const std::vector<Light>& lights, const glm::mat4& view_proj, int width,
                      int height, int tile_px) {
  LightTiles t;
  t.tile_px = tile_px;
  t.tiles_x = (width + tile_px - 1) / tile_px;
  t.tiles_y = (height + tile_px - 1) / tile_px;
  const std::size_t tiles = static_cast<std::size_t>(t.tiles_x) * t.tiles_y;
  std::vector<std::vector<std::uint32_t>> per_tile(tiles);
  // The frustum's side planes from the matrix's rows (Gribb and Hartmann): a sphere wholly
  // outside one of them is dropped.
  const glm::vec4 row0(view_proj[0][0], view_proj[1][0], view_proj[2][0], view_proj[3][0]);
  const glm::vec4 row1(view_proj[0][1], view_proj[1][1], view_proj[2][1], view_proj[3][1]);
  const glm::vec4 row3(view_proj[0][3], view_proj[1][3], view_proj[2][3], view_proj[3][3]);
  const glm::vec4 planes[5] = {row3 + row0, row3 - row0, row3 + row1, row3 - row1, row3};
  for (std::uint32_t i = 0; i < lights.size(); ++i) {
    const Light& l = lights[i];
    bool outside = false;
    for (const glm::vec4& p : planes) {
      const float len = glm::length(glm::vec3(p));
      if ((glm::dot(glm::vec3(p), l.position) + p.w) / len < -l.range_m) outside = true;
    }
    if (outside) continue;
    float x0 = std::numeric_limits<float>::max(), y0 = x0, x1 = -x0, y1 = -x0;
    bool behind = false;
    for (int k = 0; k < 8 && !behind; ++k) {
      const glm::vec3 corner =
          l.position + l.range_m * glm::vec3(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1);
      const glm::vec4 c = view_proj * glm::vec4(corner, 1.0f);
      if (c.w <= 1e-4f) {
        behind = true;
        break;
      }
      x0 = std::min(x0, c.x / c.w);
      x1 = std::max(x1, c.x / c.w);
      y0 = std::min(y0, c.y / c.w);
      y1 = std::max(y1, c.y / c.w);
    }
    int tx0 = 0, tx1 = t.tiles_x - 1, ty0 = 0, ty1 = t.tiles_y - 1;
    if (!behind) {
      auto tile_of = [&](float ndc, int px, int n) {
        const float pixel = (ndc * 0.5f + 0.5f) * static_cast<float>(px);
        return std::clamp(static_cast<int>(std::floor(pixel / static_cast<float>(tile_px))), -1, n);
      };
      tx0 = std::max(tile_of(x0, width, t.tiles_x), 0);
      tx1 = std::min(tile_of(x1, width, t.tiles_x), t.tiles_x - 1);
      ty0 = std::max(tile_of(y0, height, t.tiles_y), 0);
      ty1 = std::min(tile_of(y1, height, t.tiles_y), t.tiles_y - 1);
    }
    for (int ty = ty0; ty <= ty1; ++ty) {
      for (int tx = tx0; tx <= tx1; ++tx)
        per_tile[static_cast<std::size_t>(ty) * t.tiles_x + tx].push_back(i);
    }
  }
  t.first.resize(tiles);
  t.count.resize(tiles);
  for (std::size_t k = 0; k < tiles; ++k) {
    t.first[k] = static_cast<std::uint32_t>(t.lights.size());
    t.count[k] = static_cast<std::uint32_t>(per_tile[k].size());
    t.lights.insert(t.lights.end(), per_tile[k].begin(), per_tile[k].end());
  }
  return t;
}

}  // namespace downpour::render
