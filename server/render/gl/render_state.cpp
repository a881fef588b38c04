#include "server/render/gl/render_state.hpp"

#include "server/render/gl/gl.hpp"

namespace downpour::render {

namespace {

void set(GLenum capability, bool on) {
  if (on)
    glEnable(capability);
  else
    glDisable(capability);
}

GLenum depth_func(DepthTest d) {
  switch (d) {
    case DepthTest::kNearer:
      return GL_GREATER;
    case DepthTest::kNearerOrEqual:
      return GL_GEQUAL;
    case DepthTest::kFarther:
      return GL_LESS;
    case DepthTest::kOff:
    case DepthTest::kAlways:
      break;
  }
  return GL_ALWAYS;
}

}  // namespace

void apply(const RenderState& s) {
  set(GL_DEPTH_TEST, s.depth != DepthTest::kOff);
  if (s.depth != DepthTest::kOff) glDepthFunc(depth_func(s.depth));
  glDepthMask(s.depth_write ? GL_TRUE : GL_FALSE);
  set(GL_BLEND, s.blend != Blend::kOff);
  switch (s.blend) {
    case Blend::kOff:
      break;
    case Blend::kPremultiplied:
      glBlendEquation(GL_FUNC_ADD);
      glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
      break;
    case Blend::kAdd:
      glBlendEquation(GL_FUNC_ADD);
      glBlendFunc(GL_ONE, GL_ONE);
      break;
    case Blend::kMin:
      glBlendEquation(GL_MIN);
      break;
  }
  const GLboolean c = s.colour_write ? GL_TRUE : GL_FALSE;
  glColorMask(c, c, c, c);
  set(GL_DEPTH_CLAMP, s.depth_clamp);
  for (int i = 0; i < kClipDistances; ++i) set(GL_CLIP_DISTANCE0 + i, (s.clip_distances >> i) & 1);
  set(GL_PROGRAM_POINT_SIZE, s.program_point_size);
}

}  // namespace downpour::render
