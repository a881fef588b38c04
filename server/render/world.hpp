// What the renderer draws of the roads a session drives on (sim/road_network.hpp): the road and
// its verges, the terrain around, and the street lights. Made once for each road network, the
// first time a frame shows it (from geometry prepared where the network was loaded, if it was),
// and dropped once no session holds the network any more.
#pragma once

#include <memory>
#include <vector>

#include "server/render/chunked_mesh.hpp"
#include "server/render/gl_objects.hpp"
#include "server/render/mesh_data.hpp"
#include "server/sim/lights.hpp"
#include "server/sim/road_network.hpp"

namespace downpour::render {

// What is built of a network on the CPU (no GL): where a session's network is loaded
// (prepare_world, on the request's thread), so that the render loop only uploads it.
struct WorldGeometry {
  std::vector<sim::StreetLight> street_lights;  // sim/lights.hpp
  std::vector<std::vector<MeshData>> road, terrain, poles;
  double build_ms = 0.0;
};
WorldGeometry build_world_geometry(const sim::RoadNetwork& roads);
// Builds a network's geometry ahead of its first frame (once; thread-safe). Kept until the
// renderer takes it, or the network goes.
void prepare_world(const std::shared_ptr<const sim::RoadNetwork>& roads);

struct World {
  std::vector<sim::StreetLight> street_lights;  // sim/lights.hpp
  ChunkedMesh road;
  ChunkedMesh terrain;
  ChunkedMesh street_light_poles;
};

World make_world(const WorldGeometry& geometry);  // on the GL thread

class Worlds {
 public:
  // The world of a network (null: the built-in track's), made on first use.
  const World& get(const std::shared_ptr<const sim::RoadNetwork>& roads);
  std::size_t size() const { return entries_.size(); }

 private:
  struct Entry {
    std::weak_ptr<const sim::RoadNetwork> roads;
    const sim::RoadNetwork* key = nullptr;
    std::unique_ptr<World> world;
  };
  std::vector<Entry> entries_;
};

}  // namespace downpour::render
