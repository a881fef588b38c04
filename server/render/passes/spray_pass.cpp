#include "server/render/passes/spray_pass.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>

#include "server/render/cpu/shader_interface.hpp"

namespace downpour::render {
namespace {

constexpr float kFar = kSprayFar;
// Where a body's parcels are smoothed (spray_smooth_pass.cpp): its tiles, and this many pixels
// around them.
constexpr int kPlaneRadius = 4;
constexpr float kSmoothedFromPx = 2.0f;  // a body's sphere of a smaller radius is drawn as spray
// A parcel stands for a cloud of droplets, not a ball of white: its optical depth is capped, so
// that a dense cloud is dense by the parcels that overlap in it.
constexpr float kMaxCloudDepth = 1.5f;
constexpr float kHazeVisible = 0.004f;
constexpr float kCloudSpread = 1.8f;  // optical depth below which the haze is not composited

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

TileRuns::TileRuns() {
  vao_ = make_vertex_array();
  buffer_ = make_buffer();
}

void TileRuns::draw(const std::vector<glm::vec4>& runs) {
  if (runs.empty()) return;
  glNamedBufferData(buffer_.id(), static_cast<GLsizeiptr>(runs.size() * sizeof(glm::vec4)),
                    runs.data(), GL_STREAM_DRAW);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, storage_buffer::kRunsBuffer, buffer_.id());
  glBindVertexArray(vao_.id());
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(6 * runs.size()));
}

SprayPass::SprayPass(SharedResources&)
    : depth_program_("spray_depth.vert", "spray_depth.frag"),
      u_depth_projection_(depth_program_.uniform("u_projection")),
      u_depth_spray_(depth_program_.uniform("u_spray_count")),
      u_depth_near_(depth_program_.uniform("u_near")) {
  vao_ = make_vertex_array();
  parcels_ = make_buffer();
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
  const int haze_width = std::max(1, (width + kHazeScale - 1) / kHazeScale);
  const int haze_height = std::max(1, (height + kHazeScale - 1) / kHazeScale);
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  maps_.depth.assign(std::max(maps_.depth.size(), pixels), glm::vec4(kFar));
  maps_.mask.assign(std::max(maps_.mask.size(), pixels), 0.0f);
  haze_pixels_.assign(
      std::max(haze_pixels_.size(), static_cast<std::size_t>(haze_width) * haze_height),
      glm::vec2(0.0f));
  // The helper's first job now, so that its thread has run before the first spray does.
  helper_.start([] {});
  helper_.wait();
}

bool SprayPass::wanted(const FrameContext& frame) const {
  const sim::SprayImage* image = frame.scene.spray.get();
  return image && !image->points.empty();
}

void SprayPass::execute(const FrameContext& frame, const FrameResources& resources) {
  drawn_ = {};
  const FrameTarget& maps = resources.transient(Resource::kSprayMaps);
  const int width = maps.colour.width, height = maps.colour.height;
  const int tiles_x = (width + kTile - 1) / kTile, tiles_y = (height + kTile - 1) / kTile;
  const glm::vec2 tan(static_cast<float>(frame.camera.tan_half_fov_x),
                      static_cast<float>(frame.camera.tan_half_fov_y));
  cull(frame, width, height, tiles_x, tiles_y);
  if (cpu_splat_) {
    splat_on_cpu(maps, std::max(1, (width + kHazeScale - 1) / kHazeScale),
                 std::max(1, (height + kHazeScale - 1) / kHazeScale), tiles_x, tan);
  } else if (has_liquid()) {
    draw_maps(frame);
  }
  const std::size_t tiles = static_cast<std::size_t>(tiles_x) * tiles_y;
  for (std::size_t i = 0; i < tiles; ++i) all_tiles_[i] |= liquid_tiles_[i];
  runs_of(liquid_tiles_, tiles_x, tiles_y, width, height, liquid_runs_);
  runs_of(body_tiles_, tiles_x, tiles_y, width, height, body_runs_);
  runs_of(all_tiles_, tiles_x, tiles_y, width, height, all_runs_);
}

