// Which tiles of a driver's view the cabin hides wholly (the dashboard, the roof, the pillars and
// the mirror), found once per camera by rasterizing the cabin's mesh on the CPU at one sample per
// texel of the rain layer. The rain's composite leaves these tiles out: on llvmpipe a fragment that
// the depth test rejects still costs about half a drawn one. No GL.
#pragma once

#include <cstdint>
#include <vector>

#include "server/render/camera.hpp"
#include "server/render/mesh_data.hpp"

namespace downpour::render {

// Per tile of tile x tile texels of a width x height grid over the view (rows bottom-up, as GL's),
// 1 where every texel centre lies on the cabin's mesh (vehicle frame), else 0.
std::vector<std::uint8_t> cabin_tiles(const MeshData& cabin, const Camera& camera, int width,
                                      int height, int tile);

}  // namespace downpour::render
