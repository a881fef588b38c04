#include "server/render/passes/spray_pass.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>

#include "server/render/cpu/shader_interface.hpp"

namespace downpour::render {
namespace {

constexpr float kFar = 1.0e6f;
// The smoothing's figures (seed 001, section 4): plane fitting 9 x 9 x 3 with the weight's sigma
// about two parcel radii; the bilateral filter 7 x 7 x 22, sigma1 = w / (2 sqrt 2) over a kernel
// of width w, sigma2 = 2 sqrt 2 r.
constexpr int kPlaneRadius = 4, kPlanePasses = 3;
constexpr float kPlaneSigmaM = 0.08f, kPlaneMaxShiftM = 0.15f;
constexpr int kBilateralRadius = 3, kBilateralPasses = 22;
constexpr float kBodyRadiusM = 0.04f;
constexpr float kSmoothedFromPx = 2.0f;  // a body's sphere of a smaller radius is drawn as spray
// Road spray is dirty water: absorption per metre, red most (pure water's is far less).
const glm::vec3 kAbsorption(3.0f, 2.0f, 1.6f);
constexpr float kHazeSoftM = 1.0f;  // the haze fades over this where the scene comes nearer
// A parcel stands for a cloud of droplets, not a ball of white: its optical depth is capped, so
// that a dense cloud is dense by the parcels that overlap in it.
constexpr float kMaxCloudDepth = 1.5f;
constexpr float kHazeVisible = 0.004f;  // optical depth below which the haze is not composited

// Marks the tiles a screen circle (pixels) touches.
void mark(std::vector<std::uint8_t>& tiles, int tiles_x, int tiles_y, glm::vec2 centre,
          float radius) {
  const int x0 = std::max(0, static_cast<int>(std::floor((centre.x - radius) / SprayPass::kTile)));
  const int x1 =
      std::min(tiles_x - 1, static_cast<int>(std::floor((centre.x + radius) / SprayPass::kTile)));
  const int y0 = std::max(0, static_cast<int>(std::floor((centre.y - radius) / SprayPass::kTile)));
  const int y1 =
      std::min(tiles_y - 1, static_cast<int>(std::floor((centre.y + radius) / SprayPass::kTile)));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) tiles[static_cast<std::size_t>(y) * tiles_x + x] = 1;
}

// Runs of marked tiles along each row, as uv rectangles over the layer.
void runs_of(const std::vector<std::uint8_t>& tiles, int tiles_x, int tiles_y, int width,
             int height, std::vector<glm::vec4>& out) {
  out.clear();
  for (int y = 0; y < tiles_y; ++y) {
    for (int x = 0; x < tiles_x;) {
      if (!tiles[static_cast<std::size_t>(y) * tiles_x + x]) {
        ++x;
        continue;
      }
      int end = x;
      while (end < tiles_x && tiles[static_cast<std::size_t>(y) * tiles_x + end]) ++end;
      out.emplace_back(static_cast<float>(x * SprayPass::kTile) / width,
                       static_cast<float>(y * SprayPass::kTile) / height,
                       std::min(1.0f, static_cast<float>(end * SprayPass::kTile) / width),
                       std::min(1.0f, static_cast<float>((y + 1) * SprayPass::kTile) / height));
      x = end;
    }
  }
}

}  // namespace

const char* spray_smoothing_name(SpraySmoothing smoothing) {
  switch (smoothing) {
    case SpraySmoothing::kPlaneFit:
      return "plane_fit";
    case SpraySmoothing::kBilateral:
      return "bilateral";
    case SpraySmoothing::kNone:
      return "none";
  }
  return "?";
}

