#include "server/render/view_wet_fraction.hpp"

#include "server/render/glass_view.hpp"

namespace downpour::render {

double view_wet_fraction(const sim::ViewSpec& spec, const sim::SceneState& scene) {
  const sim::GlassWaterMap& map = scene.windshield.map;
  if (spec.view != sim::View::kCockpit || spec.width <= 0 || spec.height <= 0 || map.width <= 0 ||
      map.rgba.size() < static_cast<std::size_t>(map.width) * map.height * 4) {
    return 0.0;
  }
  const GlassView glass(make_camera(spec, scene.vehicle, &scene.weather), scene.glass, spec.height);
  constexpr int kColumns = 64, kRows = 36;
  double wet = 0.0;
  for (int row = 0; row < kRows; ++row) {
    for (int col = 0; col < kColumns; ++col) {
      const auto uv =
          glass.hit((col + 0.5) / kColumns * 2.0 - 1.0, 1.0 - (row + 0.5) / kRows * 2.0);
      if (uv && scene.glass.contains(*uv)) wet += map.coverage_at(*uv);
    }
  }
  return wet / (kColumns * kRows);
}

}  // namespace downpour::render
