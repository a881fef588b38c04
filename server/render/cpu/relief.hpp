// Shadows of a surface's relief on curved surfaces (seed 002, horizon mapping with curvature).
//
// A relief is a repeating height field (the asphalt's stones, the shoulder's setts). For each of N
// azimuths it is marched once, at start-up: the horizon map holds tan(beta), the steepest slope
// from the texel to the relief along that azimuth, and the distance map d, how far away that
// horizon point lies. At shading time a texel is lit when the light's slope above the surface
// exceeds the horizon, interpolated between the two nearest azimuths.
//
// On a convex surface the relief's far side falls away: a horizon point d away sinks by about
// k d^2 / 2 (k the surface's curvature along the light, mesh_curvature.hpp), and a texel h above
// the surface sees past the surface's own rim. Eq. 2 and eq. 3 of the paper correct the horizon
// for the two cases; the larger one holds. No GL here: the renderer uploads the maps (one layer
// per azimuth) and the road shader evaluates the same formulas (road_surface.glsl).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

namespace downpour::render::relief {

// A square height field that repeats; heights in metres over the surface (0 at its lowest).
struct HeightField {
  int size = 0;
  float texel_m = 0.0f;  // side of a texel
  std::vector<float> height_m;

  float at(int x, int y) const {
    // A power-of-two side wraps with a mask (the march's inner loop), any other with a modulo.
    if ((size & (size - 1)) == 0) {
      return height_m[static_cast<std::size_t>((y & (size - 1)) * size + (x & (size - 1)))];
    }
    return height_m[static_cast<std::size_t>(((y % size + size) % size) * size +
                                             ((x % size + size) % size))];
  }
  // Bilinear, in texels (texel centres at integers), repeating.
  float sample(float x, float y) const;
};

struct HorizonConfig {
  int directions = 32;  // azimuths, the first along +x, counter-clockwise (the paper: 16 or 32)
  int stride = 1;       // field texels per map texel
  float max_distance_texels = 128.0f;  // how far along each azimuth the march looks
  float dense_texels = 8.0f;           // sampled at every texel out to here, then ever sparser
};

// tan(beta) and d for every azimuth: layer k at azimuth 2 pi k / directions in the field's
// texel axes, (size / stride)^2 texels each, row-major. tan(beta) is negative for a texel above
// everything around it (the steepest of the slopes down, the farthest point); d in metres.
struct HorizonMaps {
  int size = 0;
  int directions = 0;
  float texel_m = 0.0f;  // of the maps
  std::vector<float> tan_beta;
  std::vector<float> distance_m;

  std::size_t index(int layer, int x, int y) const {
    return (static_cast<std::size_t>(layer) * size + static_cast<std::size_t>(y)) * size +
           static_cast<std::size_t>(x);
  }
  struct Horizon {
    float tan_beta;
    float distance_m;
  };
  // At map texel (x, y), for an azimuth (radians) between two layers: linear in between, as the
  // texture array is sampled.
  Horizon at(int x, int y, float azimuth_rad) const;
  // The share of the direct light that reaches a relief's texels past their shadows, for a light
  // at this elevation above a flat surface: over all texels and azimuths, each texel weighted by
  // the light its own facet faces, E[max(n.l, 0) lit] / E[max(n.l, 0)]. What a pixel that covers
  // many texels keeps of the sun (the facets a low sun lights are the ones facing it, so more
  // than the lit texels' share).
  float mean_lit(float elevation_rad) const;
  std::vector<float> lit_by_degree;  // mean_lit at 0, 1, ... 90 degrees (made by the build)
};

// Marches every texel along every azimuth (the field's bilinear heights at 1, 2, ... texels out to
// dense_texels, then at steps that double out to max_distance_texels), on `threads` threads. A map
// texel's centre is where the field's texture puts it: field texel (x + 1/2) stride - 1/2.
HorizonMaps build_horizon_maps(const HeightField& field, const HorizonConfig& config,
                               int threads = 2);

// The horizon corrected for the surface's curvature k (1/m, convex positive) along the light,
// for a texel h_m above the surface: the larger of eq. 2, tan(beta) (1 - k h) - k d / 2, and
// eq. 3, the surface's own rim seen from h above it, cos(beta') = 1 / (k h + 1), which lies
// below the tangent plane (a negative slope). Concave parts (k < 0) and flat ones keep the
// horizon as it is, but never below the tangent plane.
float corrected_tan_horizon(float tan_beta, float distance_m, float h_m, float k);
// Without the curvature (Forsyth's horizon map, the paper's "conventional" method).
inline float flat_tan_horizon(float tan_beta) { return tan_beta > 0.0f ? tan_beta : 0.0f; }

// The maps as the GPU holds them: 8 bits a value (llvmpipe filters 8-bit textures fastest), each
// texel of layer k with azimuths k and k + 1 (one fetch for the two the shader blends). tan(beta)
// as 1/2 + sign sqrt(|tan| / 4) / 2 (finest near 0, where a low sun's slopes are; [-4, 4]), the
// distance as sqrt(d / kHorizonDistanceRangeM).
inline constexpr float kHorizonDistanceRangeM = 0.5f;
std::uint8_t encode_tan_horizon(float tan_beta);
float decode_tan_horizon(std::uint8_t byte);
std::uint8_t encode_horizon_distance(float distance_m);
float decode_horizon_distance(std::uint8_t byte);
// Layer k of `maps` as RGBA8: r, g tan(beta) and d at azimuth k; b, a at azimuth k + 1.
std::vector<std::uint8_t> packed_layer(const HorizonMaps& maps, int k);

// The reliefs the road draws, with their maps, built once a process and shared.
struct RoadReliefs {
  HeightField asphalt;  // 512 texels over kAsphaltTileM
  HeightField setts;    // 256 texels over kSettsTileM: the shoulder's stone setts
  HorizonMaps asphalt_horizon;
  HorizonMaps setts_horizon;
  double build_ms = 0.0;  // the maps' march, wall time
};
inline constexpr float kAsphaltTileM = 1.5f;
inline constexpr float kSettsTileM = 1.0f;
// The tile of both on the GPU (shared_resources.cpp: two asphalt tiles, three of the setts).
inline constexpr float kGroundTileM = 3.0f;
// The asphalt's stones: their tops 4 to 9 mm over the binder.
inline constexpr float kAsphaltDepthM = 3.0f * kAsphaltTileM / 512.0f;
// The setts: 2 cm from the joints' floor to a stone's crown.
inline constexpr float kSettsDepthM = 0.02f;

HeightField asphalt_heights(int size, std::uint32_t seed);
HeightField setts_heights(int size, std::uint32_t seed);
std::shared_ptr<const RoadReliefs> road_reliefs(int directions = 32);

}  // namespace downpour::render::relief
