#include "server/sim/types.hpp"

namespace downpour::sim {

void Update::merge_from(const Update& later) {
  client_time_s = later.client_time_s;
  if (later.vehicle) vehicle = later.vehicle;
  if (later.wipers) wipers = later.wipers;
  if (later.weather) weather = later.weather;
  if (later.traffic) traffic = later.traffic;
  for (int v = 0; v < kViewCount; ++v) {
    if (later.client_images[v]) client_images[v] = later.client_images[v];
  }
}

std::string_view view_name(View view) {
  switch (view) {
    case View::kCockpit:
      return "COCKPIT";
    case View::kRoad:
      return "ROAD";
    case View::kWindshield:
      return "WINDSHIELD";
    case View::kRain:
      return "RAIN";
  }
  return "UNKNOWN";
}

ViewSpec view_spec(View view, int width, int height, std::optional<CameraPose> camera) {
  ViewSpec spec;
  spec.view = view;
  spec.width = width;
  spec.height = height;
  spec.camera = std::move(camera);
  return spec;
}

}  // namespace downpour::sim
