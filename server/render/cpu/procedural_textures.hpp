// Textures made on the CPU at start-up, deterministic, tileable. No GL.
#pragma once

#include <cstdint>
#include <vector>

namespace downpour::render {

struct Image8 {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;  // 4 bytes a pixel, rows top-down
};

// Asphalt micro-relief (seed 003, section 3.1): an 8-bit height field of packed aggregate in a
// darker binder, in alpha; its normals (relief scale relief_depth texels per unit height) in rgb.
Image8 make_asphalt_relief(int size, std::uint32_t seed, float relief_depth = 3.0f);
// Its heights alone, in [0, 1] (relief.hpp gives them metres).
std::vector<float> asphalt_height_unit(int size, std::uint32_t seed);
// Stone setts of a cobbled shoulder: 8 x 10 rounded blocks a tile, in courses offset by half a
// stone, sand in the joints; heights in [0, 1].
std::vector<float> setts_height_unit(int size, std::uint32_t seed);
// Heights in [0, 1] in alpha, their normals (relief_depth texels per unit height) in rgb.
Image8 relief_image(const std::vector<float>& height, int size, float relief_depth);

// Tileable value noise with a different frequency in each channel (4, 8, 16, 32 cells). Only the
// terrain's grain (alpha) is still fetched: the shaders compute their coarser noise
// (common.glsl's value_noise). The other channels stay, drawn first from the same generator, so
// that the grain keeps its pattern.
Image8 make_noise(int size, std::uint32_t seed);

}  // namespace downpour::render
