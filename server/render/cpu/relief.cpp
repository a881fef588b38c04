#include "server/render/cpu/relief.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <numbers>
#include <thread>

#include "server/render/cpu/procedural_textures.hpp"

namespace downpour::render::relief {

float HeightField::sample(float x, float y) const {
  const float fx = std::floor(x), fy = std::floor(y);
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  const float tx = x - fx, ty = y - fy;
  const float a = at(ix, iy) + (at(ix + 1, iy) - at(ix, iy)) * tx;
  const float b = at(ix, iy + 1) + (at(ix + 1, iy + 1) - at(ix, iy + 1)) * tx;
  return a + (b - a) * ty;
}

HorizonMaps::Horizon HorizonMaps::at(int x, int y, float azimuth_rad) const {
  const float turns = azimuth_rad / (2.0f * std::numbers::pi_v<float>);
  const float f = (turns - std::floor(turns)) * static_cast<float>(directions);
  const int k0 = std::min(static_cast<int>(f), directions - 1);
  const int k1 = (k0 + 1) % directions;
  const float w = f - static_cast<float>(k0);
  const std::size_t i0 = index(k0, x, y), i1 = index(k1, x, y);
  return {tan_beta[i0] + (tan_beta[i1] - tan_beta[i0]) * w,
          distance_m[i0] + (distance_m[i1] - distance_m[i0]) * w};
}

float HorizonMaps::mean_lit(float elevation_rad) const {
  if (lit_by_degree.empty()) return 1.0f;
  const float deg = std::clamp(elevation_rad * 180.0f / std::numbers::pi_v<float>, 0.0f, 90.0f);
  const int i = std::min(static_cast<int>(deg), 89);
  return lit_by_degree[i] +
         (lit_by_degree[i + 1] - lit_by_degree[i]) * (deg - static_cast<float>(i));
}

namespace {

// Where along an azimuth the march samples (texels): every texel out to 8, then steps that grow
// with the distance (a far horizon point moves the slope less than a near one).
std::vector<float> march_distances(float dense_texels, float max_texels) {
  std::vector<float> out;
  float t = 1.0f, step = 1.0f;
  while (t <= max_texels) {
    out.push_back(t);
    if (t >= dense_texels * step) step *= 2.0f;
    t += step;
  }
  return out;
}

}  // namespace

HorizonMaps build_horizon_maps(const HeightField& field, const HorizonConfig& config, int threads) {
  HorizonMaps maps;
  const int stride = std::max(config.stride, 1);
  maps.size = field.size / stride;
  maps.directions = config.directions;
  maps.texel_m = field.texel_m * static_cast<float>(stride);
  const std::size_t layer = static_cast<std::size_t>(maps.size) * maps.size;
  maps.tan_beta.assign(layer * config.directions, 0.0f);
  maps.distance_m.assign(layer * config.directions, 0.0f);
  const std::vector<float> ts = march_distances(config.dense_texels, config.max_distance_texels);
  // A map texel's centre in the field's texels: (x + 1/2) stride - 1/2, so that both textures put
  // it at the same place. Its fraction, and every sample's offset from it along an azimuth, are
  // the same for all texels: the bilinear weights are worked out once an azimuth.
  const float centre = 0.5f * static_cast<float>(stride - 1);
  struct Tap {
    int ox, oy;
    float wx, wy;
    float inv_t;  // 1 / (distance in metres)
    float t_m;
  };
  auto tap = [&](float x, float y, float t) {
    const float fx = std::floor(x), fy = std::floor(y);
    return Tap{static_cast<int>(fx),
               static_cast<int>(fy),
               x - fx,
               y - fy,
               t > 0.0f ? 1.0f / (t * field.texel_m) : 0.0f,
               t * field.texel_m};
  };
  auto height = [&](const Tap& a, int px, int py) {
    const int x = px + a.ox, y = py + a.oy;
    const float h0 = field.at(x, y) + (field.at(x + 1, y) - field.at(x, y)) * a.wx;
    const float h1 = field.at(x, y + 1) + (field.at(x + 1, y + 1) - field.at(x, y + 1)) * a.wx;
    return h0 + (h1 - h0) * a.wy;
  };

  auto march = [&](int first, int step) {
    std::vector<Tap> taps;
    for (int k = first; k < config.directions; k += step) {
      const float phi =
          2.0f * std::numbers::pi_v<float> * static_cast<float>(k) / config.directions;
      const float dx = std::cos(phi), dy = std::sin(phi);
      const Tap here = tap(centre, centre, 0.0f);
      taps.clear();
      for (float t : ts) taps.push_back(tap(centre + t * dx, centre + t * dy, t));
      for (int y = 0; y < maps.size; ++y) {
        for (int x = 0; x < maps.size; ++x) {
          const int px = x * stride, py = y * stride;
          const float h0 = height(here, px, py);
          float best = -std::numeric_limits<float>::infinity();
          float best_m = taps.empty() ? 0.0f : taps.back().t_m;
          for (const Tap& a : taps) {
            const float slope = (height(a, px, py) - h0) * a.inv_t;
            if (slope > best) {
              best = slope;
              best_m = a.t_m;
            }
          }
          const std::size_t i = maps.index(k, x, y);
          maps.tan_beta[i] = std::isfinite(best) ? best : 0.0f;
          maps.distance_m[i] = best_m;
        }
      }
    }
  };
  const int n = std::clamp(threads, 1, config.directions);
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(march, t, n);
  march(0, n);
  for (std::thread& t : pool) t.join();
  // The sunlight kept at each whole degree, from every seventh texel each way (not a divisor of
  // the setts' pattern, which every eighth would alias with): the
  // facet's normal from its neighbours' heights, lit where the light clears the (flat) horizon.
  maps.lit_by_degree.assign(91, 1.0f);
  const int step = 7;
  struct Facet {
    float nx, ny, nz;
    std::size_t texel;  // index in a layer
  };
  std::vector<Facet> facets;
  for (int y = 0; y < maps.size; y += step) {
    for (int x = 0; x < maps.size; x += step) {
      const int px = x * stride, py = y * stride;
      const float gx = (field.at(px + 1, py) - field.at(px - 1, py)) / (2.0f * field.texel_m);
      const float gy = (field.at(px, py + 1) - field.at(px, py - 1)) / (2.0f * field.texel_m);
      const float inv = 1.0f / std::sqrt(1.0f + gx * gx + gy * gy);
      facets.push_back({-gx * inv, -gy * inv, inv, maps.index(0, x, y)});
    }
  }
  for (int deg = 1; deg <= 90; ++deg) {
    const float e = static_cast<float>(deg) * std::numbers::pi_v<float> / 180.0f;
    const float tan_e = std::tan(e);
    double lit = 0.0, all = 0.0;
    for (int k = 0; k < config.directions; ++k) {
      const float phi =
          2.0f * std::numbers::pi_v<float> * static_cast<float>(k) / config.directions;
      const float lx = std::cos(e) * std::cos(phi), ly = std::cos(e) * std::sin(phi);
      const float lz = std::sin(e);
      const float* tb = &maps.tan_beta[maps.index(k, 0, 0)];
      for (const Facet& f : facets) {
        const float ndl = std::max(f.nx * lx + f.ny * ly + f.nz * lz, 0.0f);
        all += ndl;
        lit += tan_e > flat_tan_horizon(tb[f.texel]) ? ndl : 0.0f;
      }
    }
    maps.lit_by_degree[static_cast<std::size_t>(deg)] =
        all > 0.0 ? static_cast<float>(lit / all) : 1.0f;
  }
  maps.lit_by_degree[0] = maps.lit_by_degree[1];
  return maps;
}

float corrected_tan_horizon(float tan_beta, float distance_m, float h_m, float k) {
  if (k <= 0.0f) return flat_tan_horizon(tan_beta);
  // Eq. 2: the horizon point d away has sunk by about k d^2 / 2 under the tangent plane, and the
  // texel h above the surface sits on a larger circle.
  const float on_relief = tan_beta * (1.0f - k * h_m) - 0.5f * k * distance_m;
  // Eq. 3: the surface itself, seen from h above it, falls away cos(beta') = 1 / (k h + 1) below
  // the tangent plane (the paper's point B taken at height 0).
  const float c = 1.0f / (k * h_m + 1.0f);
  const float on_surface = -std::sqrt(std::max(0.0f, 1.0f - c * c)) / c;
  return std::max(on_relief, on_surface);
}

std::uint8_t encode_tan_horizon(float tan_beta) {
  const float t = std::clamp(tan_beta, -4.0f, 4.0f);
  const float e = 0.5f + 0.5f * std::copysign(std::sqrt(std::abs(t) / 4.0f), t);
  return static_cast<std::uint8_t>(std::lround(e * 255.0f));
}

float decode_tan_horizon(std::uint8_t byte) {
  const float x = 2.0f * (static_cast<float>(byte) / 255.0f) - 1.0f;
  return 4.0f * x * std::abs(x);
}

std::uint8_t encode_horizon_distance(float distance_m) {
  const float e = std::sqrt(std::clamp(distance_m / kHorizonDistanceRangeM, 0.0f, 1.0f));
  return static_cast<std::uint8_t>(std::lround(e * 255.0f));
}

float decode_horizon_distance(std::uint8_t byte) {
  const float e = static_cast<float>(byte) / 255.0f;
  return e * e * kHorizonDistanceRangeM;
}

std::vector<std::uint8_t> packed_layer(const HorizonMaps& maps, int k) {
  const std::size_t texels = static_cast<std::size_t>(maps.size) * maps.size;
  std::vector<std::uint8_t> out(texels * 4);
  const std::size_t a = maps.index(k, 0, 0), b = maps.index((k + 1) % maps.directions, 0, 0);
  for (std::size_t i = 0; i < texels; ++i) {
    out[4 * i] = encode_tan_horizon(maps.tan_beta[a + i]);
    out[4 * i + 1] = encode_horizon_distance(maps.distance_m[a + i]);
    out[4 * i + 2] = encode_tan_horizon(maps.tan_beta[b + i]);
    out[4 * i + 3] = encode_horizon_distance(maps.distance_m[b + i]);
  }
  return out;
}

HeightField asphalt_heights(int size, std::uint32_t seed) {
  HeightField f{size, kAsphaltTileM / static_cast<float>(size), asphalt_height_unit(size, seed)};
  for (float& h : f.height_m) h *= kAsphaltDepthM;
  return f;
}

HeightField setts_heights(int size, std::uint32_t seed) {
  HeightField f{size, kSettsTileM / static_cast<float>(size), setts_height_unit(size, seed)};
  for (float& h : f.height_m) h *= kSettsDepthM;
  return f;
}

std::shared_ptr<const RoadReliefs> road_reliefs(int directions) {
  static std::mutex mutex;
  static std::map<int, std::shared_ptr<const RoadReliefs>> built;
  const std::lock_guard lock(mutex);
  auto& slot = built[directions];
  if (slot) return slot;
  const auto start = std::chrono::steady_clock::now();
  auto r = std::make_shared<RoadReliefs>();
  r->asphalt = asphalt_heights(512, 2);
  r->setts = setts_heights(256, 3);
  // Both maps 256 x 256 a layer: the asphalt's at every second texel (6 mm), out to 37 cm (a 9 mm
  // stone's shadow under a sun 1.4 degrees high), every texel out to 7 cm (its small stones); the
  // setts' at every texel (4 mm), out to 50 cm.
  r->asphalt_horizon = build_horizon_maps(r->asphalt, {directions, 2, 128.0f, 24.0f});
  r->setts_horizon = build_horizon_maps(r->setts, {directions, 1, 128.0f, 16.0f});
  r->build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  slot = std::move(r);
  return slot;
}

}  // namespace downpour::render::relief
