// The fixed-function state a pass draws with. The renderer applies a pass's state before the pass
// runs, so that no pass inherits what another left behind; a pass that draws in steps declares
// each step's state (PassDecl::steps) and applies them in turn. Nothing else sets GL's depth,
// blend, clamp or clip state.
#pragma once

#include <cstdint>

namespace downpour::render {

enum class DepthTest : std::uint8_t {
  kOff,
  kNearer,         // reversed-Z: nearer is greater (GL_GREATER)
  kNearerOrEqual,  // GL_GEQUAL: the sky at depth 0 fills what nothing else covered
  // GL_LESS: a mask's test. A pass draws at a fixed depth and shades only where an earlier one
  // left a greater value in the depth buffer (llvmpipe rejects the rest before shading).
  kFarther,
  kAlways,  // GL_ALWAYS: a pass that writes a depth of its own choosing (a mask)
};

enum class Blend : std::uint8_t {
  kOff,
  kPremultiplied,  // src + dst * (1 - src alpha)
  kAdd,            // src + dst
  kMin,            // min(src, dst) per channel
};

struct RenderState {
  DepthTest depth = DepthTest::kOff;
  bool depth_write = false;
  Blend blend = Blend::kOff;
  bool colour_write = true;
  // Depths beyond the near and far planes clamped to them rather than clipped (GL_DEPTH_CLAMP).
  bool depth_clamp = false;
  // Bit i: gl_ClipDistance[i] clips (0: the road reflection's plane; 1: the split between the near
  // road, drawn with relief shadows, and the rest; 2: the road's part by the view's depth).
  std::uint8_t clip_distances = 0;
  bool program_point_size = false;  // the vertex shader sets gl_PointSize
};
inline constexpr int kClipDistances = 3;

// Sets GL's depth test, depth writes, blending, colour writes, depth clamp, clip distances and
// point size to `state`. Render thread only.
void apply(const RenderState& state);

}  // namespace downpour::render
