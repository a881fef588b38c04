// What the rain layer draws besides the streaks (rain_layer.cpp), and what hides them: the cars'
// outlines, against which each streak's depth is tested, and the splashes' crowns on the road and
// the car. No GL.
#include <algorithm>
#include <cmath>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>

#include "server/render/cpu/rain_layer.hpp"

namespace downpour::render {

namespace {

// The convex hull of eight points, counter-clockwise (Andrew's monotone chain); returns its size.
int convex_hull(const glm::vec2 (&points)[8], glm::vec2 (&hull)[16]) {
  glm::vec2 p[8];
  std::copy(std::begin(points), std::end(points), p);
  std::sort(p, p + 8,
            [](glm::vec2 a, glm::vec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  auto turn = [](glm::vec2 o, glm::vec2 a, glm::vec2 b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
  };
  int n = 0;
  for (int i = 0; i < 8; ++i) {  // lower
    while (n >= 2 && turn(hull[n - 2], hull[n - 1], p[i]) <= 0.0f) --n;
    hull[n++] = p[i];
  }
  for (int i = 6, lower = n + 1; i >= 0; --i) {  // upper
    while (n >= lower && turn(hull[n - 2], hull[n - 1], p[i]) <= 0.0f) --n;
    hull[n++] = p[i];
  }
  return n - 1;  // the last point is the first again
}

}  // namespace

const std::uint16_t* RainLayer::occlude(const RainLayerInputs& in, float sx, float sy, float cx,
                                        float cy) {
  // Last frame's rectangles back to none.
  for (int y = occluded_.y0; y < occluded_.y1; ++y) {
    std::fill_n(occluder_depth_.begin() + static_cast<std::size_t>(y) * width_ + occluded_.x0,
                occluded_.x1 - occluded_.x0, kUntouched);
  }
  occluded_ = Bounds{};
  const std::size_t texels = static_cast<std::size_t>(width_) * height_;
  if (in.scene_depth_cm.size() == texels && texels > 0) {
    std::copy(in.scene_depth_cm.begin(), in.scene_depth_cm.end(), occluder_depth_.begin());
    occluded_ = Bounds{0, 0, width_, height_};
  }
  if (in.occluders.empty()) return occluded_.empty() ? nullptr : occluder_depth_.data();
  for (const RainOccluder& o : in.occluders) {
    // To the camera in double (the world is kilometres wide), then float.
    const glm::mat4 to_camera(glm::dmat4(in.view) * o.to_world);
    float near = 1e30f;
    glm::vec2 corners[8];
    bool behind = false;
    for (int c = 0; c < 8; ++c) {
      const glm::vec3 corner((c & 1) ? o.hi.x : o.lo.x, (c & 2) ? o.hi.y : o.lo.y,
                             (c & 4) ? o.hi.z : o.lo.z);
      const glm::vec3 v(to_camera * glm::vec4(corner, 1.0f));
      const float depth = -v.z;
      if (depth < 0.1f) {
        behind = true;  // a box around the camera or behind it: no outline to draw
        break;
      }
      near = std::min(near, depth);
      corners[c] = glm::vec2(cx + sx * v.x / depth, cy + sy * v.y / depth);
    }
    if (behind) continue;
    // The box's outline: the convex hull of its corners (a box projects to a convex polygon).
    glm::vec2 hull[16];
    const int n = convex_hull(corners, hull);
    float y_lo = hull[0].y, y_hi = hull[0].y;
    for (int k = 1; k < n; ++k) y_lo = std::min(y_lo, hull[k].y), y_hi = std::max(y_hi, hull[k].y);
    // Each row whose texel centres it spans, the texels whose centres lie inside it.
    const int iy0 = std::max(0, static_cast<int>(std::ceil(y_lo - 0.5f)));
    const int iy1 = std::min(height_ - 1, static_cast<int>(std::floor(y_hi - 0.5f)));
    for (int y = iy0; y <= iy1; ++y) {
      const float yc = y + 0.5f;
      float x_lo = 1e9f, x_hi = -1e9f;
      for (int k = 0; k < n; ++k) {
        const glm::vec2 a = hull[k], e = hull[(k + 1) % n];
        if ((a.y <= yc) == (e.y <= yc)) continue;  // the edge does not cross this row
        const float x = a.x + (yc - a.y) * (e.x - a.x) / (e.y - a.y);
        x_lo = std::min(x_lo, x), x_hi = std::max(x_hi, x);
      }
      const int ix0 = std::max(0, static_cast<int>(std::ceil(std::max(x_lo, -1.0f) - 0.5f)));
      const int ix1 =
          std::min(width_ - 1, static_cast<int>(std::floor(std::min(x_hi, 1e7f) - 0.5f)));
      if (ix0 > ix1) continue;
      std::uint16_t* row = &occluder_depth_[static_cast<std::size_t>(y) * width_];
      const std::uint16_t near_cm = depth_cm(near);
      for (int x = ix0; x <= ix1; ++x) row[x] = std::min(row[x], near_cm);
      const Bounds span{ix0, y, ix1 + 1, y + 1};
      occluded_ = occluded_.empty()
                      ? span
                      : Bounds{std::min(occluded_.x0, span.x0), std::min(occluded_.y0, span.y0),
                               std::max(occluded_.x1, span.x1), std::max(occluded_.y1, span.y1)};
    }
  }
  return occluded_.empty() ? nullptr : occluder_depth_.data();
}

RainLayer::Bounds RainLayer::draw_splashes(const sim::RainState& rain, const RainLayerInputs& in,
                                           const glm::mat4& view, float sx, float sy, float cx,
                                           float cy, std::vector<Texel>& out) const {
  if (rain.splashes.empty()) return {};
  // The car's frame to the camera's, for the splashes on it (they move with the car).
  const glm::mat4 car_view(glm::dmat4(in.view) * in.vehicle_to_world);
  int lo_x = width_, lo_y = height_, hi_x = 0, hi_y = 0;
  // One point's light, shared by the four texels around it.
  auto point = [&](const glm::vec3& v, float alpha, bool occludable) {
    const float depth = -v.z;
    if (depth < kNearestSplashM) return;
    const float x = cx + sx * v.x / depth - 0.5f, y = cy + sy * v.y / depth - 0.5f;
    if (!(x >= 0.0f && y >= 0.0f && x < width_ - 1.0f && y < height_ - 1.0f)) return;
    const int ix = static_cast<int>(x), iy = static_cast<int>(y);
    const float fx = x - ix, fy = y - iy;
    const std::size_t at = static_cast<std::size_t>(iy) * width_ + ix;
    const float w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    const std::size_t texel[4] = {at, at + 1, at + width_, at + width_ + 1};
    const std::uint16_t depth_c = depth_cm(depth);
    for (int k = 0; k < 4; ++k) {
      if (occludable && !occluded_.empty() && depth_c > occluder_depth_[texel[k]]) continue;
      add(out[texel[k]], static_cast<std::uint32_t>(alpha * w[k] * kAlphaUnits + 0.5f), depth_c);
    }
    lo_x = std::min(lo_x, ix), hi_x = std::max(hi_x, ix + 2);
    lo_y = std::min(lo_y, iy), hi_y = std::max(hi_y, iy + 2);
  };
  // A point that moves by `blur` (camera frame) during the exposure: a few points along its path,
  // one a texel or so, as a streak is drawn.
  auto splat = [&](const glm::vec3& v, const glm::vec3& blur, float alpha, bool occludable) {
    const glm::vec3 tail = v + blur;
    const float depth = -v.z, tail_depth = -tail.z;
    int steps = 1;
    if (depth > kNearestSplashM && tail_depth > kNearestSplashM) {
      const float dx = sx * (tail.x / tail_depth - v.x / depth);
      const float dy = sy * (tail.y / tail_depth - v.y / depth);
      steps = std::clamp(static_cast<int>(std::max(std::abs(dx), std::abs(dy))) + 1, 1,
                         kMaxSplashSteps);
    }
    for (int i = 0; i < steps; ++i) {
      const float t = steps == 1 ? 0.0f : (i + 0.5f) / steps;
      point(v + blur * t, alpha / steps, occludable);
    }
  };
  // A splash on the road is still in the world: relative to the camera it moves back by the car's
  // velocity, and during the exposure it was where the camera will have been. One on the car moves
  // with it and with the camera (every view's camera rides on the car).
  const float exposure = static_cast<float>(in.exposure_s);
  const glm::vec3 road_blur = glm::mat3(view) * glm::vec3(in.camera_velocity) * exposure;
  const float dt = static_cast<float>(in.dt_s);
  for (const sim::SplashState& s : rain.splashes) {
    const float age = (s.age_s + dt) / static_cast<float>(sim::kSplashLifeS);
    if (age < 0.0f || age > 1.0f) continue;
    // The crown (Worthington's and Yarin's pictures of a drop on a wet surface): a ring of
    // droplets that widens to several times the drop and rises about as high, then falls back.
    const float d_m = s.diameter_mm * 1e-3f;
    const float radius = d_m * (1.0f + 5.0f * age);
    const float height = d_m * 5.0f * std::sin(3.14159265f * age);
    const glm::mat4& m = s.on_car ? car_view : view;
    const glm::vec3 centre(m * glm::vec4(s.position + glm::vec3(0.0f, 0.0f, 0.6f * height), 1.0f));
    const float depth = -centre.z;
    if (depth < kNearestSplashM) continue;
    // Its wall's area seen from the camera, in texels, as opacity: a thin sheet of water, half
    // of it hidden by the other half. The same across layer sizes, as the streaks.
    const float texels_per_m = sy / depth;
    const float wall = 2.0f * radius * height * texels_per_m * texels_per_m;
    const float fade = 1.0f - age;
    const float alpha_total = in.opacity * kSplashBrightness * std::min(wall, 4.0f) * fade;
    if (alpha_total < 1e-3f) continue;
    // A dot far away; a ring of points where the crown is a few texels wide.
    const float ring_texels = 6.2832f * radius * texels_per_m;
    const int points = std::clamp(static_cast<int>(ring_texels), 1, 16);
    const glm::vec3 blur = s.on_car ? glm::vec3(0.0f) : road_blur;
    if (points < 3) {
      splat(centre, blur, alpha_total, !s.on_car);
      continue;
    }
    const glm::vec3 up(m * glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
    const glm::vec3 e1(m * glm::vec4(radius, 0.0f, 0.0f, 0.0f));
    const glm::vec3 e2(m * glm::vec4(0.0f, radius, 0.0f, 0.0f));
    for (int k = 0; k < points; ++k) {
      const float a = 6.2832f * (k + 0.5f * age) / points;
      splat(centre + e1 * std::cos(a) + e2 * std::sin(a) + up * (0.4f * height), blur,
            alpha_total / points, !s.on_car);
    }
  }
  return lo_x < hi_x ? Bounds{lo_x, lo_y, hi_x, hi_y} : Bounds{};
}

}  // namespace downpour::render
