// The static world built once from the track: road surface and terrain, split into chunks that
// the passes cull against the camera's view. No GL.
#pragma once

#include <vector>

#include "server/render/mesh_data.hpp"
#include "server/sim/track.hpp"

namespace downpour::render {

// Road mesh chunks of 120 m, each at three levels of detail (cross-sections every 2, 8 and 24 m):
// uv = (lateral offset in metres, left positive; distance along the track in metres). The
// cross-section is crowned, with a sloping verge beyond the shoulders.
std::vector<std::vector<MeshData>> build_road_chunks(const sim::Track& track);

// Gentle hills around the track, rising to a ring of higher ground far out; the ground meets the
// road a little below its edge. uv = world xy in metres. 8 x 8 chunks, each at four levels of
// detail (cells of 20, 40, 80 and 160 m over the same grid) with skirts that hide the cracks
// between neighbours drawn at different levels.
std::vector<std::vector<MeshData>> build_terrain_chunks(const sim::Track& track);

// Terrain height at a world position (also used by tests and scenery placement).
double terrain_height(const sim::Track& track, double x, double y);

}  // namespace downpour::render
