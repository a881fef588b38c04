// Hand-made water on the road for the render tests and the render-views tool: a window of water
// around the car as the simulation publishes it (sim::RoadWaterImage), built without minutes of
// simulated rain: a film of a given depth over the paved width, and round puddles placed in the
// car's frame.
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <glm/geometric.hpp>

#include "server/sim/pose.hpp"
#include "server/sim/road_water.hpp"
#include "server/sim/track.hpp"

namespace downpour::testing {

struct HandPuddle {
  double forward_m = 0.0;  // its centre in the car's frame (from the rear axle)
  double left_m = 0.0;
  double radius_m = 1.0;
  double depth_mm = 5.0;  // standing water at its centre; it shoals to the film at its rim
};

// The render tests' puddles: in the chase camera's sight behind and beside the car, and in the
// driver's ahead.
inline std::vector<HandPuddle> test_puddles() {
  return {
      {-3.5, 0.3, 1.6, 6.0}, {9.0, 0.8, 1.4, 5.0}, {16.0, -1.2, 2.2, 8.0}, {6.0, 3.2, 1.0, 4.0}};
}

// standing_mm of water over the texture (capacity_mm) on every paved cell of the rings around
// the car (0: a dry road), and the puddles on it. Each ring's cells take the water at their centre
// (those a finer ring holds too).
inline std::shared_ptr<const sim::RoadWaterImage> hand_road_water(
    const sim::VehicleState& car, double standing_mm, const std::vector<HandPuddle>& puddles = {},
    double capacity_mm = 0.5) {
  const sim::Track& track = sim::Track::built_in();
  auto image = std::make_shared<sim::RoadWaterImage>();
  const sim::RoadWaterConfig config;
  image->cell_m = config.cell_m;
  image->cells = config.cells;
  image->levels = config.levels;
  image->capacity_mm = capacity_mm;
  const glm::dvec2 car_xy(car.position_m);
  image->origins = sim::RoadWater::ring_origins(car_xy, config.cell_m, config.cells, config.levels);
  const glm::dmat4 to_world = sim::vehicle_to_world(car);
  std::vector<glm::dvec2> centres;
  for (const HandPuddle& p : puddles)
    centres.emplace_back(to_world * glm::dvec4(p.forward_m, p.left_m, 0.0, 1.0));
  const int n = image->cells;
  image->water_standing_mm.assign(static_cast<std::size_t>(image->levels) * n * n * 2, 0.0f);
  double sum = 0.0, sum_standing = 0.0;
  int paved = 0;
  const double s_car = track.project(car_xy, 40.0).s;
  for (int l = 0; l < image->levels; ++l) {
    const double cell = image->level_cell_m(l);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const glm::dvec2 xy = (glm::dvec2(image->origins[l] + glm::ivec2(i, j)) + 0.5) * cell;
        const sim::Track::Projection p = track.project_near(xy, s_car);
        // (As RoadWater::image: a cell beside the paved edge shows the road's water.)
        if (std::abs(p.lateral) > track.paved_half_width() + cell) continue;
        double standing = standing_mm;
        for (std::size_t k = 0; k < puddles.size(); ++k) {
          const double r = glm::length(xy - centres[k]) / puddles[k].radius_m;
          if (r < 1.0) standing = std::max(standing, puddles[k].depth_mm * (1.0 - r * r));
        }
        const double water = standing > 0.0 ? capacity_mm + standing : 0.0;
        const std::size_t c = (static_cast<std::size_t>(l) * n + j) * n + i;
        image->water_standing_mm[2 * c] = static_cast<float>(water);
        image->water_standing_mm[2 * c + 1] = static_cast<float>(standing);
        image->max_standing_mm = std::max(image->max_standing_mm, static_cast<float>(standing));
        if (l > 0) continue;
        sum += water;
        sum_standing += standing;
        ++paved;
      }
    }
  }
  image->mean_water_mm = paved > 0 ? static_cast<float>(sum / paved) : 0.0f;
  image->mean_standing_mm = paved > 0 ? static_cast<float>(sum_standing / paved) : 0.0f;
  return image;
}

}  // namespace downpour::testing
