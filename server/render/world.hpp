// What the renderer draws of the roads a session drives on (sim/road_network.hpp): the road and
// its verges, the terrain around, and the street lights, uploaded. Made once for each road
// network, the first time a frame shows it (from geometry prepared where the network was loaded,
// if it was: world_geometry.hpp), and dropped once no session holds the network any more.
#pragma once

#include <memory>
#include <vector>

#include "server/render/chunked_mesh.hpp"
#include "server/render/cpu/world_geometry.hpp"
#include "server/render/gl/gl_objects.hpp"

namespace downpour::render {

// Street lights farther than this are not drawn (a pole there is a fifth of a pixel wide at 1280 x
// 720; at night the lamp_glow pass still draws its lens), over the frame's detail distance scale
// (350 m at 640 x 360).
inline constexpr float kStreetLightsDrawnWithin_m = 700.0f;

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
