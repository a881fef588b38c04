#include "server/render/pass.hpp"

#include <algorithm>
#include <stdexcept>

namespace downpour::render {

std::string_view resource_name(Resource r) {
  switch (r) {
    case Resource::kViewColour:
      return "view colour";
    case Resource::kViewDepth:
      return "view depth";
    case Resource::kGlassLayer:
      return "glass layer";
    case Resource::kGlassSurface:
      return "glass water surface";
    case Resource::kEnvironment:
      return "environment";
    case Resource::kRoadWater:
      return "road water";
    case Resource::kRoadReflection:
      return "road reflection";
    case Resource::kSprayLayer:
      return "spray layer";
  }
  return "?";
}

void check_pass_order(std::string_view view, const std::vector<Pass*>& passes) {
  // The frame provides these from its start (the simulation's, or drawn before the passes).
  const std::vector<Resource> provided = {Resource::kGlassSurface, Resource::kEnvironment,
                                          Resource::kRoadWater, Resource::kRoadReflection};
  std::vector<Resource> available = {Resource::kViewColour, Resource::kViewDepth};
  available.insert(available.end(), provided.begin(), provided.end());
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
    const bool to_view = std::all_of(d.writes.begin(), d.writes.end(), [](Resource r) {
      return r == Resource::kViewColour || r == Resource::kViewDepth;
    });
    if (d.writes.empty() || (!to_view && d.writes.size() != 1)) {
      throw std::logic_error(std::string(view) + " view, pass " + d.name +
                             ": must write one target");
    }
    for (Resource r : d.writes) {
      if (std::find(provided.begin(), provided.end(), r) != provided.end())
        fail(d, "cannot write", r);
      available.push_back(r);
    }
  }
}

}  // namespace downpour::render
