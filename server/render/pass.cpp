#include "server/render/pass.hpp"

#include <algorithm>
#include <iterator>
#include <stdexcept>

#include "server/render/cpu/shader_interface.hpp"

namespace downpour::render {

namespace {

constexpr ResourceInfo kResources[] = {
    {Resource::kViewColour, "view colour", texture_unit::kViewColour, false, true},
    {Resource::kViewDepth, "view depth", texture_unit::kViewDepth, false, true},
    {Resource::kGlassLayer, "glass layer", texture_unit::kGlassLayer, false, false},
    // (Three texture buffers at their own units: upload_glass_surface.)
    {Resource::kGlassSurface, "glass water surface", 0, true, false},
    {Resource::kEnvironment, "environment", texture_unit::kEnvironment, true, false},
    {Resource::kRoadWater, "road water", texture_unit::kRoadWater, true, false},
    {Resource::kRoadReflection, "road reflection", texture_unit::kReflection, true, false},
    {Resource::kSprayLayer, "spray layer", texture_unit::kSprayLayer, false, false},
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

}  // namespace downpour::render