SprayPass::SprayPass(SharedResources&)
    : depth_program_("spray_depth.vert", "spray_depth.frag"),
      plane_program_("spray_runs.vert", "spray_plane_fit.frag"),
      bilateral_program_("spray_runs.vert", "spray_bilateral.frag"),
      shade_program_("spray_runs.vert", "spray_shade.frag"),
      haze_program_("spray_haze.vert", "spray_haze.frag"),
      haze_composite_program_("spray_runs.vert", "spray_haze_composite.frag"),
      u_depth_projection_(depth_program_.uniform("u_projection")),
      u_depth_spray_(depth_program_.uniform("u_spray_count")),
      u_depth_near_(depth_program_.uniform("u_near")),
      u_plane_size_(plane_program_.uniform("u_size")),
      u_plane_tan_(plane_program_.uniform("u_tan")),
      u_plane_sigma_(plane_program_.uniform("u_sigma")),
      u_plane_shift_(plane_program_.uniform("u_max_shift")),
      u_bilateral_size_(bilateral_program_.uniform("u_size")),
      u_bilateral_sigma_px_(bilateral_program_.uniform("u_sigma_px")),
      u_bilateral_sigma_z_(bilateral_program_.uniform("u_sigma_z")),
      u_shade_size_(shade_program_.uniform("u_size")),
      u_shade_tan_(shade_program_.uniform("u_tan")),
      u_shade_to_world_(shade_program_.uniform("u_view_to_world")),
      u_shade_near_(shade_program_.uniform("u_near")),
      u_shade_scale_(shade_program_.uniform("u_scale")),
      u_shade_absorption_(shade_program_.uniform("u_absorption")),
      u_haze_projection_(haze_program_.uniform("u_projection")),
      u_haze_light_(haze_composite_program_.uniform("u_light")),
      u_haze_near_(haze_composite_program_.uniform("u_near")),
      u_haze_soft_(haze_composite_program_.uniform("u_soft_m")) {
  GLuint vao = 0;
  glCreateVertexArrays(1, &vao);
  vao_ = VertexArray(vao);
  GLuint ids[3];
  glCreateBuffers(3, ids);
  parcels_ = Buffer(ids[0]);
  haze_ = Buffer(ids[1]);
  runs_buffer_ = Buffer(ids[2]);
  // The runs' depth against the mask: the smoothing's between the spray's and the body's marks.
  plane_program_.uniform("u_depth").set(0.5f * (kSprayMaskSpray + kSprayMaskBody));
  bilateral_program_.uniform("u_depth").set(0.5f * (kSprayMaskSpray + kSprayMaskBody));
  const char* gl = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const std::string renderer = gl ? gl : "";
  cpu_splat_ = renderer.find("llvmpipe") != std::string::npos ||
               renderer.find("softpipe") != std::string::npos;
  if (const char* choice = std::getenv("DOWNPOUR_SPRAY_SPLAT")) {
    if (std::string_view(choice) == "cpu") cpu_splat_ = true;
    if (std::string_view(choice) == "gpu") cpu_splat_ = false;
  }
}

void SprayPass::prepare(int view_width, int view_height) {
  const int width = std::max(1, (view_width + kScale - 1) / kScale);
  const int height = std::max(1, (view_height + kScale - 1) / kScale);
  const Targets& t = targets(width, height);
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  maps_.depth.assign(std::max(maps_.depth.size(), pixels), glm::vec4(kFar));
  maps_.mask.assign(std::max(maps_.mask.size(), pixels), 0.0f);
  haze_pixels_.assign(
      std::max(haze_pixels_.size(), static_cast<std::size_t>(t.haze_width) * t.haze_height),
      glm::vec2(0.0f));
  // The helper's first job now, so that its thread has run before the first spray does.
  helper_.start([] {});
  helper_.wait();
}

bool SprayPass::wanted(const FrameContext& frame) const {
  const sim::SprayImage* image = frame.scene.spray.get();
  return image && !image->points.empty();
}

