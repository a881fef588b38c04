#include "server/render/pass.hpp"

#include <algorithm>
#include <array>
#include <iterator>
#include <stdexcept>

#include "server/render/cpu/shader_interface.hpp"

namespace downpour::render {

namespace {

constexpr std::array<float, 4> kClear{0.0f, 0.0f, 0.0f, 0.0f};
constexpr std::array<float, 4> kBlack{0.0f, 0.0f, 0.0f, 1.0f};

constexpr ResourceInfo kResources[] = {
    {Resource::kViewColour, "view colour", texture_unit::kViewColour, false, true, kNotTransient,
     false, kClear, 0.0f},
    {Resource::kViewDepth, "view depth", texture_unit::kViewDepth, false, true, kNotTransient,
     false, kClear, 0.0f},
    // Its depth: the nearest water (1, reversed-Z), for the mask.
    {Resource::kGlassLayer, "glass layer", texture_unit::kGlassLayer, false, false, kGlassLayerSize,
     true, kClear, 1.0f},
    // (Three texture buffers at their own units: RenderSession::Impl::upload_glass_surface.)
    {Resource::kGlassSurface, "glass water surface", 0, true, false, kNotTransient, false, kClear,
     0.0f},
    {Resource::kEnvironment, "environment", texture_unit::kEnvironment, true, false, kNotTransient,
     false, kClear, 0.0f},
    {Resource::kRoadWater, "road water", texture_unit::kRoadWater, true, false, kNotTransient,
     false, kClear, 0.0f},
    // Its depth: the far plane (0, reversed-Z), as a view's.
    {Resource::kRoadReflection, "road reflection", texture_unit::kReflection, true, false,
     kRoadReflectionScale, true, kBlack, 0.0f},
    {Resource::kSprayLayer, "spray layer", texture_unit::kSprayLayer, false, false,
     kSprayLayerScale, false, kClear, 0.0f},
    // (Its two rings are the lamp map's own targets.)
    {Resource::kLampMap, "lamp map", texture_unit::kLampMap, true, false, kNotTransient, false,
     kClear, 0.0f},
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
      if (resource_info(r).from_frame) fail(d, "cannot write", r);
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
