// The water on the windshield as every view samples it (seed 000, section 1.5 steps 1-4), built on
// the CPU once per published frame: the metaballs' summed density in glass space at a fixed texel
// size in millimetres, the paper's height compression and threshold, and the normals. One map per
// session per frame, shared by the COCKPIT and WINDSHIELD views and a dash camera. Incremental:
// only the tiles whose metaballs changed since the last frame are rebuilt.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>

#include "server/sim/drop_physics.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::sim {

// The paper's height compression and water threshold (seed 000, section 1.5 steps 2-3): for
// V0 = first_level, first_level + level_step, ... (steps times), V = k (V - V0) + V0 where V > V0;
// water where the compressed value exceeds the threshold.
struct HeightCompressionConfig {
  float k = 0.3f;
  float first_level = 0.5f;
  float level_step = 0.1f;
  int steps = 5;
  float threshold = 0.5f;
};

struct GlassWaterMapConfig {
  // Texel size on the glass. The driver's eye, focused on the road, blurs the glass over a circle
  // about as wide as the pupil (4 mm), so 2 mm texels resolve all that the driver can see.
  double texel_mm = 2.0;
  HeightCompressionConfig compression;
  // The metaball profile N = 1 / (1 + (h/R)^4) is added over a square reaching this many radii
  // from the centre (the paper's sprite; N = 0.025 at its edge).
  double splat_extent_radii = 2.5;
  // Drops smaller than a texel would light a texel only where one happens to lie near their
  // centre: below small_radius_texels a metaball is splatted that wide, its density lowered so
  // that it wets about its own area (the map's coverage and wet fraction stay true, the drop shows
  // as a faint spot). Below min_radius_texels it is left out (the shrinking ends of trails).
  double small_radius_texels = 0.75;
  double min_radius_texels = 0.28;
  // Beyond the paper: the water height (mm) of a compressed density of 1, for the normals; and
  // lenses: a lone drop is a spherical cap meeting the glass at the simulation's contact angle.
  double height_scale_mm = 4.0;
  double contact_angle_deg = kContactAngleDeg;
};

class GlassWaterMapBuilder {
 public:
  static constexpr int kTile = 8;  // texels a side: the unit of incremental rebuilding

  explicit GlassWaterMapBuilder(const GlassConfig& glass, GlassWaterMapConfig config = {});

  // Brings `map` up to these metaballs. A map built by the previous call is updated where its
  // tiles' metaballs changed; any other map is built whole.
  void build(const std::vector<Metaball>& metaballs, GlassWaterMap& map);

  const GlassWaterMapConfig& config() const { return config_; }
  // The summed densities before compression, one float a texel (tests).
  const std::vector<float>& raw_heights() const { return raw_; }
  int tiles() const { return tiles_x_ * tiles_y_; }
  int tiles_rebuilt() const { return tiles_rebuilt_; }  // by the last build

 private:
  void splat_tile(int tile, const std::vector<Metaball>& metaballs);
  void shade(int i0, int i1, int j0, int j1, std::vector<std::uint8_t>& rgba);

  GlassWaterMapConfig config_;
  int width_ = 0, height_ = 0;
  int tiles_x_ = 0, tiles_y_ = 0;
  float texel_ = 0.0f;
  float contact_sin_ = 0.0f;
  std::vector<std::uint32_t> on_glass_;  // all ones where the texel centre is inside the trapezoid
  std::size_t glass_texels_ = 0;
  std::vector<float> raw_;          // summed densities
  std::vector<float> row_buffers_;  // three rows of compressed heights, for shade()
  // Per tile: a hash and count of the metaballs that reach it, now and at the last build.
  std::vector<std::uint64_t> tile_hash_, last_tile_hash_;
  std::vector<std::uint32_t> tile_count_, last_tile_count_;
  struct TexelSpan {
    int i0, i1, j0, j1;  // inclusive
    float radius;        // as splatted
    float amplitude;     // of its density
  };
  std::vector<TexelSpan> reach_;  // per metaball: the texels its square reaches
  // The metaballs reaching each tile, as index runs (a counting sort by tile).
  std::vector<std::uint32_t> tile_start_, tile_fill_, tile_entries_;
  std::vector<std::uint8_t> dirty_;
  std::vector<float> tile_max_raw_;  // the highest summed density in each tile
  std::uint64_t last_stamp_ = 0;
  int tiles_rebuilt_ = 0;
};

}  // namespace downpour::sim