SprayPass::Targets& SprayPass::targets(int width, int height) {
  for (auto& t : targets_) {
    if (t->width == width && t->height == height) return *t;
  }
  if (targets_.size() >= 4) targets_.erase(targets_.begin());
  auto t = std::make_unique<Targets>();
  t->width = width;
  t->height = height;
  auto make = [](GLenum format, int w, int h, bool linear, Texture& texture, Framebuffer& fbo) {
    texture = make_texture_2d(format, w, h);
    const GLint filter = linear ? GL_LINEAR : GL_NEAREST;
    glTextureParameteri(texture.id(), GL_TEXTURE_MIN_FILTER, filter);
    glTextureParameteri(texture.id(), GL_TEXTURE_MAG_FILTER, filter);
    glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(texture.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    GLuint id = 0;
    glCreateFramebuffers(1, &id);
    fbo = Framebuffer(id);
    glNamedFramebufferTexture(id, GL_COLOR_ATTACHMENT0, texture.id(), 0);
  };
  make(GL_RGBA32F, width, height, false, t->depth, t->depth_fbo);
  t->mask = make_texture_2d(GL_DEPTH_COMPONENT32F, width, height);
  glNamedFramebufferTexture(t->depth_fbo.id(), GL_DEPTH_ATTACHMENT, t->mask.id(), 0);
  for (int i = 0; i < 2; ++i) {
    make(GL_R32F, width, height, false, t->smooth[i], t->smooth_fbo[i]);
    glNamedFramebufferTexture(t->smooth_fbo[i].id(), GL_DEPTH_ATTACHMENT, t->mask.id(), 0);
  }
  t->haze_width = std::max(1, (width + kHazeScale - 1) / kHazeScale);
  t->haze_height = std::max(1, (height + kHazeScale - 1) / kHazeScale);
  make(GL_RG32F, t->haze_width, t->haze_height, true, t->haze, t->haze_fbo);
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  t->shade_fbo = Framebuffer(id);
  glNamedFramebufferTexture(id, GL_DEPTH_ATTACHMENT, t->mask.id(), 0);
  targets_.push_back(std::move(t));
  return *targets_.back();
}

void SprayPass::upload(Buffer& buffer, const void* data, std::size_t bytes) {
  glNamedBufferData(buffer.id(), static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 16)), data,
                    GL_STREAM_DRAW);
}

void SprayPass::draw_runs(const std::vector<glm::vec4>& runs) {
  upload(runs_buffer_, runs.data(), runs.size() * sizeof(glm::vec4));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, storage_buffer::kRunsBuffer, runs_buffer_.id());
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(6 * runs.size()));
}

// The four depth maps and the mask of what was hit.
void SprayPass::depth_maps(const FrameContext& frame, Targets& t) {
  if (cpu_splat_) {
    // (Drawn with the tiles, in execute.)
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage2D(t.depth.id(), 0, 0, 0, t.width, t.height, GL_RGBA, GL_FLOAT,
                        maps_.depth.data());
    glTextureSubImage2D(t.mask.id(), 0, 0, 0, t.width, t.height, GL_DEPTH_COMPONENT, GL_FLOAT,
                        maps_.mask.data());
    return;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, t.depth_fbo.id());
  glViewport(0, 0, t.width, t.height);
  const float far[4] = {kFar, kFar, kFar, kFar};
  const float no_hit = 0.0f;
  // (A depth clear obeys the depth mask: the step writes depth.)
  apply_step(kMaps);
  glClearNamedFramebufferfv(t.depth_fbo.id(), GL_COLOR, 0, far);
  glClearNamedFramebufferfv(t.depth_fbo.id(), GL_DEPTH, 0, &no_hit);
  // The spray's parcels first, then the body's: each hit leaves its kind in the mask and passes a
  // greater-or-equal test (a failed test would drop the fragment before MIN blending), so the
  // mask ends with the body's mark over the spray's; MIN keeps the nearest front and, by the
  // sign, the farthest back.
  packed_.clear();
  for (const auto* list : {&spray_, &body_})
    for (const SprayBall& b : *list) packed_.emplace_back(b.centre, b.radius);
  upload(parcels_, packed_.data(), packed_.size() * sizeof(glm::vec4));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, storage_buffer::kParcelsBuffer, parcels_.id());
  depth_program_.use();
  u_depth_projection_.set(frame.camera.projection);
  u_depth_spray_.set(static_cast<int>(spray_.size()));
  u_depth_near_.set(frame.camera.near_m);
  glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, static_cast<GLsizei>(packed_.size()));
  apply_own_state();
}

