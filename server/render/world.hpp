// What the renderer draws of the roads a session drives on (sim/road_network.hpp): the road and
// its verges, the terrain around, and the street lights. Made once for
// each road network on the render thread, the first time a frame shows it, and dropped once no
// session holds the network any more.
#pragma once

#include <memory>
#include <vector>

#include "server/render/chunked_mesh.hpp"
#include "server/render/gl_objects.hpp"
#include "server/sim/lights.hpp"
#include "server/sim/road_network.hpp"

namespace downpour::render {

struct World {
  std::vector<sim::StreetLight> street_lights;  // sim/lights.hpp
  ChunkedMesh road;
  ChunkedMesh terrain;
  ChunkedMesh street_light_poles;
  double build_ms = 0.0;
};

World make_world(const sim::RoadNetwork& roads);

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
