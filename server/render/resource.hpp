// The resources a frame's passes read and write (pass.hpp), and what the renderer knows of each, in
// one table (pass.cpp): where a pass finds it, whether the frame's start provides it, and how the
// renderer makes it where it is a transient.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace downpour::render {

enum class Resource : std::uint8_t {
  kViewColour,  // the view's colour target: cleared at the frame's start
  kViewDepth,   // its depth (reversed-Z): cleared at the frame's start
  kGlassLayer,  // the water on the glass over the scene, reduced size, premultiplied
  // The water's surface on the glass (sim::GlassWaterSurface), uploaded from the simulation on
  // first read.
  kGlassSurface,
  // The world outside the windshield as a cube map (environment_probe.hpp), the session's, which
  // the renderer refreshes before the view's passes where one reads it.
  kEnvironment,
  kRoadWater,  // the road's water around the car, uploaded from the simulation on first read
  // The scene mirrored in the road's plane with its depth, a quarter of the view: drawn by a frame
  // pass (road_reflection_pass.hpp) before the view's passes where one reads it and the road is
  // wet.
  kRoadReflection,
  kSprayLayer,  // the spray over the scene, a third of the view, premultiplied
  // The spray's liquid at the layer's size: the four depth maps (front and back of the body and
  // of the lone spray) and, as its depth, the mask of what a sphere hit (spray_pass.hpp).
  kSprayMaps,
  kSprayBodyFront,  // the body's front distance, smoothed (seed 001's screen-space surface)
  kSprayHaze,       // the clouds' optical depth, and times distance, at half the layer's size
  // The lamps' light on the ground around the camera (lamp_map.hpp): drawn by a frame pass
  // (lamp_map_pass.hpp) where the frame has lamps; read weighted by the frame block's lamp_map.x,
  // which is 0 where it was not drawn.
  kLampMap,
  // A client-background view's picture and its depth (sim::ClientImage), uploaded on first read
  // where new.
  kClientImage,
  // The road drawn at half the view's size with its depth (the road's own), for a composite to
  // bring into the view (road_pass.hpp): on a CPU rasterizer, where the road's shading is the
  // dearest of a chase view's passes.
  kRoadLayer,
};
inline constexpr std::size_t kResourceCount = 14;

inline constexpr int kNotTransient = -1;
inline constexpr int kGlassLayerSize = 0;
inline constexpr int kSprayLayerScale = 3;      // the spray layer: a third of the view each way
inline constexpr int kRoadReflectionScale = 4;  // the road reflection: a quarter
inline constexpr int kRoadLayerScale = 2;       // the road's layer: half

inline constexpr int kSprayHazeOverLayer = 2;  // the spray's haze: half the layer each way

// A transient's colour format.
enum class Format : std::uint8_t { kRgba8, kRgba32f, kR32f, kRg32f };

// What the renderer knows of each resource, in one table (pass.cpp).
struct ResourceInfo {
  Resource resource;
  std::string_view name;
  unsigned texture_unit = 0;  // where a pass that reads it finds it (shader_interface.hpp)
  // There from the frame's start: the simulation's, uploaded on first read, or drawn by a frame
  // pass before the view's passes. Only a frame pass writes one.
  bool from_frame = false;
  bool view_target = false;  // the view's own colour or depth
  // A transient, made by the renderer for the passes that write it and kept by size
  // (render_targets.hpp): its size is the view's over `scale` each way, or the glass layer's own
  // (GlassView::layer_size) for kGlassLayerSize; kNotTransient for the rest.
  int scale = kNotTransient;
  Format format = Format::kRgba8;
  bool linear = true;  // read with bilinear filtering, else the nearest texel
  // The depth attached to a transient's framebuffer: its own (this resource), another
  // transient's of the same size (the spray's mask, for the tests against it), or none.
  std::optional<Resource> depth_from = std::nullopt;
  // What a transient holds before the first pass of a frame draws into it (its own depth too).
  std::array<float, 4> clear_colour = {0.0f, 0.0f, 0.0f, 0.0f};
  float clear_depth = 0.0f;
};
const ResourceInfo& resource_info(Resource resource);
inline std::string_view resource_name(Resource resource) { return resource_info(resource).name; }

}  // namespace downpour::render
