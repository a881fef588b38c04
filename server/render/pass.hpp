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
#include "server/render/resource.hpp"

namespace downpour::render {

// One step of a pass that draws under more than one state: its name and state.
struct PassStep {
  std::string_view name;
  RenderState state;
};

struct PassDecl {
  std::string name;
  std::vector<Resource> reads;   // bound to their texture units before the pass runs
  std::vector<Resource> writes;  // one target: the view (colour and/or depth), or a transient
  RenderState state;             // applied before the pass runs
  bool reads_step = false;       // calls FrameContext::water(): the state after the step (rain()
                                 // waits for it only before any rain is published)
  // Every other state the pass draws under, in the order it draws them (Pass::apply_step).
  std::vector<PassStep> steps = {};
};

class Pass {
 public:
  virtual ~Pass() = default;
  virtual const PassDecl& decl() const = 0;
  // Nothing to draw this frame (clear glass) skips the pass and its target's preparation.
  virtual bool wanted(const FrameContext&) const { return true; }
  virtual void execute(const FrameContext& frame, const FrameResources& resources) = 0;
  // The pass writes every texel of its transient that a later pass reads (the CPU's uploads): the
  // renderer does not clear it first.
  virtual bool overwrites_target(const FrameContext&) const { return false; }

 protected:
  // Applies the declared state of step `i` (PassDecl::steps); the pass's own state is `state`.
  void apply_step(std::size_t i) const { apply(decl().steps.at(i).state); }
  void apply_own_state() const { apply(decl().state); }
};

// Throws std::logic_error naming the pass and the resource where a pass of `view` reads what
// neither the frame's start nor an earlier pass provides, or writes more than one target, or
// writes what the frame's start provides.
void check_pass_order(std::string_view view, const std::vector<Pass*>& passes);
// Likewise for a frame pass: one that draws a resource of the frame's start (from_frame) before
// the view's passes, reading nothing but the frame's start.
void check_frame_pass(const Pass& pass);

}  // namespace downpour::render
