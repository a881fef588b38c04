// What the renderer draws of the roads a session drives on, built on the CPU (no GL): where a
// session's network is loaded (prepare_world, on the request's thread), so that the render loop
// (world.hpp) only uploads it.
#pragma once

#include <memory>
#include <vector>

#include "server/model/mesh_data.hpp"
#include "server/sim/lights.hpp"
#include "server/sim/road_network.hpp"

namespace downpour::render {

struct WorldGeometry {
  std::vector<sim::StreetLight> street_lights;  // sim/lights.hpp
  std::vector<std::vector<MeshData>> road, poles;
  SkirtedChunks terrain;
  double build_ms = 0.0;
};
WorldGeometry build_world_geometry(const sim::RoadNetwork& roads);
// Builds a network's geometry ahead of its first frame (once; thread-safe). Kept until the
// renderer takes it, or the network goes.
void prepare_world(const std::shared_ptr<const sim::RoadNetwork>& roads);
// The geometry prepared for a network, taken by the render thread when it first draws the network
// (thread-safe); null where none was prepared. Marks the network's world as made, so that a later
// session on it prepares nothing, until the network goes.
std::shared_ptr<const WorldGeometry> take_prepared_world(
    const std::shared_ptr<const sim::RoadNetwork>& roads);

}  // namespace downpour::render
