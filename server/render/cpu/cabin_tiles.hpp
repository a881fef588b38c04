// Which tiles of a driver's view the cabin hides wholly (the dashboard, the roof, the pillars and
// the mirror), which it reaches into and which it leaves clear, found once per camera by
// rasterizing the cabin's mesh on the CPU at one sample per texel of the rain layer. The rain's
// composite leaves the hidden tiles out (on llvmpipe a fragment that the depth test rejects still
// costs about half a drawn one) and depth-tests only the edge tiles. No GL.
#pragma once

#include <cstdint>
#include <vector>

#include "server/model/mesh_data.hpp"
#include "server/render/cpu/camera.hpp"

namespace downpour::render {

// What the cabin does to a tile of the view.
enum CabinTile : std::uint8_t {
  kCabinClear = 0,   // no texel centre of the tile, or of the texels around it, lies on the cabin
  kCabinHidden = 1,  // every texel centre of the tile lies on it
  kCabinEdge = 2,    // some do
};

// Per tile of tile x tile texels of a width x height grid over the view (rows bottom-up, as GL's),
// what the cabin's mesh (vehicle frame) does to it (CabinTile). A tile is an edge one if the cabin
// covers a texel centre within a texel of it, so that a pixel of the cabin between texel centres
// is not taken for clear (a part of the cabin thinner than two texels may still be).
std::vector<std::uint8_t> cabin_tiles(const MeshData& cabin, const Camera& camera, int width,
                                      int height, int tile);

}  // namespace downpour::render
