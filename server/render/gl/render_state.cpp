#include "server/render/gl/render_state.hpp"

#include "server/render/gl/gl.hpp"

namespace downpour::render {

void apply(const RenderState& s) {
  if (s.depth == DepthTest::kOff) {
    glDisable(GL_DEPTH_TEST);
  } else {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(s.depth == DepthTest::kNearer          ? GL_GREATER
                : s.depth == DepthTest::kNearerOrEqual ? GL_GEQUAL
                                                       : GL_ALWAYS);
  }
  glDepthMask(s.depth_write ? GL_TRUE : GL_FALSE);
  if (s.blend == Blend::kOff) {
    glDisable(GL_BLEND);
  } else {
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  }
  const GLboolean c = s.colour_write ? GL_TRUE : GL_FALSE;
  glColorMask(c, c, c, c);
}

}  // namespace downpour::render
