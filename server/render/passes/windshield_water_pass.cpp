#include "server/render/passes/windshield_water_pass.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <optional>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

namespace downpour::render {
namespace {

constexpr int kTile = 32;  // texels a side: the compression's tiles

static_assert(sizeof(sim::Metaball) == 3 * sizeof(float), "metaballs are uploaded as they are");

// Square texels at a density (texels per mm) over a glass-space extent, within the config's sizes.
WaterMapSize map_size(glm::dvec2 extent_mm, double texels_per_mm, const WindshieldWaterConfig& c) {
  const double longest = std::max(extent_mm.x, extent_mm.y);
  double density = std::max(texels_per_mm, c.min_map_width / extent_mm.x);
  density = std::min(density, c.max_map_size / longest);
  WaterMapSize size;
  size.width = std::max(1, static_cast<int>(std::lround(extent_mm.x * density)));
  size.height = std::max(1, static_cast<int>(std::lround(extent_mm.y * density)));
  return size;
}

}  // namespace

WaterMapLayout water_map_layout(const FrameContext& f, const WindshieldWaterConfig& config) {
  const sim::GlassConfig& glass = f.scene.glass;
  const glm::dvec2 glass_mm(glass.bottom_width_mm, glass.height_mm);
  WaterMapLayout layout;
  if (f.spec.view != sim::View::kCockpit) {
    // windshield.frag fits the glass into the view with a 10 % margin.
    const double aspect = double(f.spec.width) / f.spec.height;
    const double view_height_mm = std::max(glass.bottom_width_mm / aspect, glass.height_mm) * 1.1;
    layout.size = map_size(glass_mm, f.spec.height / view_height_mm, config);
    layout.extent_mm = glm::vec2(glass_mm);
    return layout;
  }
  // A grid of points over the glass's rectangle, projected into the view: the visible ones bound
  // the part of the glass seen; between visible neighbours, the view's pixels per millimetre.
  constexpr int kColumns = 64, kRows = 32;
  const glm::dvec2 cell = glass_mm / glm::dvec2(kColumns, kRows);
  const glm::dmat4 clip(f.camera.projection * f.camera.view * f.vehicle_to_world);
  const glm::dvec2 half_view(0.5 * f.spec.width, 0.5 * f.spec.height);
  std::optional<glm::dvec2> pixel[kRows + 1][kColumns + 1];  // on screen, from its centre
  glm::dvec2 lo(glass_mm), hi(0.0);
  for (int r = 0; r <= kRows; ++r) {
    for (int c = 0; c <= kColumns; ++c) {
      const glm::dvec2 mm = glm::dvec2(c, r) * cell;
      const glm::dvec4 p = clip * glm::dvec4(glass.to_vehicle(mm), 1.0);
      if (p.w <= 1e-4) continue;
      const glm::dvec2 ndc = glm::dvec2(p) / p.w;
      if (std::abs(ndc.x) > 1.0 || std::abs(ndc.y) > 1.0) continue;
      pixel[r][c] = ndc * half_view;
      lo = glm::min(lo, mm - cell);  // the cells around a visible point may be partly visible
      hi = glm::max(hi, mm + cell);
    }
  }
  // The mean over the view, not over the glass: a cell of density d (pixels per mm) fills about
  // d^2 of the image, so the near, magnified part of the glass counts as much as it fills.
  double weighted = 0.0, weights = 0.0;
  for (int r = 0; r <= kRows; ++r) {
    for (int c = 0; c < kColumns; ++c) {
      if (!pixel[r][c] || !pixel[r][c + 1]) continue;
      const double d = glm::length(*pixel[r][c + 1] - *pixel[r][c]) / cell.x;
      weighted += d * d * d;
      weights += d * d;
    }
  }
  if (weights <= 0.0 || hi.x <= lo.x || hi.y <= lo.y) {  // the glass is out of sight
    layout.size = map_size(glass_mm, 0.0, config);
    layout.extent_mm = glm::vec2(glass_mm);
    return layout;
  }
  // Metaballs are on the glass: a margin only where the view cuts it.
  lo = glm::max(lo - double(config.map_margin_mm), glm::dvec2(0.0));
  hi = glm::min(hi + double(config.map_margin_mm), glass_mm);
  layout.size = map_size(hi - lo, weighted / weights, config);
  layout.origin_mm = glm::vec2(lo);
  layout.extent_mm = glm::vec2(hi - lo);
  return layout;
}

WindshieldWaterPass::WindshieldWaterPass(WindshieldWaterConfig config)
    : config_(config),
      splat_program_("windshield_water_splat.vert", "windshield_water_splat.frag"),
      compress_program_("windshield_water_splat.vert", "windshield_water_compress.frag"),
      compress_tiles_program_("windshield_water_tiles.vert", "windshield_water_compress.frag"),
      current_(maps_.end()) {
  // The metaball profile N = 1 / (1 + (h/R)^4), at texel centres across the sprite.
  const int n = config_.density_texture_size;
  std::vector<float> density(static_cast<std::size_t>(n) * n);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const glm::vec2 p = ((glm::vec2(x, y) + 0.5f) / float(n) * 2.0f - 1.0f) *
                          config_.splat_extent_radii;  // in radii
      const float h2 = glm::dot(p, p);
      density[static_cast<std::size_t>(y) * n + x] = 1.0f / (1.0f + h2 * h2);
    }
  }
  density_ = make_texture_2d(GL_R32F, n, n);
  glTextureSubImage2D(density_.id(), 0, 0, 0, n, n, GL_RED, GL_FLOAT, density.data());
  glTextureParameteri(density_.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(density_.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);

  // One float attribute stream each: metaballs (u, v, R) and compression tiles (u, v).
  auto point_stream = [](int components, VertexArray& vao_out, Buffer& buffer_out) {
    GLuint vao = 0, buffer = 0;
    glCreateVertexArrays(1, &vao);
    vao_out = VertexArray(vao);
    glCreateBuffers(1, &buffer);
    buffer_out = Buffer(buffer);
    glEnableVertexArrayAttrib(vao, 0);
    glVertexArrayAttribFormat(vao, 0, components, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, 0, 0);
  };
  point_stream(3, metaball_vao_, metaball_buffer_);
  point_stream(2, tile_vao_, tile_buffer_);

  const HeightCompressionConfig& c = config_.compression;
  for (ShaderProgram* p : {&compress_program_, &compress_tiles_program_}) {
    p->set("u_k", c.k);
    p->set("u_first_level", c.first_level);
    p->set("u_level_step", c.level_step);
    p->set("u_steps", c.steps);
    p->set("u_threshold", c.threshold);
    p->set("u_height_scale_mm", config_.height_scale_mm);
    p->set("u_contact_sin", std::sin(glm::radians(config_.contact_angle_deg)));
  }
  for (ShaderProgram* p : {&splat_program_, &compress_program_})
    p->set("u_extent_radii", config_.splat_extent_radii);
}