// The cloud: spread over kCloudSpread times the parcel's radius (a parcel stands for a cloud that
// merges with its neighbours', not a puff of its own), at least a haze pixel wide, its optical
// depth thinned to keep its extinction. Parcels at the camera are too few to stand for the cloud
// around it: they fade in from 0.5 to 3 m.
bool spray_cloud(const sim::SprayImage::Point& p, const glm::vec3& v, float haze_pixel_m,
                 SprayHazeBall& out) {
  const float z = -v.z;
  const float r = std::max(kCloudSpread * p.radius_m, haze_pixel_m);
  const float near = std::clamp((z - 0.5f) / 2.5f, 0.0f, 1.0f);
  const float depth =
      p.haze_depth * (p.radius_m / r) * (p.radius_m / r) * near * near * (3.0f - 2.0f * near);
  if (depth <= 0.002f) return false;
  out = {{v, r}, std::min(depth, kMaxCloudDepth)};
  return true;
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
    SprayHazeBall cloud;
    if (spray_cloud(p, v, kHazeScale * pixel_m, cloud)) {
      clouds_.push_back(cloud);
      if (mark_all) mark(all_tiles_, tiles_x, tiles_y, centre, cloud.ball.radius / pixel_m + 1.0f);
    }
  }
  drawn_.body = static_cast<std::uint32_t>(body_.size());
  drawn_.spray = static_cast<std::uint32_t>(spray_.size());
  drawn_.haze = static_cast<std::uint32_t>(clouds_.size());
}

// The CPU draws the parcels' maps and the haze (llvmpipe): its maps say exactly which tiles hold
// liquid or visible haze.
void SprayPass::splat_on_cpu(const FrameTarget& maps, int haze_width, int haze_height, int tiles_x,
                             glm::vec2 tan) {
  const int width = maps.colour.width, height = maps.colour.height;
  const SprayCamera layer{width, height, tan};
  const SprayCamera quarter{haze_width, haze_height, tan};
  // The haze on the helper thread while this one draws the liquid's maps.
  helper_.start([this, quarter] { splat_haze(quarter, clouds_, haze_pixels_); });
  const sim::WaitOnExit join(&helper_);  // before anything it reads goes, even if this throws
  splat_depth(layer, body_, spray_, maps_);
  helper_.wait();
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (maps_.mask[static_cast<std::size_t>(y) * width + x] > 0.0f)
        liquid_tiles_[static_cast<std::size_t>(y / kTile) * tiles_x + x / kTile] = 1;
    }
  }
  for (int y = 0; y < haze_height; ++y) {
    for (int x = 0; x < haze_width; ++x) {
      if (haze_pixels_[static_cast<std::size_t>(y) * haze_width + x].x > kHazeVisible) {
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
  if (!has_liquid()) return;
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(maps.colour.texture, 0, 0, 0, width, height, GL_RGBA, GL_FLOAT,
                      maps_.depth.data());
  glTextureSubImage2D(maps.depth.texture, 0, 0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT,
                      maps_.mask.data());
}

// The four depth maps and the mask of what was hit, on the GPU, into the bound target (cleared to
// nothing): the spray's parcels first, then the body's, so that each hit leaves its kind in the
// mask and the mask ends with the body's mark over the spray's.
void SprayPass::draw_maps(const FrameContext& frame) {
  packed_.clear();
  for (const auto* list : {&spray_, &body_})
    for (const SprayBall& b : *list) packed_.emplace_back(b.centre, b.radius);
  glNamedBufferData(
      parcels_.id(),
      static_cast<GLsizeiptr>(std::max<std::size_t>(packed_.size(), 1) * sizeof(glm::vec4)),
      packed_.data(), GL_STREAM_DRAW);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, storage_buffer::kParcelsBuffer, parcels_.id());
  depth_program_.use();
  u_depth_projection_.set(frame.camera.projection);
  u_depth_spray_.set(static_cast<int>(spray_.size()));
  u_depth_near_.set(frame.camera.near_m);
  glBindVertexArray(vao_.id());
  glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, static_cast<GLsizei>(packed_.size()));
}

SprayCompositePass::SprayCompositePass(SharedResources&, const SprayPass& spray)
    : spray_(spray), program_("spray_runs.vert", "spray_composite.frag") {}

void SprayCompositePass::execute(const FrameContext&, const FrameResources&) {
  program_.use();
  runs_.draw(spray_.runs());
}

}  // namespace downpour::render
