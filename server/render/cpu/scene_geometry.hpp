// The static world built once for a road network: road surface, terrain and street lights, split
// into chunks that the passes cull against the camera's view. No GL.
#pragma once

#include <vector>

#include "server/model/mesh_data.hpp"
#include "server/sim/lights.hpp"
#include "server/sim/road_network.hpp"

namespace downpour::render {

// Chunks of up to 120 m of a lane section, each at three levels of detail (cross-sections every 2,
// 8 and 24 m): uv = (t, s) on its road (lateral offset left positive, and along, in metres); a
// column of vertices at every lane border, each with its strip's width, kind and marks
// (VertexLane; no marks on a junction's connecting roads); a verge beyond each paved edge,
// rounding down from it, unless another road's pavement lies there.
std::vector<std::vector<MeshData>> build_road_chunks(const sim::RoadNetwork& roads);

// The ground around the roads: around the built-in track gentle hills, around a simulator's roads
// level fields a little below the nearest road; both rising to a ring of higher ground far out.
// The ground meets the road a little below its edge. uv = world xy in metres. 16 x 16 chunks, each
// at four levels of detail (cells of 20, 40, 80 and 160 m over the same grid) with skirts that hide
// the cracks between neighbours drawn at different levels.
SkirtedChunks build_terrain_chunks(const sim::RoadNetwork& roads);

// The street lights' meshes (street_light_pass.hpp), four poles a chunk (one level of detail).
std::vector<std::vector<MeshData>> build_street_light_chunks(
    const std::vector<sim::StreetLight>& lights);

// Terrain height at a world position (also used by tests and scenery placement).
double terrain_height(const sim::RoadNetwork& roads, double x, double y);

}  // namespace downpour::render
