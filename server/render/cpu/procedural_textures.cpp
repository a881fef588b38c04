#include "server/render/cpu/procedural_textures.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace downpour::render {
namespace {

// Tileable value noise of `cells` cells per side, smooth (quintic) interpolation, in [0, 1].
std::vector<float> value_noise(int size, int cells, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> lattice(static_cast<std::size_t>(cells * cells));
  for (float& v : lattice) v = u(rng);
  auto at = [&](int i, int j) {
    return lattice[((j % cells + cells) % cells) * cells + ((i % cells + cells) % cells)];
  };
  auto fade = [](float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); };
  std::vector<float> out(static_cast<std::size_t>(size * size));
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const float fx = static_cast<float>(x) * cells / size,
                  fy = static_cast<float>(y) * cells / size;
      const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
      const float tx = fade(fx - ix), ty = fade(fy - iy);
      const float a = at(ix, iy) + (at(ix + 1, iy) - at(ix, iy)) * tx;
      const float b = at(ix, iy + 1) + (at(ix + 1, iy + 1) - at(ix, iy + 1)) * tx;
      out[y * size + x] = a + (b - a) * ty;
    }
  }
  return out;
}

std::uint8_t to_byte(float v) {
  return static_cast<std::uint8_t>(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f);
}

}  // namespace

std::vector<float> asphalt_height_unit(int size, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<float> height(static_cast<std::size_t>(size * size), 0.0f);
  // Aggregate: rounded stones of a few sizes, packed at random, each a dome; the tallest wins.
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const int stones = size * size / 28;
  for (int k = 0; k < stones; ++k) {
    const float cx = u(rng) * size, cy = u(rng) * size;
    const float r = 1.2f + 3.8f * u(rng) * u(rng);
    const float top = 0.45f + 0.55f * u(rng);
    const int r_int = static_cast<int>(std::ceil(r));
    for (int dy = -r_int; dy <= r_int; ++dy) {
      for (int dx = -r_int; dx <= r_int; ++dx) {
        const float d2 = (dx + 0.5f) * (dx + 0.5f) + (dy + 0.5f) * (dy + 0.5f);
        if (d2 > r * r) continue;
        const float dome = top * std::sqrt(1.0f - d2 / (r * r));
        const int x = ((static_cast<int>(cx) + dx) % size + size) % size;
        const int y = ((static_cast<int>(cy) + dy) % size + size) % size;
        float& h = height[y * size + x];
        h = std::max(h, dome);
      }
    }
  }
  // Binder between the stones: low, slightly uneven.
  const std::vector<float> fine = value_noise(size, size / 8, rng);
  for (std::size_t i = 0; i < height.size(); ++i) height[i] = std::max(height[i], 0.12f * fine[i]);
  return height;
}

std::vector<float> setts_height_unit(int size, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  // 8 courses of 10 setts across the tile, each course offset by half a stone from the last; a
  // stone is a rounded block (its crown 0.7-1, worn flat in the middle, rounded to the joints),
  // a little out of square; sand in the joints.
  constexpr int kColumns = 8, kCourses = 10;
  const float w = static_cast<float>(size) / kColumns, l = static_cast<float>(size) / kCourses;
  std::vector<float> crown(kColumns * kCourses), tilt_x(kColumns * kCourses),
      tilt_y(kColumns * kCourses), shrink(kColumns * kCourses);
  for (std::size_t k = 0; k < crown.size(); ++k) {
    crown[k] = 0.7f + 0.3f * u(rng);
    tilt_x[k] = (u(rng) - 0.5f) * 0.3f;
    tilt_y[k] = (u(rng) - 0.5f) * 0.3f;
    shrink[k] = 0.8f + 0.12f * u(rng);
  }
  const std::vector<float> sand = value_noise(size, size / 8, rng);
  std::vector<float> height(static_cast<std::size_t>(size * size));
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const float fy = (static_cast<float>(y) + 0.5f) / l;
      const int course = static_cast<int>(fy);
      const float fx = (static_cast<float>(x) + 0.5f) / w + 0.5f * static_cast<float>(course & 1);
      const int column = static_cast<int>(fx) % kColumns;
      const std::size_t k = static_cast<std::size_t>(course % kCourses * kColumns + column);
      // Distance to the stone's edge, as a fraction of its half size (0 at its centre).
      const float ex = std::abs(fx - std::floor(fx) - 0.5f) * 2.0f / shrink[k];
      const float ey = std::abs(fy - std::floor(fy) - 0.5f) * 2.0f / shrink[k];
      const float e = std::max(ex, ey);
      float h = 0.08f + 0.1f * sand[static_cast<std::size_t>(y * size + x)];
      if (e < 1.0f) {
        const float round =
            std::sqrt(std::max(0.0f, 1.0f - std::pow(std::max(e - 0.35f, 0.0f) / 0.65f, 2.0f)));
        const float top = crown[k] * round + tilt_x[k] * (fx - std::floor(fx) - 0.5f) +
                          tilt_y[k] * (fy - std::floor(fy) - 0.5f);
        h = std::max(h, top);
      }
      height[static_cast<std::size_t>(y * size + x)] = std::clamp(h, 0.0f, 1.0f);
    }
  }
  return height;
}

Image8 relief_image(const std::vector<float>& height, int size, float relief_depth) {
  Image8 img{size, size, std::vector<std::uint8_t>(static_cast<std::size_t>(size * size * 4))};
  auto h = [&](int x, int y) { return height[((y + size) % size) * size + ((x + size) % size)]; };
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const glm::vec3 n =
          glm::normalize(glm::vec3((h(x - 1, y) - h(x + 1, y)) * relief_depth,
                                   (h(x, y - 1) - h(x, y + 1)) * relief_depth, 2.0f));
      std::uint8_t* p = &img.rgba[static_cast<std::size_t>(y * size + x) * 4];
      p[0] = to_byte(n.x * 0.5f + 0.5f);
      p[1] = to_byte(n.y * 0.5f + 0.5f);
      p[2] = to_byte(n.z * 0.5f + 0.5f);
      p[3] = to_byte(h(x, y));
    }
  }
  return img;
}

Image8 make_asphalt_relief(int size, std::uint32_t seed, float relief_depth) {
  return relief_image(asphalt_height_unit(size, seed), size, relief_depth);
}

Image8 make_noise(int size, std::uint32_t seed) {
  std::mt19937 rng(seed);
  Image8 img{size, size, std::vector<std::uint8_t>(static_cast<std::size_t>(size * size * 4))};
  const int cells[4] = {4, 8, 16, 32};
  for (int c = 0; c < 4; ++c) {
    const std::vector<float> n = value_noise(size, cells[c], rng);
    for (std::size_t i = 0; i < n.size(); ++i) img.rgba[i * 4 + c] = to_byte(n[i]);
  }
  return img;
}

}  // namespace downpour::render
