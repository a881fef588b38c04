#include "server/render/render_targets.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "server/render/gl/render_state.hpp"

namespace downpour::render {

namespace {

GLenum gl_format(Format f) {
  switch (f) {
    case Format::kRgba32f:
      return GL_RGBA32F;
    case Format::kR32f:
      return GL_R32F;
    case Format::kRg32f:
      return GL_RG32F;
    case Format::kRgba8:
      break;
  }
  return GL_RGBA8;
}

}  // namespace

Framebuffer framebuffer_with(GLuint colour, GLuint depth) {
  GLuint fb = 0;
  glCreateFramebuffers(1, &fb);
  Framebuffer fbo(fb);
  if (colour) glNamedFramebufferTexture(fb, GL_COLOR_ATTACHMENT0, colour, 0);
  if (depth) glNamedFramebufferTexture(fb, GL_DEPTH_ATTACHMENT, depth, 0);
  if (glCheckNamedFramebufferStatus(fb, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw std::runtime_error("render target framebuffer incomplete");
  }
  return fbo;
}

void clear_view(GLuint fbo) {
  apply(RenderState{DepthTest::kOff, true, Blend::kOff});
  const float black[4] = {0.0f, 0.0f, 0.0f, 1.0f};
  const float zero_depth = 0.0f;
  glClearNamedFramebufferfv(fbo, GL_COLOR, 0, black);
  glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &zero_depth);
}

namespace {

// Readback buffers of `bytes` each.
std::array<Buffer, kReadbackSlots> readback_buffers(std::size_t bytes) {
  std::array<Buffer, kReadbackSlots> out;
  GLuint ids[kReadbackSlots];
  glCreateBuffers(kReadbackSlots, ids);
  for (int i = 0; i < kReadbackSlots; ++i) {
    out[i] = Buffer(ids[i]);
    glNamedBufferStorage(ids[i], static_cast<GLsizeiptr>(bytes), nullptr, GL_MAP_READ_BIT);
  }
  return out;
}

}  // namespace

GroundTruthTarget::GroundTruthTarget(int w, int h,
                                     const std::array<Texture, kReadbackSlots>& view_depth,
                                     int pictures) {
  const std::size_t pixels = static_cast<std::size_t>(w) * h;
  clean = make_texture_2d(GL_RGBA8, w, h);
  for (int i = 0; i < pictures; ++i)
    clean_fbo[i] = framebuffer_with(clean.id(), view_depth[i].id());
  clean_pbo = readback_buffers(pixels * 4);
  depth_pbo = readback_buffers(pixels * sizeof(float));
}

ViewTarget::ViewTarget(int w, int h, int pictures_)
    : width(w), height(h), pictures(std::clamp(pictures_, 1, kReadbackSlots)) {
  for (int i = 0; i < pictures; ++i) {
    colour[i] = make_texture_2d(GL_RGBA8, w, h);
    depth[i] = make_texture_2d(GL_DEPTH_COMPONENT32F, w, h);
    fbo[i] = framebuffer_with(colour[i].id(), depth[i].id());
  }
  pbo = readback_buffers(static_cast<std::size_t>(w) * h * 4);
}

ViewTarget::~ViewTarget() {
  for (GLsync f : fence) {
    if (f) glDeleteSync(f);
  }
}

bool ViewTarget::busy() const {
  return std::any_of(fence.begin(), fence.end(), [](GLsync f) { return f != nullptr; });
}

Transient& TransientTargets::get(Resource r, int width, int height, std::uint64_t frame) {
  const auto key = std::make_tuple(r, width, height);
  auto it = targets_.find(key);
  if (it != targets_.end()) {
    it->second.last_frame = frame;
    return it->second;
  }
  const ResourceInfo& info = resource_info(r);
  Transient t;
  t.last_frame = frame;
  t.serial = ++made_;
  t.width = width;
  t.height = height;
  t.texture = make_texture_2d(gl_format(info.format), width, height);
  const GLint filter = info.linear ? GL_LINEAR : GL_NEAREST;
  glTextureParameteri(t.texture.id(), GL_TEXTURE_MIN_FILTER, filter);
  glTextureParameteri(t.texture.id(), GL_TEXTURE_MAG_FILTER, filter);
  glTextureParameteri(t.texture.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(t.texture.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  if (info.depth_from == r) {
    t.depth = make_texture_2d(GL_DEPTH_COMPONENT32F, width, height);
    glTextureParameteri(t.depth.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(t.depth.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTextureParameteri(t.depth.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(t.depth.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
  // (A borrowed depth is attached as the frame binds it: its owner may be made again.)
  t.fbo = framebuffer_with(t.texture.id(), t.depth.id());
  return targets_.emplace(key, std::move(t)).first->second;
}

void TransientTargets::attach_depth(Transient& t, const Transient& owner) {
  if (t.borrowed == owner.serial) return;
  glNamedFramebufferTexture(t.fbo.id(), GL_DEPTH_ATTACHMENT, owner.depth.id(), 0);
  t.borrowed = owner.serial;
}

void TransientTargets::evict() {
  while (targets_.size() > kMax) {
    auto oldest = targets_.begin();
    for (auto it = targets_.begin(); it != targets_.end(); ++it) {
      if (it->second.last_frame < oldest->second.last_frame) oldest = it;
    }
    targets_.erase(oldest);
  }
}

}  // namespace downpour::render
