#include "server/render/world.hpp"

#include <algorithm>
#include <chrono>

#include <spdlog/spdlog.h>

namespace downpour::render {

World make_world(const WorldGeometry& g) {
  World w;
  w.street_lights = g.street_lights;
  // The road's rows every 8 m from 120 m (at the scale of COCKPIT's 720 rows): where a 300 m
  // curve's 8 m chords, 3 cm off the arc, are a fifth of a pixel. The road's far part in a chase
  // view (road_pass.hpp) starts where a layer's texel spans 10 cm: at its four times nearer
  // levels that is 125 at every size (17.3 m at 640x360), so the chunk under its camera is drawn
  // there with 8 m rows (ChunkedMesh::draw_visible's level_from_m).
  w.road = ChunkedMesh(g.road, {120.0f, 500.0f});
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
