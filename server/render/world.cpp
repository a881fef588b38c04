#include "server/render/world.hpp"

#include <algorithm>
#include <chrono>

#include <spdlog/spdlog.h>

namespace downpour::render {

World make_world(const WorldGeometry& g) {
  World w;
  w.street_lights = g.street_lights;
  w.road = ChunkedMesh(g.road, {150.0f, 500.0f});
  w.terrain = ChunkedMesh(g.terrain, {200.0f, 500.0f, 1200.0f});
  w.street_light_poles = ChunkedMesh(g.poles, {}, kStreetLightsDrawnWithin_m);
  return w;
}

const World& Worlds::get(const std::shared_ptr<const sim::RoadNetwork>& given) {
  const std::shared_ptr<const sim::RoadNetwork>& roads = given ? given : sim::built_in_roads();
  // A network no session holds any more (the built-in one is held for good).
  std::erase_if(entries_, [](const Entry& e) { return e.roads.expired(); });
  for (const Entry& e : entries_) {
    if (e.key == roads.get()) return *e.world;
  }
  // Prepared where the network was loaded, or built here (hand-made scenes, the built-in track).
  std::shared_ptr<const WorldGeometry> geometry = take_prepared_world(roads);
  const auto t0 = std::chrono::steady_clock::now();
  const bool built_here = !geometry;
  if (built_here) geometry = std::make_shared<const WorldGeometry>(build_world_geometry(*roads));
  // (The world holds no reference to the network, so that it can go with its last session.)
  auto world = std::make_unique<World>(make_world(*geometry));
  spdlog::debug(
      "road network of {} roads drawn: geometry {:.0f} ms ({}), upload {:.0f} ms",
      roads->road_count(), geometry->build_ms, built_here ? "here" : "prepared",
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() -
          (built_here ? geometry->build_ms : 0.0));
  entries_.push_back({roads, roads.get(), std::move(world)});
  return *entries_.back().world;
}

}  // namespace downpour::render