WindshieldWaterPass::Maps& WindshieldWaterPass::maps_for(WaterMapSize size) {
  auto it = maps_.find(size);
  if (it == maps_.end()) {
    // Views of many sizes at once are rare; past a handful, start over rather than grow.
    if (maps_.size() >= 6) maps_.clear();
    Maps m;
    m.heights = make_texture_2d(GL_R32F, size.width, size.height);
    glTextureParameteri(m.heights.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(m.heights.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    // Mips for a defocused camera's blur, up to 16 texels.
    for (int s = std::max(size.width, size.height); s > 1 && m.water_levels < 5; s /= 2)
      ++m.water_levels;
    m.water = make_texture_2d(GL_RGBA8, size.width, size.height, m.water_levels);
    // The blur level is one for the whole frame: one mip level a lookup is enough.
    glTextureParameteri(m.water.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_NEAREST);
    for (const Texture* t : {&m.heights, &m.water}) {
      glTextureParameteri(t->id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTextureParameteri(t->id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    GLuint fbos[2];
    glCreateFramebuffers(2, fbos);
    m.heights_fbo = Framebuffer(fbos[0]);
    m.water_fbo = Framebuffer(fbos[1]);
    glNamedFramebufferTexture(fbos[0], GL_COLOR_ATTACHMENT0, m.heights.id(), 0);
    glNamedFramebufferTexture(fbos[1], GL_COLOR_ATTACHMENT0, m.water.id(), 0);
    it = maps_.emplace(size, std::move(m)).first;
  }
  return it->second;
}

void WindshieldWaterPass::splat(const sim::WindshieldState& water, const WaterMapLayout& layout) {
  const WaterMapSize size = layout.size;
  Maps& m = maps_for(size);
  current_ = maps_.find(size);
  layout_ = layout;
  glBindFramebuffer(GL_FRAMEBUFFER, m.heights_fbo.id());
  glViewport(0, 0, size.width, size.height);
  const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  glClearNamedFramebufferfv(m.heights_fbo.id(), GL_COLOR, 0, zero);
  // The metaballs that can show: on the map, and not far below a texel (one of R < t / 3 lifts
  // its nearest texel over the threshold less than a third of the time, and costs as much to draw
  // as a large one); past the budget, the largest.
  const float texels_per_mm = static_cast<float>(size.width) / layout.extent_mm.x;
  const float min_radius_mm = config_.min_radius_texels / texels_per_mm;
  const glm::vec2 lo = layout.origin_mm, hi = layout.origin_mm + layout.extent_mm;
  drawn_.clear();
  for (const sim::Metaball& b : water.metaballs) {
    const float reach = config_.splat_extent_radii * b.radius_mm;
    if (b.radius_mm >= min_radius_mm && b.u_mm + reach >= lo.x && b.u_mm - reach <= hi.x &&
        b.v_mm + reach >= lo.y && b.v_mm - reach <= hi.y) {
      drawn_.push_back(b);
    }
  }
  if (drawn_.size() > static_cast<std::size_t>(config_.max_metaballs)) {
    std::nth_element(
        drawn_.begin(), drawn_.begin() + config_.max_metaballs, drawn_.end(),
        [](const sim::Metaball& a, const sim::Metaball& b) { return a.radius_mm > b.radius_mm; });
    drawn_.resize(static_cast<std::size_t>(config_.max_metaballs));
  }
  metaball_count_ = drawn_.size();
  // The compression runs over the sprites, or over the tiles of the map that any sprite reaches,
  // whichever covers less (llvmpipe shades whole 4 x 4 blocks: count those). On the tiles it
  // shades each texel once: better where the sprites pile up.
  const int tiles_x = (size.width + kTile - 1) / kTile, tiles_y = (size.height + kTile - 1) / kTile;
  occupied_.assign(static_cast<std::size_t>(tiles_x) * tiles_y, 0);
  double sprite_texels = 0.0;
  for (const sim::Metaball& b : drawn_) {
    const float reach = config_.splat_extent_radii * b.radius_mm * texels_per_mm;  // texels
    const double blocks = std::ceil(reach / 2.0);
    sprite_texels += 16.0 * (blocks + 1.0) * (blocks + 1.0);
    const glm::vec2 c = (glm::vec2(b.u_mm, b.v_mm) - lo) * texels_per_mm;
    const int x0 = std::max(0, static_cast<int>(c.x - reach) / kTile);
    const int x1 = std::min(tiles_x - 1, static_cast<int>(c.x + reach) / kTile);
    const int y0 = std::max(0, static_cast<int>(c.y - reach) / kTile);
    const int y1 = std::min(tiles_y - 1, static_cast<int>(c.y + reach) / kTile);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) occupied_[static_cast<std::size_t>(y) * tiles_x + x] = 1;
    }
  }
  // Runs of occupied tiles along each row, as quads in the map's clip space.
  tile_vertices_.clear();
  double tile_texels = 0.0;
  const glm::vec2 to_clip = 2.0f * float(kTile) / glm::vec2(size.width, size.height);
  for (int y = 0; y < tiles_y; ++y) {
    for (int x = 0; x < tiles_x;) {
      if (!occupied_[static_cast<std::size_t>(y) * tiles_x + x]) {
        ++x;
        continue;
      }
      const int start = x;
      while (x < tiles_x && occupied_[static_cast<std::size_t>(y) * tiles_x + x]) ++x;
      const glm::vec2 a = glm::vec2(start, y) * to_clip - 1.0f,
                      b = glm::vec2(x, y + 1) * to_clip - 1.0f;
      tile_vertices_.insert(tile_vertices_.end(),
                            {a, {b.x, a.y}, {a.x, b.y}, {a.x, b.y}, {b.x, a.y}, b});
      tile_texels += double(x - start) * kTile * kTile;
    }
  }
  compress_over_tiles_ = tile_texels < sprite_texels;
  if (drawn_.empty()) return;

  // Re-uploaded every frame: orphan the old storage, grow it when the drops outnumber it. One
  // vertex per metaball, drawn as a point sprite (the paper's first choice): on llvmpipe a point
  // costs about half of an instanced quad's two triangles.
  const std::size_t bytes = drawn_.size() * sizeof(sim::Metaball);
  if (bytes > metaball_capacity_) metaball_capacity_ = std::max(bytes, 2 * metaball_capacity_);
  glNamedBufferData(metaball_buffer_.id(), static_cast<GLsizeiptr>(metaball_capacity_), nullptr,
                    GL_STREAM_DRAW);
  glNamedBufferSubData(metaball_buffer_.id(), 0, static_cast<GLsizeiptr>(bytes), drawn_.data());
  glVertexArrayVertexBuffer(metaball_vao_.id(), 0, metaball_buffer_.id(), 0, sizeof(sim::Metaball));

  glDisable(GL_DEPTH_TEST);
  glEnable(GL_BLEND);
  glBlendEquation(GL_FUNC_ADD);
  glBlendFunc(GL_ONE, GL_ONE);
  splat_program_.use();
  set_layout_uniforms(splat_program_);
  glBindTextureUnit(binding::kMetaballDensity, density_.id());
  draw_metaballs();
  glDisable(GL_BLEND);
}

void WindshieldWaterPass::compress() {
  assert(current_ != maps_.end() && "compress() before splat()");
  Maps& m = current_->second;
  const WaterMapSize size = current_->first;
  // Dry glass: flat, no height, no water. Heights are zero outside every metaball's sprite, so the
  // pass runs over the sprites alone (overlapping ones compute the same texels again) or, where
  // they pile up, once over the tiles they reach (see splat()).
  const float dry[4] = {0.5f, 0.5f, 0.0f, 0.0f};
  glClearNamedFramebufferfv(m.water_fbo.id(), GL_COLOR, 0, dry);
  glTextureParameteri(m.water.id(), GL_TEXTURE_MAX_LEVEL, 0);  // until build_mipmaps()
  if (metaball_count_ == 0) return;
  glBindFramebuffer(GL_FRAMEBUFFER, m.water_fbo.id());
  glViewport(0, 0, size.width, size.height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glBindTextureUnit(binding::kWaterHeights, m.heights.id());
  if (compress_over_tiles_) {
    const std::size_t bytes = tile_vertices_.size() * sizeof(glm::vec2);
    if (bytes > tile_capacity_) tile_capacity_ = std::max(bytes, 2 * tile_capacity_);
    glNamedBufferData(tile_buffer_.id(), static_cast<GLsizeiptr>(tile_capacity_), nullptr,
                      GL_STREAM_DRAW);
    glNamedBufferSubData(tile_buffer_.id(), 0, static_cast<GLsizeiptr>(bytes),
                         tile_vertices_.data());
    glVertexArrayVertexBuffer(tile_vao_.id(), 0, tile_buffer_.id(), 0, sizeof(glm::vec2));
    compress_tiles_program_.use();
    set_layout_uniforms(compress_tiles_program_);
    glBindVertexArray(tile_vao_.id());
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(tile_vertices_.size()));
  } else {
    compress_program_.use();
    set_layout_uniforms(compress_program_);
    draw_metaballs();
  }
}

void WindshieldWaterPass::set_layout_uniforms(ShaderProgram& program) {
  program.set("u_texels_per_mm", static_cast<float>(layout_.size.width) / layout_.extent_mm.x);
  program.set("u_map_origin_mm", layout_.origin_mm);
  program.set("u_map_extent_mm", layout_.extent_mm);
}

void WindshieldWaterPass::draw_metaballs() {
  glEnable(GL_PROGRAM_POINT_SIZE);
  glBindVertexArray(metaball_vao_.id());
  glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(metaball_count_));
  glDisable(GL_PROGRAM_POINT_SIZE);
}

void WindshieldWaterPass::build_mipmaps(int up_to_level) {
  assert(current_ != maps_.end());
  const GLuint water = current_->second.water.id();
  glTextureParameteri(water, GL_TEXTURE_MAX_LEVEL, up_to_level);
  glGenerateTextureMipmap(water);
}

std::vector<float> WindshieldWaterPass::read_heights() const {
  assert(current_ != maps_.end());
  const WaterMapSize size = current_->first;
  std::vector<float> out(static_cast<std::size_t>(size.width) * size.height);
  glGetTextureImage(current_->second.heights.id(), 0, GL_RED, GL_FLOAT,
                    static_cast<GLsizei>(out.size() * sizeof(float)), out.data());
  return out;
}

std::vector<std::uint8_t> WindshieldWaterPass::read_water_map() const {
  assert(current_ != maps_.end());
  const WaterMapSize size = current_->first;
  std::vector<std::uint8_t> out(static_cast<std::size_t>(size.width) * size.height * 4);
  glGetTextureImage(current_->second.water.id(), 0, GL_RGBA, GL_UNSIGNED_BYTE,
                    static_cast<GLsizei>(out.size()), out.data());
  return out;
}

}  // namespace downpour::render