// The clouds' optical depth, and times distance, at a quarter of the view.
void SprayPass::haze_map(const FrameContext& frame, Targets& t) {
  if (cpu_splat_) {
    // (Drawn with the tiles, in execute.)
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage2D(t.haze.id(), 0, 0, 0, t.haze_width, t.haze_height, GL_RG, GL_FLOAT,
                        haze_pixels_.data());
    return;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, t.haze_fbo.id());
  glViewport(0, 0, t.haze_width, t.haze_height);
  const float clear[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  glClearNamedFramebufferfv(t.haze_fbo.id(), GL_COLOR, 0, clear);
  packed_.clear();
  for (const SprayHazeBall& h : clouds_) {
    packed_.emplace_back(h.ball.centre, h.ball.radius);
    packed_.emplace_back(h.depth, 0.0f, 0.0f, 0.0f);
  }
  upload(haze_, packed_.data(), packed_.size() * sizeof(glm::vec4));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, storage_buffer::kHazeBuffer, haze_.id());
  haze_program_.use();
  u_haze_projection_.set(frame.camera.projection);
  apply_step(kHaze);
  glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, static_cast<GLsizei>(clouds_.size()));
  apply_own_state();
}

GLuint SprayPass::smooth(Targets& t, const std::vector<glm::vec4>& runs, glm::vec2 tan) {
  const int passes = smoothing_ == SpraySmoothing::kPlaneFit    ? kPlanePasses
                     : smoothing_ == SpraySmoothing::kBilateral ? kBilateralPasses
                                                                : 0;
  GLuint body_front = t.depth.id();
  if (passes == 0 || runs.empty()) return body_front;
  const glm::vec2 size(static_cast<float>(t.width), static_cast<float>(t.height));
  const float far[4] = {kFar, kFar, kFar, kFar};
  for (int i = 0; i < 2; ++i) glClearNamedFramebufferfv(t.smooth_fbo[i].id(), GL_COLOR, 0, far);
  if (smoothing_ == SpraySmoothing::kPlaneFit) {
    plane_program_.use();
    u_plane_size_.set(size);
    u_plane_tan_.set(tan);
    u_plane_sigma_.set(kPlaneSigmaM);
    u_plane_shift_.set(kPlaneMaxShiftM);
  } else {
    bilateral_program_.use();
    u_bilateral_size_.set(size);
    u_bilateral_sigma_px_.set((2.0f * kBilateralRadius + 1.0f) / (2.0f * std::sqrt(2.0f)));
    u_bilateral_sigma_z_.set(2.0f * std::sqrt(2.0f) * kBodyRadiusM);
  }
  upload(runs_buffer_, runs.data(), runs.size() * sizeof(glm::vec4));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, storage_buffer::kRunsBuffer, runs_buffer_.id());
  glViewport(0, 0, t.width, t.height);
  // Only where the mask holds the body (llvmpipe rejects the rest before shading).
  apply_step(kSmooth);
  for (int pass = 0; pass < passes; ++pass) {
    glBindTextureUnit(texture_unit::kSpraySmooth, body_front);
    glBindFramebuffer(GL_FRAMEBUFFER, t.smooth_fbo[pass % 2].id());
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(6 * runs.size()));
    body_front = t.smooth[pass % 2].id();
  }
  apply_own_state();
  return body_front;
}

