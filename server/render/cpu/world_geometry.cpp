#include "server/render/cpu/world_geometry.hpp"

#include <chrono>
#include <map>
#include <mutex>

#include "server/render/cpu/scene_geometry.hpp"

namespace downpour::render {

namespace {

// Geometry prepared ahead of its first frame, by network, until the render thread takes it; then
// null, marking the network's world as made (a later session on it prepares nothing), until the
// network goes.
struct Prepared {
  std::mutex mutex;
  std::map<const sim::RoadNetwork*,
           std::pair<std::weak_ptr<const sim::RoadNetwork>, std::shared_ptr<const WorldGeometry>>>
      worlds;
  void drop_expired() {
    std::erase_if(worlds, [](const auto& e) { return e.second.first.expired(); });
  }
};
Prepared& prepared() {
  static Prepared p;
  return p;
}

}  // namespace

WorldGeometry build_world_geometry(const sim::RoadNetwork& roads) {
  const auto t0 = std::chrono::steady_clock::now();
  WorldGeometry g;
  g.street_lights = sim::street_lights(roads);
  g.road = build_road_chunks(roads);
  g.terrain = build_terrain_chunks(roads);
  g.poles = build_street_light_chunks(g.street_lights);
  g.build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return g;
}

void prepare_world(const std::shared_ptr<const sim::RoadNetwork>& roads) {
  if (!roads || roads == sim::built_in_roads()) return;
  {
    std::lock_guard lock(prepared().mutex);
    prepared().drop_expired();
    if (prepared().worlds.count(roads.get())) return;
  }
  auto geometry = std::make_shared<const WorldGeometry>(build_world_geometry(*roads));
  std::lock_guard lock(prepared().mutex);
  prepared().worlds.emplace(roads.get(), std::make_pair(roads, std::move(geometry)));
}

std::shared_ptr<const WorldGeometry> take_prepared_world(
    const std::shared_ptr<const sim::RoadNetwork>& roads) {
  std::lock_guard lock(prepared().mutex);
  prepared().drop_expired();
  auto it = prepared().worlds.find(roads.get());
  if (it == prepared().worlds.end())
    it = prepared().worlds.emplace(roads.get(), std::make_pair(roads, nullptr)).first;
  std::shared_ptr<const WorldGeometry> geometry = std::move(it->second.second);
  it->second.second.reset();
  return geometry;
}

}  // namespace downpour::render
