#include "server/render/view_wet_fraction.hpp"

#include "server/render/glass_rays.hpp"

namespace downpour::render {

double view_wet_fraction(const sim::ViewSpec& spec, const sim::SceneState& scene) {
  const sim::WindshieldState& water = scene.windshield;
  if (spec.view != sim::View::kCockpit || spec.width <= 0 || spec.height <= 0) return 0.0;
  if (water.coverage_width <= 0 || water.coverage_height <= 0 || water.coverage_cell_mm <= 0.0 ||
      water.coverage.size() <
          static_cast<std::size_t>(water.coverage_width) * water.coverage_height) {
    return 0.0;
  }
  const GlassRays rays(spec, scene.glass);
  constexpr int kColumns = 64, kRows = 36;
  double wet = 0.0;
  for (int row = 0; row < kRows; ++row) {
    for (int col = 0; col < kColumns; ++col) {
      const auto uv = rays.hit((col + 0.5) / kColumns * 2.0 - 1.0, 1.0 - (row + 0.5) / kRows * 2.0);
      if (!uv || !scene.glass.contains(*uv)) continue;
      const int x = static_cast<int>(uv->x / water.coverage_cell_mm);
      const int y = static_cast<int>(uv->y / water.coverage_cell_mm);
      if (x < 0 || y < 0 || x >= water.coverage_width || y >= water.coverage_height) continue;
      wet += water.coverage[static_cast<std::size_t>(y) * water.coverage_width + x] / 255.0;
    }
  }
  return wet / (kColumns * kRows);
}

}  // namespace downpour::render
