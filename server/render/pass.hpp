// A render pass declared in one place: its name, what it reads and writes (by Resource), its GL
// state and its draw code. A view is a list of passes (data, in renderer.cpp); the renderer binds
// each pass's target and inputs, applies its state, and checks at start-up that every pass reads
// only what the frame provides or an earlier pass of the view wrote.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "server/render/frame_context.hpp"
#include "server/render/gl/render_state.hpp"

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
  // The scene mirrored in the road's plane with its depth, a quarter of the view: the renderer
  // draws it before the view's passes where one reads it and the road is wet.
  kRoadReflection,
  kSprayLayer,  // the spray over the scene, half the view, premultiplied
};
inline constexpr std::size_t kResourceCount = 8;

// What the renderer knows of each resource, in one table (pass.cpp).
struct ResourceInfo {
  Resource resource;
  std::string_view name;
  unsigned texture_unit;  // where a pass that reads it finds it (shader_interface.hpp)
  bool from_frame;        // there from the frame's start (the simulation's, or drawn before)
  bool view_target;       // the view's own colour or depth
};
const ResourceInfo& resource_info(Resource resource);
inline std::string_view resource_name(Resource resource) { return resource_info(resource).name; }

struct PassDecl {
  std::string name;
  std::vector<Resource> reads;   // bound to their texture units before the pass runs
  std::vector<Resource> writes;  // one target: the view (colour and/or depth), or a transient
  RenderState state;
  bool reads_step = false;  // calls FrameContext::water() or rain(): the state after the step
};

class Pass {
 public:
  virtual ~Pass() = default;
  virtual const PassDecl& decl() const = 0;
  // Nothing to draw this frame (clear glass) skips the pass and its target's preparation.
  virtual bool wanted(const FrameContext&) const { return true; }
  virtual void execute(const FrameContext& frame, const FrameResources& resources) = 0;
};

// Throws std::logic_error naming the pass and the resource where a pass of `view` reads what
// neither the frame's start nor an earlier pass provides, or writes more than one target.
void check_pass_order(std::string_view view, const std::vector<Pass*>& passes);

}  // namespace downpour::render
