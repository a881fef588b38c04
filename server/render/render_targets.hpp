// The renderer's GL targets: each view's colour, depth and readback buffers (ViewTarget), and the
// targets that live within a frame (the glass layer, the road reflection, the spray's), made as
// the resource table says (resource.hpp's ResourceInfo) and kept by size (TransientTargets).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <tuple>

#include "server/render/gl/gl_objects.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

inline constexpr int kReadbackSlots = 2;

// A framebuffer with these attachments (0: none); throws if GL finds it incomplete.
Framebuffer framebuffer_with(GLuint colour, GLuint depth);

// A view's start: colour black, depth 0 (reversed-Z's infinity), in framebuffer `fbo` (its depth
// mask turned on, which clears obey).
void clear_view(GLuint fbo);

// A view's ground truth (sim::Outputs) on its way back: the clean frame's colour (the view's
// colour before the first pass that adds water; its framebuffer has the slot's view depth, so that
// the blades drawn over it hide behind the cabin as they do in the frame), and readback buffers for
// it and for the view's depth.
struct GroundTruthTarget {
  Texture clean;
  std::array<Framebuffer, kReadbackSlots> clean_fbo;
  std::array<Buffer, kReadbackSlots> clean_pbo;
  std::array<Buffer, kReadbackSlots> depth_pbo;

  // view_depth: the view's depth textures, `pictures` of them (ViewTarget).
  GroundTruthTarget(int w, int h, const std::array<Texture, kReadbackSlots>& view_depth,
                    int pictures);
};

// A view's colour and depth (its picture), and its readback buffers, a slot for each frame in
// flight, used in turn. With a picture per slot (pictures = kReadbackSlots), a frame draws into the
// picture whose last frame has been read back, so that a copy into it at the frame's start
// (CockpitPass's kept cabin) finds nothing still drawing into it: on llvmpipe it would wait for the
// frame before, which pipelining still has in flight. Without (1), the slots share one picture.
struct ViewTarget {
  int width = 0;
  int height = 0;
  int pictures = 1;
  std::array<Texture, kReadbackSlots> colour;  // the first `pictures` of them
  std::array<Texture, kReadbackSlots> depth;
  std::array<Framebuffer, kReadbackSlots> fbo;
  std::array<Buffer, kReadbackSlots> pbo;
  std::array<GLsync, kReadbackSlots> fence{};  // a readback in flight per slot
  int next_slot = 0;
  std::unique_ptr<GroundTruthTarget> truth;  // made for the first frame that asks for outputs

  ViewTarget(int w, int h, int pictures);
  ~ViewTarget();
  int picture(int slot) const { return slot % pictures; }  // the picture slot `slot` draws into
  ViewTarget(const ViewTarget&) = delete;
  ViewTarget& operator=(const ViewTarget&) = delete;
  bool busy() const;
};

// A target that lives only within a frame.
struct Transient {
  Texture texture;
  Texture depth;  // its own, where its resource has one (ResourceInfo::depth_from)
  Framebuffer fbo;
  int width = 0;
  int height = 0;
  std::uint64_t last_frame = 0;  // the last frame that drew into it
  std::uint64_t serial = 0;      // which target this is, never reused (GL names are)
  // Another transient's depth (ResourceInfo::depth_from) attached to fbo: that target's serial.
  std::uint64_t borrowed = 0;
};

class TransientTargets {
 public:
  // The target for `r` at this size, made on first use, marked as drawn in `frame`.
  Transient& get(Resource r, int width, int height, std::uint64_t frame);
  // Many view sizes at once are rare: past kMax, the targets unused the longest go. Call it at a
  // frame's start, so that it never takes one a pass of the frame has bound.
  void evict();
  void clear() { targets_.clear(); }
  // `t`'s framebuffer with `owner`'s depth attached (once per pair).
  static void attach_depth(Transient& t, const Transient& owner);

 private:
  // Four view sizes' worth: a size has up to six (the glass layer, the road reflection, the spray
  // layer, maps, body front and haze).
  static constexpr std::size_t kMax = 24;
  std::map<std::tuple<Resource, int, int>, Transient> targets_;
  std::uint64_t made_ = 0;
};

}  // namespace downpour::render