std::vector<float> SprayPass::smooth_body_depth(int width, int height, glm::vec2 tan,
                                                const std::vector<float>& front) {
  Targets& t = targets(width, height);
  std::vector<glm::vec4> depth(front.size(), glm::vec4(kFar));
  std::vector<float> mask(front.size(), 0.0f);
  for (std::size_t i = 0; i < front.size(); ++i) {
    depth[i].x = front[i];
    if (front[i] < 0.5f * kFar) mask[i] = kSprayMaskBody;
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(t.depth.id(), 0, 0, 0, width, height, GL_RGBA, GL_FLOAT, depth.data());
  glTextureSubImage2D(t.mask.id(), 0, 0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT,
                      mask.data());
  glBindVertexArray(vao_.id());
  const GLuint smoothed = smooth(t, {glm::vec4(0.0f, 0.0f, 1.0f, 1.0f)}, tan);
  std::vector<glm::vec4> out(front.size());
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glGetTextureImage(smoothed, 0, GL_RGBA, GL_FLOAT,
                    static_cast<GLsizei>(out.size() * sizeof(glm::vec4)), out.data());
  std::vector<float> z(front.size());
  for (std::size_t i = 0; i < z.size(); ++i) z[i] = out[i].x;
  return z;
}

void SprayPass::execute(const FrameContext& frame, const FrameResources& resources) {
  drawn_ = {};
  const Camera& camera = frame.camera;
  const int width = std::max(1, (resources.view_colour.width + kScale - 1) / kScale);
  const int height = std::max(1, (resources.view_colour.height + kScale - 1) / kScale);
  const int tiles_x = (width + kTile - 1) / kTile, tiles_y = (height + kTile - 1) / kTile;
  const glm::vec2 tan(static_cast<float>(camera.tan_half_fov_x),
                      static_cast<float>(camera.tan_half_fov_y));
  cull(frame, width, height, tiles_x, tiles_y);
  Targets& t = targets(width, height);
  if (cpu_splat_) splat_on_cpu(t, width, height, tiles_x, tan);
  const std::size_t tiles = static_cast<std::size_t>(tiles_x) * tiles_y;
  for (std::size_t i = 0; i < tiles; ++i) all_tiles_[i] |= liquid_tiles_[i];
  runs_of(liquid_tiles_, tiles_x, tiles_y, width, height, liquid_runs_);
  runs_of(body_tiles_, tiles_x, tiles_y, width, height, body_runs_);
  runs_of(all_tiles_, tiles_x, tiles_y, width, height, all_runs_);
  glBindVertexArray(vao_.id());
  if (!body_.empty() || !spray_.empty()) shade_liquid(frame, resources, t, tan);
  if (!clouds_.empty()) haze_over(frame, resources, t);
}

// Culls the parcels to the view: the body's, the spray's and the clouds in view space, and the
// tiles of the layer each touches.
void SprayPass::cull(const FrameContext& frame, int width, int height, int tiles_x, int tiles_y) {
  const sim::SprayImage& image = *frame.scene.spray;
  const Camera& camera = frame.camera;
  const float tan_x = static_cast<float>(camera.tan_half_fov_x);
  const float tan_y = static_cast<float>(camera.tan_half_fov_y);
  const float px_per_tan = 0.5f * static_cast<float>(height) / tan_y;  // layer pixels per x / z
  const glm::mat3 rotation(camera.view);
  const glm::dvec3 eye(camera.position);
  body_.clear();
  spray_.clear();
  clouds_.clear();
  const std::size_t tiles = static_cast<std::size_t>(tiles_x) * tiles_y;
  liquid_tiles_.assign(tiles, 0);
  body_tiles_.assign(tiles, 0);
  all_tiles_.assign(tiles, 0);
  // (The origin's offset from the eye in double, then each point's in float.)
  const glm::vec3 origin = rotation * glm::vec3(image.origin_m - eye);
  const bool mark_all = !cpu_splat_;  // the CPU's maps give the tiles exactly (below)
  for (const sim::SprayImage::Point& p : image.points) {
    const glm::vec3 v = origin + rotation * glm::vec3(p.x, p.y, p.z);
    const float z = -v.z;
    if (z <= camera.near_m + 0.05f) continue;
    const float inv_z = 1.0f / z;
    const glm::vec2 centre((v.x * inv_z / tan_x * 0.5f + 0.5f) * width,
                           (v.y * inv_z / tan_y * 0.5f + 0.5f) * height);
    const float pixel_m = z / px_per_tan;  // one layer pixel's size at that distance
    const float reach = 1.3f * std::max(p.radius_m, p.liquid_radius_m) / pixel_m + 2.0f;
    if (centre.x < -reach || centre.y < -reach || centre.x > width + reach ||
        centre.y > height + reach)
      continue;
    if (p.liquid_radius_m > 0.0f) {
      // A body (a sheet) is never drawn under 3/4 of a pixel, so that it shows far away; lone
      // spray smaller than a pixel misses the pixels' centres, as it would a camera's.
      const float r = p.body ? std::max(p.liquid_radius_m, 0.75f * pixel_m) : p.liquid_radius_m;
      // A body's sphere under two pixels across has no surface to smooth: it is drawn as spray.
      const bool body = p.body && r > kSmoothedFromPx * pixel_m;
      (body ? body_ : spray_).push_back({v, r});
      const float cover = 1.3f * r / pixel_m + 1.0f;
      if (mark_all) mark(liquid_tiles_, tiles_x, tiles_y, centre, cover);
      if (body) mark(body_tiles_, tiles_x, tiles_y, centre, cover + kPlaneRadius);
    }
    // The cloud: drawn at least a haze pixel wide, its optical depth thinned to keep its
    // extinction. Parcels at the camera are too few to stand for the cloud around it: they fade
    // in from 0.5 to 3 m.
    const float r = std::max(p.radius_m, kHazeScale * pixel_m);
    const float near = std::clamp((z - 0.5f) / 2.5f, 0.0f, 1.0f);
    const float depth =
        p.haze_depth * (p.radius_m / r) * (p.radius_m / r) * near * near * (3.0f - 2.0f * near);
    if (depth > 0.002f) {
      clouds_.push_back({{v, r}, std::min(depth, kMaxCloudDepth)});
      if (mark_all) mark(all_tiles_, tiles_x, tiles_y, centre, r / pixel_m + 1.0f);
    }
  }
  drawn_.body = static_cast<std::uint32_t>(body_.size());
  drawn_.spray = static_cast<std::uint32_t>(spray_.size());
  drawn_.haze = static_cast<std::uint32_t>(clouds_.size());
}

// The CPU draws the parcels' maps and the haze (llvmpipe): its maps say exactly which tiles hold
// liquid or visible haze.
void SprayPass::splat_on_cpu(const Targets& t, int width, int height, int tiles_x, glm::vec2 tan) {
  const SprayCamera layer{width, height, tan};
  const SprayCamera quarter{t.haze_width, t.haze_height, tan};
  // The haze on the helper thread while this one draws the liquid's maps.
  helper_.start([this, quarter] { splat_haze(quarter, clouds_, haze_pixels_); });
  struct Join {
    sim::WorkerThread& helper;
    ~Join() { helper.wait(); }  // before anything it reads goes, even if this throws
  } join{helper_};
  splat_depth(layer, body_, spray_, maps_);
  helper_.wait();
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (maps_.mask[static_cast<std::size_t>(y) * width + x] > 0.0f)
        liquid_tiles_[static_cast<std::size_t>(y / kTile) * tiles_x + x / kTile] = 1;
    }
  }
  for (int y = 0; y < t.haze_height; ++y) {
    for (int x = 0; x < t.haze_width; ++x) {
      if (haze_pixels_[static_cast<std::size_t>(y) * t.haze_width + x].x > kHazeVisible) {
        // A haze pixel is 2 x 2 layer pixels; bilinear reaches one more around.
        for (int dy = -1; dy <= 2; ++dy) {
          for (int dx = -1; dx <= 2; ++dx) {
            const int lx = std::clamp(x * kHazeScale + dx, 0, width - 1);
            const int ly = std::clamp(y * kHazeScale + dy, 0, height - 1);
            all_tiles_[static_cast<std::size_t>(ly / kTile) * tiles_x + lx / kTile] = 1;
          }
        }
      }
    }
  }
}

