#include "server/render/pass.hpp"

#include <algorithm>
#include <array>
#include <iterator>
#include <stdexcept>

#include "server/render/cpu/shader_interface.hpp"

namespace downpour::render {

namespace {

using R = Resource;
constexpr float kFar = 1.0e6f;  // kSprayFar (cpu/spray_splat.hpp)

constexpr ResourceInfo kResources[] = {
    {.resource = R::kViewColour,
     .name = "view colour",
     .texture_unit = texture_unit::kViewColour,
     .view_target = true},
    {.resource = R::kViewDepth,
     .name = "view depth",
     .texture_unit = texture_unit::kViewDepth,
     .view_target = true},
    // Its depth: the nearest water (1, reversed-Z), for the mask.
    {.resource = R::kGlassLayer,
     .name = "glass layer",
     .texture_unit = texture_unit::kGlassLayer,
     .scale = kGlassLayerSize,
     .depth_from = R::kGlassLayer,
     .clear_depth = 1.0f},
    // (Three texture buffers at their own units: RenderSession::Impl::upload_glass_surface.)
    {.resource = R::kGlassSurface, .name = "glass water surface", .from_frame = true},
    {.resource = R::kEnvironment,
     .name = "environment",
     .texture_unit = texture_unit::kEnvironment,
     .from_frame = true},
    {.resource = R::kRoadWater,
     .name = "road water",
     .texture_unit = texture_unit::kRoadWater,
     .from_frame = true},
    // Black where nothing is mirrored; its depth the far plane (0, reversed-Z), as a view's.
    {.resource = R::kRoadReflection,
     .name = "road reflection",
     .texture_unit = texture_unit::kReflection,
     .from_frame = true,
     .scale = kRoadReflectionScale,
     .depth_from = R::kRoadReflection,
     .clear_colour = {0.0f, 0.0f, 0.0f, 1.0f}},
    // Its depth: the spray's mask, so that the liquid's colour is shaded only where a sphere hit.
    {.resource = R::kSprayLayer,
     .name = "spray layer",
     .texture_unit = texture_unit::kSprayLayer,
     .scale = kSprayLayerScale,
     .depth_from = R::kSprayMaps},
    // Nothing anywhere (kFar), and the mask's depth 0: no sphere hit.
    {.resource = R::kSprayMaps,
     .name = "spray depth maps",
     .texture_unit = texture_unit::kSprayDepth,
     .scale = kSprayLayerScale,
     .format = Format::kRgba32f,
     .linear = false,
     .depth_from = R::kSprayMaps,
     .clear_colour = {kFar, kFar, kFar, kFar}},
    // Smoothed where the mask holds the body, against it.
    {.resource = R::kSprayBodyFront,
     .name = "spray body front",
     .texture_unit = texture_unit::kSpraySmooth,
     .scale = kSprayLayerScale,
     .format = Format::kR32f,
     .linear = false,
     .depth_from = R::kSprayMaps,
     .clear_colour = {kFar, kFar, kFar, kFar}},
    {.resource = R::kSprayHaze,
     .name = "spray haze",
     .texture_unit = texture_unit::kSprayHaze,
     .scale = kSprayHazeOverLayer * kSprayLayerScale,
     .format = Format::kRg32f},
    // (Its two rings are the lamp map's own targets.)
    {.resource = R::kLampMap,
     .name = "lamp map",
     .texture_unit = texture_unit::kLampMap,
     .from_frame = true},
    // (Its depth at its own unit: RenderSession::Impl::upload_client_image.)
    {.resource = R::kClientImage,
     .name = "client image",
     .texture_unit = texture_unit::kClientImage,
     .from_frame = true},
    // Alpha 0 where no road is; a depth of its own, for the layer's own draws.
    {.resource = R::kRoadLayer,
     .name = "road layer",
     .texture_unit = texture_unit::kRoadLayer,
     .scale = kRoadLayerScale,
     .depth_from = R::kRoadLayer},
};
static_assert(std::size(kResources) == kResourceCount);
constexpr bool in_order() {
  for (std::size_t i = 0; i < kResourceCount; ++i) {
    if (static_cast<std::size_t>(kResources[i].resource) != i) return false;
  }
  return true;
}
static_assert(in_order(), "kResources follows Resource's order");

}  // namespace

const ResourceInfo& resource_info(Resource r) {
  return kResources[std::min(static_cast<std::size_t>(r), kResourceCount - 1)];
}

void check_pass_order(std::string_view view, const std::vector<Pass*>& passes) {
  // The view's targets, and what the frame provides from its start.
  std::vector<Resource> available;
  for (const ResourceInfo& info : kResources) {
    if (info.view_target || info.from_frame) available.push_back(info.resource);
  }
  auto fail = [&](const PassDecl& d, std::string_view what, Resource r) {
    throw std::logic_error(std::string(view) + " view, pass " + d.name + ": " + std::string(what) +
                           " " + std::string(resource_name(r)));
  };
  for (const Pass* pass : passes) {
    const PassDecl& d = pass->decl();
    for (Resource r : d.reads) {
      if (std::find(available.begin(), available.end(), r) == available.end())
        fail(d, "reads before anything writes", r);
    }
    const bool to_view = std::all_of(d.writes.begin(), d.writes.end(),
                                     [](Resource r) { return resource_info(r).view_target; });
    if (d.writes.empty() || (!to_view && d.writes.size() != 1)) {
      throw std::logic_error(std::string(view) + " view, pass " + d.name +
                             ": must write one target");
    }
    for (Resource r : d.writes) {
      const ResourceInfo& info = resource_info(r);
      if (info.from_frame) fail(d, "cannot write", r);
      // A target drawn against another's depth (the spray's mask) comes after that one's pass.
      if (info.depth_from && *info.depth_from != r &&
          std::find(available.begin(), available.end(), *info.depth_from) == available.end())
        fail(d, "draws against the depth of what no pass wrote yet:", *info.depth_from);
      available.push_back(r);
    }
  }
}

void check_frame_pass(const Pass& pass) {
  const PassDecl& d = pass.decl();
  auto fail = [&](std::string_view what) {
    throw std::logic_error("frame pass " + d.name + ": " + std::string(what));
  };
  if (d.writes.size() != 1 || !resource_info(d.writes.front()).from_frame)
    fail("must write one resource of the frame's start");
  for (Resource r : d.reads) {
    if (!resource_info(r).from_frame || r == d.writes.front())
      fail("reads " + std::string(resource_name(r)) + ", which is not there before it");
  }
}

}  // namespace downpour::render
