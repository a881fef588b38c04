#include "server/render/world.hpp"

#include <algorithm>
#include <chrono>

#include "server/render/passes/street_light_pass.hpp"
#include "server/render/scene_geometry.hpp"

namespace downpour::render {

World make_world(const sim::RoadNetwork& roads) {
  const auto t0 = std::chrono::steady_clock::now();
  World w;
  w.street_lights = sim::street_lights(roads);
  w.road = ChunkedMesh(build_road_chunks(roads), {150.0f, 500.0f});
  w.terrain = ChunkedMesh(build_terrain_chunks(roads), {200.0f, 500.0f, 1200.0f});
  w.street_light_poles =
      ChunkedMesh(build_street_light_chunks(w.street_lights), {}, kStreetLightsDrawnWithin_m);
  w.build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return w;
}

const World& Worlds::get(const std::shared_ptr<const sim::RoadNetwork>& given) {
  const std::shared_ptr<const sim::RoadNetwork>& roads = given ? given : sim::built_in_roads();
  // A network no session holds any more (the built-in one is held for good).
  std::erase_if(entries_, [](const Entry& e) { return e.roads.expired(); });
  for (const Entry& e : entries_) {
    if (e.key == roads.get()) return *e.world;
  }
  // (The world holds no reference to the network, so that it can go with its last session.)
  auto world = std::make_unique<World>(make_world(*roads));
  entries_.push_back({roads, roads.get(), std::move(world)});
  return *entries_.back().world;
}

}  // namespace downpour::render
