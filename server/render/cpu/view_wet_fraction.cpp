#include "server/render/cpu/view_wet_fraction.hpp"

#include "server/render/cpu/glass_view.hpp"
#include "server/sim/glass_water_surface.hpp"

namespace downpour::render {

double view_wet_fraction(const sim::ViewSpec& spec, const sim::SceneState& scene) {
  const sim::GlassWaterSurface* surface = scene.windshield.surface.get();
  if (spec.view != sim::View::kCockpit || spec.width <= 0 || spec.height <= 0 || !surface ||
      surface->cells.empty()) {
    return 0.0;
  }
  const GlassView glass(make_camera(spec, scene.vehicle, &scene.weather), scene.glass, spec.height);
  constexpr int kColumns = 64, kRows = 36;
  double wet = 0.0;
  for (int row = 0; row < kRows; ++row) {
    for (int col = 0; col < kColumns; ++col) {
      const auto uv =
          glass.hit((col + 0.5) / kColumns * 2.0 - 1.0, 1.0 - (row + 0.5) / kRows * 2.0);
      if (uv && scene.glass.contains(*uv) && surface->top_height(glm::vec2(*uv)) > 0.0f) wet += 1.0;
    }
  }
  return wet / (kColumns * kRows);
}

}  // namespace downpour::render
