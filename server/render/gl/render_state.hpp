// The fixed-function state a pass draws with. The renderer applies a pass's state before the pass
// runs, so that no pass inherits what another left behind.
#pragma once

namespace downpour::render {

enum class DepthTest {
  kOff,
  kNearer,         // reversed-Z: nearer is greater (GL_GREATER)
  kNearerOrEqual,  // GL_GEQUAL: the sky at depth 0 fills what nothing else covered
  kAlways,         // GL_ALWAYS: a pass that writes a depth of its own choosing (a mask)
};

enum class Blend {
  kOff,
  kPremultiplied,  // src + dst * (1 - src alpha)
};

struct RenderState {
  DepthTest depth = DepthTest::kOff;
  bool depth_write = false;
  Blend blend = Blend::kOff;
  bool colour_write = true;
};

// Sets GL's depth test, depth writes, blending and colour writes to `state`. Render thread only.
void apply(const RenderState& state);

}  // namespace downpour::render
