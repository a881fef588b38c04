#include "server/sim/rain_arrival.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/geometric.hpp>

#include "server/sim/drop_physics.hpp"
#include "server/sim/water_inputs.hpp"

namespace downpour::sim {
namespace {

constexpr double kN0 = 8000.0;  // Marshall-Palmer, m^-3 mm^-1
constexpr int kRainBins = 24;   // drop-size bins for the impact rate

}  // namespace

RainArrival::RainArrival(const WindshieldConfig& config, std::uint64_t seed)
    : config_(config), random_(seed, 1) {}

// Impacts per second = sum over drop sizes of number density x speed through the glass x area,
// Marshall-Palmer sizes.
void RainArrival::step(double dt, const WaterInputs& in,
                       const std::function<void(glm::dvec2, double)>& land) {
  const WaterConfig& w = config_.water;
  const GlassConfig& g = config_.glass;
  if (in.rain_rate_mm_h <= 0.0) return;
  const double lambda = 4.1 * std::pow(in.rain_rate_mm_h, -0.21);
  const double area_m2 = 0.5 * (g.bottom_width_mm + g.top_width_mm) * g.height_mm * 1e-6;
  const glm::dvec3 n = g.normal();
  const double bin = (w.max_drop_diameter_mm - w.min_drop_diameter_mm) / kRainBins;
  std::array<double, kRainBins> cumulative{};
  double total = 0.0;
  for (int k = 0; k < kRainBins; ++k) {
    const double d = w.min_drop_diameter_mm + (k + 0.5) * bin;
    const glm::dvec3 velocity = in.air_velocity_mps - glm::dvec3(0.0, 0.0, terminal_speed_mps(d));
    const double flux = std::max(0.0, -glm::dot(velocity, n));  // m/s into the glass
    total += kN0 * std::exp(-lambda * d) * bin * flux * area_m2;
    cumulative[k] = total;
  }
  const std::uint32_t impacts = random_.poisson(total * dt);
  for (std::uint32_t i = 0; i < impacts; ++i) {
    const double pick = random_.uniform() * total;
    const int k = static_cast<int>(std::lower_bound(cumulative.begin(), cumulative.end(), pick) -
                                   cumulative.begin());
    const double d =
        w.min_drop_diameter_mm + (std::min(k, kRainBins - 1) + random_.uniform()) * bin;
    glm::dvec2 pos;
    do {
      pos = {random_.uniform(0.0, g.bottom_width_mm), random_.uniform(0.0, g.height_mm)};
    } while (!g.contains(pos));
    land(pos, M_PI / 6.0 * d * d * d);
  }
}

}  // namespace downpour::sim
