#pragma once

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "server/render/frame_context.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::render {

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

struct WindshieldWaterConfig {
  HeightCompressionConfig compression;
  int density_texture_size = 64;    // the metaball profile, computed once (section 1.5 step 1)
  float splat_extent_radii = 2.5f;  // a metaball's sprite reaches this far from its centre
  // Level of detail: metaballs smaller than this many texels are left out (they would light a
  // texel only now and then, and cost as much as large ones to draw), and past the budget the
  // smallest (on llvmpipe a sprite costs about 0.3 us twice over: splat and compression).
  float min_radius_texels = 0.33f;
  int max_metaballs = 12000;
  // The maps' texels are square, about as many as the view's pixels on the glass (the glass as
  // far as the view sees it), 256 to 1024 across.
  int min_map_width = 256;
  int max_map_size = 1024;
  // Around the part of the glass that a COCKPIT view sees: metaballs whose sprite reaches into
  // it have their centre within the margin (sprites are culled by their centre).
  float map_margin_mm = 30.0f;
  // Beyond the paper: the water height (mm) of a compressed density of 1, for the normals, and
  // lenses: a lone drop is a spherical cap meeting the glass at the contact angle.
  float height_scale_mm = 4.0f;
  float contact_angle_deg = 40.0f;
};

struct WaterMapSize {
  int width = 0;
  int height = 0;
  bool operator<(const WaterMapSize& o) const {
    return std::pair(width, height) < std::pair(o.width, o.height);
  }
};

// Where the maps lie on the glass and their size in texels.
struct WaterMapLayout {
  WaterMapSize size;
  glm::vec2 origin_mm{0.0f};  // glass space of the maps' corner (0, 0)
  glm::vec2 extent_mm{1.0f};  // glass-space size covered
};

// The maps for a view. WINDSHIELD: the glass's bounding rectangle [0, bottom width] x [0, height]
// at the view's fit. COCKPIT: the part of that rectangle the camera sees (plus a margin), at the
// view's mean pixel density on the glass (weighted by the image each part fills); the driver's
// eye sees most of the glass, a dash camera less of it, closer.
WaterMapLayout water_map_layout(const FrameContext& frame, const WindshieldWaterConfig& config);

// Windshield water as the paper renders it (seed 000, section 1.5 steps 1-4), in glass space:
// metaballs splatted as point sprites of the precomputed density with additive blending into a
// float height map over a rectangle of the glass (water_map_layout), then one pass that
// compresses the heights, thresholds them and takes normals by central differences into the water
// map (over the same sprites, or over the tiles they reach where they pile up):
// RGBA8 = (normal u, normal v) * 0.5 + 0.5, compressed height, water coverage (anti-aliased mask).
// Reads: the WindshieldState's metaballs. Writes: the height map, then the water map.
// A sprite whose centre lies off the map is culled (GL clips points by their centre): hence the
// layout's margin. The paper's instanced quads cost about twice as much on llvmpipe.
class WindshieldWaterPass {
 public:
  explicit WindshieldWaterPass(WindshieldWaterConfig config = {});

  // Splats the metaballs into a height map of the layout's size (made on first use of a size).
  void splat(const sim::WindshieldState& water, const WaterMapLayout& layout);
  // Compression, threshold and normals: height map -> water map (of the last splat).
  void compress();
  // Fills the water map's mip levels 1 to up_to_level (for a defocused camera); after compress().
  void build_mipmaps(int up_to_level);

  const WindshieldWaterConfig& config() const { return config_; }
  const WaterMapLayout& layout() const { return layout_; }
  GLuint water_map() const { return current_->second.water.id(); }
  int water_map_levels() const { return current_->second.water_levels; }

  // Read-backs for tests: heights (rows bottom-up, one float a texel) and the water map (RGBA8).
  std::vector<float> read_heights() const;
  std::vector<std::uint8_t> read_water_map() const;

 private:
  struct Maps {
    Texture heights;  // R32F, additive splats
    Framebuffer heights_fbo;
    Texture water;  // RGBA8, mipmapped storage
    Framebuffer water_fbo;
    int water_levels = 1;
  };
  Maps& maps_for(WaterMapSize size);
  void set_layout_uniforms(ShaderProgram& program);
  void draw_metaballs();

  WindshieldWaterConfig config_;
  ShaderProgram splat_program_;
  ShaderProgram compress_program_;        // over the sprites
  ShaderProgram compress_tiles_program_;  // over the tiles they reach, when those are fewer
  Texture density_;                       // N = 1 / (1 + (h/R)^4) over [-extent R, extent R]^2
  VertexArray metaball_vao_;
  Buffer metaball_buffer_;             // the metaballs as they are, one vertex each
  std::size_t metaball_capacity_ = 0;  // bytes
  std::vector<sim::Metaball> drawn_;   // of the last splat
  std::size_t metaball_count_ = 0;
  bool compress_over_tiles_ = false;
  std::vector<std::uint8_t> occupied_;    // tiles that a sprite reaches
  std::vector<glm::vec2> tile_vertices_;  // runs of them, as triangles
  VertexArray tile_vao_;
  Buffer tile_buffer_;
  std::size_t tile_capacity_ = 0;      // bytes
  std::map<WaterMapSize, Maps> maps_;  // one set per view size in use
  std::map<WaterMapSize, Maps>::iterator current_;
  WaterMapLayout layout_;
};

}  // namespace downpour::render
