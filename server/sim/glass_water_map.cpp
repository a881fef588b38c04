#include "server/sim/glass_water_map.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>

namespace downpour::sim {
namespace {

// Stamps only name contents (a renderer compares them to skip uploads); they carry no state.
std::uint64_t next_stamp() {
  static std::atomic<std::uint64_t> counter{0};
  return ++counter;
}

std::uint64_t mix(std::uint64_t z) {  // splitmix64's finaliser
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

std::uint64_t metaball_hash(const Metaball& m) {
  const std::uint64_t u = std::bit_cast<std::uint32_t>(m.u_mm);
  const std::uint64_t v = std::bit_cast<std::uint32_t>(m.v_mm);
  const std::uint64_t r = std::bit_cast<std::uint32_t>(m.radius_mm);
  return mix((u << 32 | v) ^ mix(r + 0x51ed2701u));
}

// The texels whose centres lie strictly within `reach` of `centre` along one axis.
void texel_span(float centre, float reach, float texel, int* first, int* last) {
  *first = static_cast<int>(std::floor((centre - reach) / texel - 0.5f)) + 1;
  *last = static_cast<int>(std::ceil((centre + reach) / texel - 0.5f)) - 1;
}

// Below this summed density a texel is at least 1.7 radii from every centre that could make it
// water: flat, dry glass. Above it, up to the threshold, the normals of a drop's rim.
constexpr float kShadedDensity = 0.1f;
constexpr std::uint32_t kDryTexel = 0x00008080u;  // flat normal, no height, no water

std::uint32_t byte_of(float x) {
  return static_cast<std::uint32_t>(
      static_cast<std::int32_t>(std::min(std::max(x, 0.0f), 1.0f) * 255.0f + 0.5f));
}

// Threshold and normals of one texel (seed 000, section 1.5 steps 3-4): central differences of
// the compressed heights (c at the texel, l r d u around it). Beyond the paper, lenses: a lone drop
// is a spherical cap, whose surface leans sin(contact angle) * h / R at distance h from the centre
// of a drop of contact radius R; (h / R)^2 comes back from the raw density, N = 1 / (1 + (h/R)^4).
// Where the compressed heights lean more (drops run together) they win. Without this the
// compressed plateaus are flat, and a drop would show only its edge, not the world turned over.
// Branch-free, so that a row of texels runs as vector code. Little-endian RGBA8.
struct TexelShading {
  float threshold = 0.5f;
  float to_height = 2.0f;  // height (mm) per texel of the slope, per unit of compressed height
  float contact_sin2 = 0.4f;

  std::uint32_t operator()(float raw, float c, float l, float r, float d, float u) const {
    const float sx = 0.5f * (r - l), sy = 0.5f * (u - d);  // height per texel
    // The surface normal's glass-parallel part: normalize(-gradient * height_scale, 1).xy.
    const float gx = -sx * to_height, gy = -sy * to_height;
    const float inv_len = 1.0f / std::sqrt(gx * gx + gy * gy + 1.0f);
    const float nx = gx * inv_len, ny = gy * inv_len;
    const float lean2 =
        contact_sin2 *
        std::min(std::sqrt(std::max(1.0f / std::max(raw, 1e-6f) - 1.0f, 0.0f)), 1.0f);
    const float steep2 = sx * sx + sy * sy;
    const float lens = std::sqrt(lean2 / std::max(steep2, 1e-12f));
    const bool use_lens = steep2 > 1e-12f && nx * nx + ny * ny < lean2;
    const bool wet = raw >= kShadedDensity;  // else far from water: dry, flat glass
    const float tx = wet ? (use_lens ? -sx * lens : nx) : 0.0f;
    const float ty = wet ? (use_lens ? -sy * lens : ny) : 0.0f;
    // The threshold's edge placed within the texel from the local slope.
    const float mask =
        (c - threshold) / std::max(std::max(std::abs(sx), std::abs(sy)), 1e-4f) + 0.5f;
    return byte_of(tx * 0.5f + 0.5f) | byte_of(ty * 0.5f + 0.5f) << 8 | byte_of(c) << 16 |
           byte_of(wet ? mask : 0.0f) << 24;
  }
};

}  // namespace

double GlassWaterMap::coverage_at(glm::dvec2 uv) const {
  if (width <= 0 || height <= 0 || texel_mm <= 0.0) return 0.0;
  const int i = static_cast<int>(std::floor(uv.x / texel_mm));
  const int j = static_cast<int>(std::floor(uv.y / texel_mm));
  if (i < 0 || j < 0 || i >= width || j >= height) return 0.0;
  return rgba[(static_cast<std::size_t>(j) * width + i) * 4 + 3] / 255.0;
}

GlassWaterMapBuilder::GlassWaterMapBuilder(const GlassConfig& glass, GlassWaterMapConfig config)
    : config_(config) {
  texel_ = static_cast<float>(config_.texel_mm);
  width_ = std::max(1, static_cast<int>(std::ceil(glass.bottom_width_mm / config_.texel_mm)));
  height_ = std::max(1, static_cast<int>(std::ceil(glass.height_mm / config_.texel_mm)));
  constexpr int t = kTile;
  tiles_x_ = (width_ + t - 1) / t;
  tiles_y_ = (height_ + t - 1) / t;
  contact_sin_ = static_cast<float>(std::sin(config_.contact_angle_deg * M_PI / 180.0));
  const std::size_t texels = static_cast<std::size_t>(width_) * height_;
  on_glass_.resize(texels);
  for (int j = 0; j < height_; ++j) {
    for (int i = 0; i < width_; ++i) {
      const bool inside = glass.contains(glm::dvec2(i + 0.5, j + 0.5) * config_.texel_mm);
      on_glass_[static_cast<std::size_t>(j) * width_ + i] = inside ? 0xffffffffu : 0u;
      glass_texels_ += inside;
    }
  }
  raw_.assign(texels, 0.0f);
  const std::size_t tiles = static_cast<std::size_t>(tiles_x_) * tiles_y_;
  tile_hash_.assign(tiles, 0);
  last_tile_hash_.assign(tiles, 0);
  tile_count_.assign(tiles, 0);
  last_tile_count_.assign(tiles, 0);
  dirty_.assign(tiles, 0);
  tile_max_raw_.assign(tiles, 0.0f);
}

void GlassWaterMapBuilder::build(const std::vector<Metaball>& metaballs, GlassWaterMap& map) {
  constexpr int t = kTile;
  const float extent = static_cast<float>(config_.splat_extent_radii);
  const bool whole = map.stamp == 0 || map.stamp != last_stamp_ || map.width != width_ ||
                     map.height != height_ ||
                     map.rgba.size() != static_cast<std::size_t>(width_) * height_ * 4;

  // Which tiles each metaball reaches: a hash and a count per tile, then the runs of entries.
  const std::size_t tiles = tile_hash_.size();
  std::fill(tile_hash_.begin(), tile_hash_.end(), 0);
  std::fill(tile_count_.begin(), tile_count_.end(), 0);
  reach_.resize(metaballs.size());
  const float min_radius = static_cast<float>(config_.min_radius_texels * config_.texel_mm);
  const float small_radius = static_cast<float>(config_.small_radius_texels * config_.texel_mm);
  for (std::size_t idx = 0; idx < metaballs.size(); ++idx) {
    const Metaball& m = metaballs[idx];
    TexelSpan& span = reach_[idx];
    // A small drop splatted as wide as small_radius at amplitude a, wet where a N(h / R') > 1/2:
    // out to h^2 = R'^2 sqrt(2a - 1), which is R^2 for a = (1 + (R / R')^4) / 2.
    const float radius = std::max(m.radius_mm, small_radius);
    const float ratio = m.radius_mm / radius;
    const float amplitude = 0.5f * (1.0f + ratio * ratio * ratio * ratio);
    const float reach = extent * radius;
    int i0, i1, j0, j1;
    texel_span(m.u_mm, reach, texel_, &i0, &i1);
    texel_span(m.v_mm, reach, texel_, &j0, &j1);
    i0 = std::max(i0, 0);
    j0 = std::max(j0, 0);
    i1 = std::min(i1, width_ - 1);
    j1 = std::min(j1, height_ - 1);
    if (i0 > i1 || j0 > j1 || !(m.radius_mm >= min_radius)) {
      span = {1, 0, 1, 0, 0.0f, 0.0f};  // reaches no texel
      continue;
    }
    span = {i0, i1, j0, j1, radius, amplitude};
    const std::uint64_t h = metaball_hash(m);
    for (int ty = j0 / t; ty <= j1 / t; ++ty) {
      for (int tx = i0 / t; tx <= i1 / t; ++tx) {
        const std::size_t tile = static_cast<std::size_t>(ty) * tiles_x_ + tx;
        tile_hash_[tile] += h;
        ++tile_count_[tile];
      }
    }
  }
  tile_start_.assign(tiles + 1, 0);
  for (std::size_t k = 0; k < tiles; ++k) tile_start_[k + 1] = tile_start_[k] + tile_count_[k];
  tile_entries_.resize(tile_start_[tiles]);
  tile_fill_.assign(tile_start_.begin(), tile_start_.end() - 1);
  for (std::uint32_t idx = 0; idx < metaballs.size(); ++idx) {
    const TexelSpan& span = reach_[idx];
    if (span.i0 > span.i1) continue;
    for (int ty = span.j0 / t; ty <= span.j1 / t; ++ty) {
      for (int tx = span.i0 / t; tx <= span.i1 / t; ++tx)
        tile_entries_[tile_fill_[static_cast<std::size_t>(ty) * tiles_x_ + tx]++] = idx;
    }
  }

  if (whole) map.rgba.assign(static_cast<std::size_t>(width_) * height_ * 4, 0);
  tiles_rebuilt_ = 0;
  for (std::size_t k = 0; k < tiles; ++k) {
    dirty_[k] =
        whole || tile_hash_[k] != last_tile_hash_[k] || tile_count_[k] != last_tile_count_[k];
    if (!dirty_[k]) continue;
    splat_tile(static_cast<int>(k), metaballs);
    ++tiles_rebuilt_;
  }
  // Shade the rebuilt tiles and the texels around them (their normals take the neighbours), in
  // runs of neighbouring tiles along each row of tiles.
  int row_begin = height_, row_end = 0;
  for (int ty = 0; ty < tiles_y_; ++ty) {
    const int j0 = std::max(ty * t - 1, 0), j1 = std::min((ty + 1) * t + 1, height_);
    for (int tx = 0; tx < tiles_x_;) {
      if (!dirty_[static_cast<std::size_t>(ty) * tiles_x_ + tx]) {
        ++tx;
        continue;
      }
      const int first = tx;
      while (tx < tiles_x_ && dirty_[static_cast<std::size_t>(ty) * tiles_x_ + tx]) ++tx;
      shade(std::max(first * t - 1, 0), std::min(tx * t + 1, width_), j0, j1, map.rgba);
      row_begin = std::min(row_begin, j0);
      row_end = std::max(row_end, j1);
    }
  }
  std::swap(tile_hash_, last_tile_hash_);
  std::swap(tile_count_, last_tile_count_);

  std::uint64_t wet = 0;
  const std::size_t texels = static_cast<std::size_t>(width_) * height_;
  const std::uint32_t* shaded = reinterpret_cast<const std::uint32_t*>(map.rgba.data());
  for (std::size_t k = 0; k < texels; ++k) wet += (shaded[k] & on_glass_[k]) >> 24;
  map.width = width_;
  map.height = height_;
  map.texel_mm = config_.texel_mm;
  map.previous_stamp = whole ? 0 : map.stamp;
  map.stamp = next_stamp();
  map.dirty_row_begin = whole ? 0 : std::min(row_begin, row_end);
  map.dirty_row_end = whole ? height_ : row_end;
  map.wet_fraction = glass_texels_ ? static_cast<double>(wet) / (255.0 * glass_texels_) : 0.0;
  last_stamp_ = map.stamp;
}

// The texel loops are built twice (GCC), AVX2 and baseline, and picked at load time by an ifunc
// resolver. A ThreadSanitizer build runs that resolver before its runtime is up, and clang wants
// the attribute on the first declaration: both get the baseline alone.
#if defined(__SANITIZE_THREAD__) || defined(__clang__)
#define DOWNPOUR_VECTOR_CLONES
#else
#define DOWNPOUR_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#endif

// The summed profiles N = 1 / (1 + (h/R)^4) of the metaballs that reach this tile, over its
// texels (seed 000, section 1.5 step 1).
DOWNPOUR_VECTOR_CLONES void GlassWaterMapBuilder::splat_tile(
    int tile, const std::vector<Metaball>& metaballs) {
  constexpr int t = kTile;
  const int tx = tile % tiles_x_, ty = tile / tiles_x_;
  const int ti0 = tx * t, tj0 = ty * t;
  // The tile in a local block (a full one even at the map's edges), added up, then copied out.
  alignas(32) float block[t][t] = {};
  float u_of[t];
  for (int i = 0; i < t; ++i) u_of[i] = (static_cast<float>(ti0 + i) + 0.5f) * texel_;
  for (std::uint32_t e = tile_start_[tile]; e < tile_start_[tile + 1]; ++e) {
    const Metaball& m = metaballs[tile_entries_[e]];
    const TexelSpan& span = reach_[tile_entries_[e]];
    const int i0 = std::max(span.i0 - ti0, 0), i1 = std::min(span.i1 - ti0, t - 1);
    const int j0 = std::max(span.j0 - tj0, 0), j1 = std::min(span.j1 - tj0, t - 1);
    const float inv_r2 = 1.0f / (span.radius * span.radius);
    const float a = span.amplitude;
    for (int j = j0; j <= j1; ++j) {
      const float dv = (static_cast<float>(tj0 + j) + 0.5f) * texel_ - m.v_mm;
      const float dv2 = dv * dv;
      // The whole row of the tile at once (vector code), zero outside the metaball's square.
      for (int i = 0; i < t; ++i) {
        const float du = u_of[i] - m.u_mm;
        const float q = (du * du + dv2) * inv_r2;  // (h/R)^2
        const float n = a / (1.0f + q * q);
        block[j][i] += (i >= i0 && i <= i1) ? n : 0.0f;
      }
    }
  }
  const int w = std::min(t, width_ - ti0), h = std::min(t, height_ - tj0);
  for (int j = 0; j < h; ++j)
    std::copy_n(block[j], w, raw_.data() + static_cast<std::ptrdiff_t>(tj0 + j) * width_ + ti0);
  const int ti1 = ti0 + w - 1, tj1 = tj0 + h - 1;
  float highest = 0.0f;
  for (int j = tj0; j <= tj1; ++j) {
    const float* row = raw_.data() + static_cast<std::ptrdiff_t>(j) * width_;
    for (int i = ti0; i <= ti1; ++i) highest = std::max(highest, row[i]);
  }
  tile_max_raw_[tile] = highest;
}

// Threshold and normals over a rectangle of texels [i0, i1) x [j0, j1), from the compressed
// heights of its rows and the rows around it (three row buffers, rolling down the rectangle).
// Vector code eight texels wide where the CPU has AVX2, else four (SSE2); the same IEEE results.
DOWNPOUR_VECTOR_CLONES void GlassWaterMapBuilder::shade(int i0, int i1, int j0, int j1,
                                                        std::vector<std::uint8_t>& rgba) {
  TexelShading k;
  k.threshold = config_.compression.threshold;
  k.to_height = static_cast<float>(config_.height_scale_mm) / texel_;
  k.contact_sin2 = contact_sin_ * contact_sin_;
  const HeightCompressionConfig& cc = config_.compression;
  constexpr int t = kTile;
  // Buffer columns [c0, c1): the rectangle and a column either side, within the map.
  const int c0 = std::max(i0 - 1, 0), c1 = std::min(i1 + 1, width_), n = c1 - c0;
  row_buffers_.resize(3 * static_cast<std::size_t>(n));
  float* below = row_buffers_.data();
  float* middle = below + n;
  float* above = middle + n;
  auto compress_row = [&](int j, float* __restrict out) {
    const float* __restrict in =
        raw_.data() + static_cast<std::size_t>(std::clamp(j, 0, height_ - 1)) * width_ + c0;
    std::copy_n(in, n, out);
    float level = cc.first_level;
    for (int step = 0; step < cc.steps; ++step, level += cc.level_step) {  // vector code
      for (int i = 0; i < n; ++i)
        out[i] = std::min(out[i], level) + cc.k * std::max(out[i] - level, 0.0f);
    }
  };
  compress_row(j0 - 1, below);
  compress_row(j0, middle);
  std::uint32_t* texels = reinterpret_cast<std::uint32_t*>(rgba.data());
  for (int j = j0; j < j1; ++j) {
    compress_row(j + 1, above);
    const std::size_t row = static_cast<std::size_t>(j) * width_;
    const float* __restrict raw = raw_.data() + row;
    // Indexed by map column: c, d and u are the compressed rows at, below and above j.
    const float* __restrict c = middle - c0;
    const float* __restrict d = below - c0;
    const float* __restrict u = above - c0;
    std::uint32_t* __restrict out = texels + row;
    const float* tile_max = tile_max_raw_.data() + static_cast<std::size_t>(j / t) * tiles_x_;
    // Along the row a tile at a time: a tile far from water is dry, flat glass throughout.
    for (int a = i0; a < i1;) {
      const int b = std::min((a / t + 1) * t, i1);
      if (tile_max[a / t] < kShadedDensity) {
        std::fill(out + a, out + b, kDryTexel);
        a = b;
        continue;
      }
      // The map's edge columns take themselves for their missing neighbour (clamp to edge).
      if (a == 0) {
        out[0] = k(raw[0], c[0], c[0], c[std::min(1, width_ - 1)], d[0], u[0]);
        ++a;
      }
      const int last = std::min(b, width_ - 1);
      for (int i = a; i < last; ++i) out[i] = k(raw[i], c[i], c[i - 1], c[i + 1], d[i], u[i]);
      if (b == width_ && a < b) {
        const int e = width_ - 1;
        out[e] = k(raw[e], c[e], c[e - 1], c[e], d[e], u[e]);
      }
      a = b;
    }
    float* recycled = below;
    below = middle;
    middle = above;
    above = recycled;
  }
}

}  // namespace downpour::sim