// The liquid's depth maps, the body's front smoothed over its tiles, and its colour into the layer
// where a sphere was hit.
void SprayPass::shade_liquid(const FrameContext& frame, const FrameResources& resources, Targets& t,
                             glm::vec2 tan) {
  depth_maps(frame, t);
  const glm::vec2 size(static_cast<float>(t.width), static_cast<float>(t.height));
  // The body's front depth smoothed, over the body's tiles; elsewhere the maps' own.
  const GLuint body_front = body_.empty() ? t.depth.id() : smooth(t, body_runs_, tan);

  // The liquid's colour into the layer, where a sphere was hit.
  glBindTextureUnit(texture_unit::kSprayDepth, t.depth.id());
  glBindTextureUnit(texture_unit::kSpraySmooth, body_front);
  // (Attached each frame: the renderer may have replaced the layer's texture under the same
  // name.)
  glNamedFramebufferTexture(t.shade_fbo.id(), GL_COLOR_ATTACHMENT0,
                            resources.transient(Resource::kSprayLayer).colour.texture, 0);
  glBindFramebuffer(GL_FRAMEBUFFER, t.shade_fbo.id());
  glViewport(0, 0, t.width, t.height);
  // The runs at depth 0 pass only where a hit left more (llvmpipe rejects the rest before
  // shading them).
  apply_step(kShade);
  shade_program_.use();
  u_shade_size_.set(size);
  u_shade_tan_.set(tan);
  u_shade_to_world_.set(glm::transpose(glm::mat4(glm::mat3(frame.camera.view))));
  u_shade_near_.set(frame.camera.near_m);
  u_shade_scale_.set(kScale);
  u_shade_absorption_.set(kAbsorption);
  draw_runs(liquid_runs_);
  apply_own_state();
}

// The clouds' haze over the layer, lit by the light around them.
void SprayPass::haze_over(const FrameContext& frame, const FrameResources& resources, Targets& t) {
  haze_map(frame, t);
  // The light the droplets scatter: the sky's and the scene's around them, as the rain's.
  const Atmosphere& atm = frame.atmosphere;
  // (Linear: the shader adds the lamps' light where their beams pass, then encodes it.)
  const glm::vec3 light =
      glm::mix(atm.sky_horizon, atm.ambient, 0.4f) * 0.95f + atm.sun_radiance * 0.05f;
  glBindFramebuffer(GL_FRAMEBUFFER, resources.transient(Resource::kSprayLayer).fbo);
  glViewport(0, 0, t.width, t.height);
  glBindTextureUnit(texture_unit::kSprayHaze, t.haze.id());
  haze_composite_program_.use();
  u_haze_light_.set(light);
  u_haze_near_.set(frame.camera.near_m);
  u_haze_soft_.set(kHazeSoftM);
  apply_step(kHazeOver);
  draw_runs(all_runs_);
  apply_own_state();
}

SprayCompositePass::SprayCompositePass(SharedResources&, const SprayPass& spray)
    : spray_(spray), program_("spray_runs.vert", "spray_composite.frag") {
  GLuint vao = 0;
  glCreateVertexArrays(1, &vao);
  vao_ = VertexArray(vao);
  GLuint id = 0;
  glCreateBuffers(1, &id);
  runs_buffer_ = Buffer(id);
}

void SprayCompositePass::execute(const FrameContext&, const FrameResources&) {
  const std::vector<glm::vec4>& runs = spray_.runs();
  if (runs.empty()) return;
  glNamedBufferData(runs_buffer_.id(), static_cast<GLsizeiptr>(runs.size() * sizeof(glm::vec4)),
                    runs.data(), GL_STREAM_DRAW);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, storage_buffer::kRunsBuffer, runs_buffer_.id());
  program_.use();
  glBindVertexArray(vao_.id());
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(6 * runs.size()));
}

}  // namespace downpour::render
