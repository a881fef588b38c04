// The rain layer's streaks (rain_layer.hpp): each drop projected in batches as vector code, drawn
// as a Wu line into 16-bit texels on two threads, resolved to premultiplied colour and cut into
// the runs of tiles the composite draws. The occluders and splashes are in rain_layer_splashes.cpp.
#include "server/render/cpu/rain_layer.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "server/render/cpu/cabin_tiles.hpp"
#include "server/render/cpu/display.hpp"
#include "server/render/cpu/light_set.hpp"
#include "server/sim/random.hpp"

namespace downpour::render {

namespace {

// Terminal speed by diameter, over the field's sizes (0-8 mm).
struct SpeedTable {
  static constexpr int kSteps = 256;
  static constexpr float kStepMm = 8.0f / kSteps;
  float speed[kSteps + 1];
  float at(float diameter_mm) const {
    return speed[std::clamp(static_cast<int>(diameter_mm / kStepMm + 0.5f), 0, kSteps)];
  }
};
const SpeedTable& speed_table() {
  static const SpeedTable table = [] {
    SpeedTable t;
    for (int i = 0; i <= SpeedTable::kSteps; ++i)
      t.speed[i] = static_cast<float>(sim::terminal_speed_mps(i * SpeedTable::kStepMm));
    return t;
  }();
  return table;
}

// A texel's coverage in bytes for its summed opacities: independent coverings, 1 - exp(-sum).
struct CoverageTable {
  static constexpr int kSteps = 512;
  static constexpr float kMax = 8.0f;
  std::uint32_t coverage[kSteps + 1];
  // For a sum in RainLayer's units (1/4096): alpha * kSteps / kMax is sum / 64.
  std::uint32_t at_units(std::uint32_t sum) const {
    static_assert(kSteps / kMax * 64.0f == 4096.0f);
    return coverage[std::min((sum + 32) / 64, std::uint32_t{kSteps})];
  }
};
const CoverageTable& coverage_table() {
  static const CoverageTable table = [] {
    CoverageTable t;
    for (int i = 0; i <= CoverageTable::kSteps; ++i) {
      const float a = 1.0f - std::exp(-CoverageTable::kMax * i / CoverageTable::kSteps);
      t.coverage[i] = static_cast<std::uint32_t>(a * 255.0f + 0.5f);
    }
    return t;
  }();
  return table;
}

}  // namespace

struct RainLayer::Batch {
  float x[kBatch], y[kBatch], z[kBatch], diameter[kBatch], speed[kBatch];
  float far_fade[kBatch], top_fade[kBatch];
  std::int32_t pick[kBatch];  // the drop's own number in 24 bits, the same every frame (thinning)
  float head_x[kBatch], head_y[kBatch], head_z[kBatch];
  float motion_x[kBatch], motion_y[kBatch], motion_z[kBatch], reach[kBatch];
  // The copy being drawn, per drop: its streak's head on the layer, its depth, opacity (0 where
  // none is drawn) and width, and its line along the major axis (x_major: the layer's x), from a0
  // to a1 >= a0, across from b0 by slope per texel along.
  float hx[kBatch], hy[kBatch], depth[kBatch], alpha[kBatch], width[kBatch];
  float a0[kBatch], a1[kBatch], b0[kBatch], b1[kBatch], slope[kBatch];
  std::int32_t x_major[kBatch];
  std::uint16_t visible[kBatch];  // the drops whose copy is drawn
};

// The haze's transmittance by distance, in a table per build (0-64 m, this view's haze).
constexpr int kHazeSteps = 256;
constexpr float kHazeStepM = 64.0f / kHazeSteps;
constexpr std::uint32_t kHazeStepCm = 25;  // kHazeStepM
static_assert(kHazeStepCm == static_cast<std::uint32_t>(kHazeStepM * 100.0f));
// The far streaks' thinning (project_copy). The span of the drops' numbers over which a streak
// fades in:
constexpr float kThinFade = 0.125f;
// The least share drawn: the fewer, each the more opaque, the more the coverage where they overlap,
// 1 - exp(-sum), falls short of the mean (3% at a half, 11% at a tenth).
constexpr float kLeastFarShare = 0.25f;

struct RainLayer::Frame {
  Frame(const sim::RainState& rain, const RainLayerInputs& in, int width, int height);

  // Every drop of the batch, then its copy c, as branch-free arithmetic over arrays, which the
  // compiler turns into vector code: the projection, the cull, the opacity and the line's set-up.
  void project(Batch& b, int n) const;
  void project_copy(Batch& b, int n, int c) const;
  // The lamps' light on a drop at p (camera frame), in levels (Texels::lit).
  std::uint32_t lamp_level(const glm::vec3& p) const;

  const sim::RainState& rain;
  const RainLayerInputs& in;
  int width, height;
  glm::mat4 view;  // from the field's origin to the camera
  glm::mat3 rotate;
  // In the camera's frame: the fall's direction, the wind, and the drift of every drop relative
  // to the camera (wind less the camera's velocity); a drop's velocity is fall x its speed + wind.
  glm::vec3 fall_v, wind_v, relative_drift_v;
  float dt, exposure;
  float tan_x, tan_y, sx, sy, cx, cy;
  int max_steps;
  float px, opacity;
  // The share of far streaks drawn, and how fast the share falls to it from kThinFromM (per m).
  float far_share, thin_slope;
  static_assert(RainLayerInputs::kThinToM > RainLayerInputs::kThinFromM);
  // The box repeats across and along: its drops are drawn again one box width to each side, so
  // that the rain fills the view to its edges where the view is wider than the box (far ahead) and
  // the box's sides leave no seam; and, for a camera behind the box (the chase camera), one box
  // length back as well, so that there is rain between that camera and the car. The drops wrap at
  // the box's sides and ends already, so the copies continue the same field. (Upwards the view's
  // top is the sky, far off, where the haze hides what streaks there would be; the box's top
  // fades out instead.)
  struct Copy {
    glm::vec3 offset_v;
    bool behind;  // continues the box's near end: its far-end fade does not apply
  };
  Copy copies[kMaxCopies];
  int copy_count = 3;
  float transmittance[kHazeSteps + 1];
  std::size_t lamp_count;
  // The occluders' depths per texel, or null where no occluder covers the layer (occlude()).
  const std::uint16_t* occluded = nullptr;
};

RainLayer::Frame::Frame(const sim::RainState& rain, const RainLayerInputs& in, int width,
                        int height)
    : rain(rain), in(in), width(width), height(height) {
  // Drops are relative to the field's origin; so is the camera here, so that floats keep
  // millimetres wherever the car is.
  const glm::dvec3 origin = rain.origin_m;
  glm::dmat4 to_origin(1.0);
  to_origin[3] = glm::dvec4(origin, 1.0);
  view = glm::mat4(glm::dmat4(in.view) * to_origin);
  rotate = glm::mat3(view);
  fall_v = rotate * rain.fall_direction;
  wind_v = rotate * rain.wind_mps;
  relative_drift_v = rotate * (rain.wind_mps - glm::vec3(in.camera_velocity));
  dt = static_cast<float>(in.dt_s);
  exposure = static_cast<float>(in.exposure_s);
  tan_x = static_cast<float>(in.tan_half_fov_x);
  tan_y = static_cast<float>(in.tan_half_fov_y);
  sx = 0.5f * width / static_cast<float>(in.tan_half_fov_x);
  sy = 0.5f * height / static_cast<float>(in.tan_half_fov_y);
  cx = 0.5f * width, cy = 0.5f * height;
  max_steps = 2 * (width + height);
  px = in.pixels_per_texel;
  opacity = in.opacity;
  far_share = std::clamp(in.far_share, kLeastFarShare, 1.0f);
  thin_slope = (1.0f - far_share) / (RainLayerInputs::kThinToM - RainLayerInputs::kThinFromM);
  const glm::vec3 across = rotate * (rain.box_left * (2.0f * rain.box_half_m.y));
  const glm::vec3 back = rotate * (rain.box_forward * (-2.0f * rain.box_half_m.x));
  copies[0] = {glm::vec3(0.0f), false};
  copies[1] = {across, false};
  copies[2] = {-across, false};
  const glm::dvec3 camera = glm::dvec3(glm::inverse(in.view)[3]) - origin;
  if (glm::dot(glm::vec3(camera), rain.box_forward) < -rain.box_half_m.x + kNearestM) {
    copies[copy_count++] = {back, true};
    copies[copy_count++] = {back + across, true};
    copies[copy_count++] = {back - across, true};
  }
  // A table instead of an exp per drop.
  for (int i = 0; i <= kHazeSteps; ++i)
    transmittance[i] = std::exp(-in.haze_per_m * i * kHazeStepM);
  lamp_count = std::min(in.lamps.size(), RainLayerInputs::kMaxLamps);
}

void RainLayer::Frame::project(Batch& b, int n) const {
  for (int i = 0; i < n; ++i) {
    const glm::vec3 rel(b.x[i], b.y[i], b.z[i]);
    const glm::vec3 head =
        glm::vec3(view * glm::vec4(rel, 1.0f)) + (fall_v * b.speed[i] + wind_v) * dt;
    b.head_x[i] = head.x, b.head_y[i] = head.y, b.head_z[i] = head.z;
    // The streak: from the head back along the drop's motion relative to the camera.
    const glm::vec3 motion = (fall_v * b.speed[i] + relative_drift_v) * exposure;
    b.motion_x[i] = motion.x, b.motion_y[i] = motion.y, b.motion_z[i] = motion.z;
    b.reach[i] = std::abs(motion.x) + std::abs(motion.y) + std::abs(motion.z);
    // The box's far end and top fade out; its sides are seamless (the copies).
    b.far_fade[i] = std::clamp(
        (rain.box_half_m.x - glm::dot(rel, rain.box_forward)) * (1.0f / 8.0f), 0.0f, 1.0f);
    b.top_fade[i] = std::clamp((rain.box_half_m.z - rel.z) * (1.0f / 1.5f), 0.0f, 1.0f);
  }
}

void RainLayer::Frame::project_copy(Batch& b, int n, int c) const {
  const glm::vec3 offset = copies[c].offset_v;
  const float behind = copies[c].behind ? 1.0f : 0.0f;
  // (Copies: std::clamp takes its bounds by reference, and a member's would make the compiler
  // check at run time whether the stores below write it, and keep a scalar loop for that.)
  const float floor_share = far_share, share_slope = thin_slope;
  for (int i = 0; i < n; ++i) {
    const float hvx = b.head_x[i] + offset.x, hvy = b.head_y[i] + offset.y;
    const float depth = -(b.head_z[i] + offset.z);
    const float reach = b.reach[i];
    // Drops nearer than kNearestM are not drawn (any eye or camera focused on the road sees
    // them as a faint blur). Most copies lie wholly outside the view: a streak whose head is
    // further out of the view than the streak reaches cannot come into it.
    // (& and |, not && and ||: no branches, so that the loop is vector code.)
    bool visible = (depth >= kNearestM) & (std::abs(hvx) - reach <= tan_x * (depth + reach)) &
                   (std::abs(hvy) - reach <= tan_y * (depth + reach));
    float tvx = hvx - b.motion_x[i], tvy = hvy - b.motion_y[i];
    float tail_depth = depth + b.motion_z[i];
    // A tail behind the camera: cut where the streak comes within 6 cm of it.
    const bool cut = tail_depth < 0.06f;
    const float t = cut ? (depth - 0.06f) / std::max(depth - tail_depth, 1e-6f) : 1.0f;
    tvx = hvx + (tvx - hvx) * t;
    tvy = hvy + (tvy - hvy) * t;
    tail_depth = cut ? 0.06f : tail_depth;
    const float inv_depth = 1.0f / std::max(depth, kNearestM);
    const float inv_tail = 1.0f / std::max(tail_depth, 0.06f);
    const float hx = cx + sx * hvx * inv_depth, hy = cy + sy * hvy * inv_depth;
    const float tx = cx + sx * tvx * inv_tail, ty = cy + sy * tvy * inv_tail;
    visible = visible & !(((hx < 0.0f) & (tx < 0.0f)) | ((hy < 0.0f) & (ty < 0.0f)) |
                          ((hx >= width) & (tx >= width)) | ((hy >= height) & (ty >= height)));
    // Widths and lengths in the view's pixels, for the same opacity at any layer size.
    const float true_width = b.diameter[i] * 1e-3f * sy * inv_depth * px;
    const float half_width = 0.5f * std::max(true_width, 1.0f) + 0.5f;
    const float core = std::clamp(true_width / (2.0f * half_width), 0.0f, 1.0f);
    const float length = std::max(std::abs(tx - hx), std::abs(ty - hy));
    const float spread = std::clamp(2.0f * half_width / std::max(length * px, 1.0f), 0.3f, 1.0f);
    // Haze (seed 004): far streaks fade in steps of opacity, 3/4, 1/2 and 1/4, by distance.
    const float level = depth < 5.0f ? 1.0f : depth < 10.0f ? 0.75f : depth < 16.0f ? 0.5f : 0.25f;
    const float fade = std::max(behind, b.far_fade[i]) * b.top_fade[i];
    // Far streaks thinned (RainLayerInputs::far_share): the share drawn at this depth, and this
    // drop's weight by its number, w(pick) = clamp((k - pick) / kThinFade, 0, 1), with k such
    // that w's mean over numbers in [0, 1) is the share; so a streak fades in over kThinFade of
    // the numbers as the camera nears it rather than appears at once. Where w's ramp lies within
    // [0, 1), k = share + kThinFade / 2; where it passes 1 (a share near 1), the root below; at
    // the share 1, k = 1 + kThinFade: every weight 1.
    const float share =
        std::clamp(1.0f - (depth - RainLayerInputs::kThinFromM) * share_slope, floor_share, 1.0f);
    const float k = share <= 1.0f - 0.5f * kThinFade
                        ? share + 0.5f * kThinFade
                        : 1.0f + kThinFade - std::sqrt(2.0f * kThinFade * (1.0f - share));
    const float pick = static_cast<float>(b.pick[i]) * (1.0f / 16777216.0f);
    const float weight = std::clamp((k - pick) * (1.0f / kThinFade), 0.0f, 1.0f);
    const float alpha = opacity * level * fade * (0.35f + 0.65f * core) * spread * weight / share;
    b.hx[i] = hx, b.hy[i] = hy;
    b.depth[i] = depth;
    b.alpha[i] = visible ? alpha : 0.0f;
    b.width[i] = true_width;
    // The Wu line's set-up (draw_streak): along the major axis from its lower end.
    const bool x_major = std::abs(tx - hx) >= std::abs(ty - hy);
    const float a_head = x_major ? hx : hy, a_tail = x_major ? tx : ty;
    const float b_head = x_major ? hy : hx, b_tail = x_major ? ty : tx;
    const bool swap = a_tail < a_head;
    const float a0 = swap ? a_tail : a_head, a1 = swap ? a_head : a_tail;
    const float b0 = swap ? b_tail : b_head, b1 = swap ? b_head : b_tail;
    b.a0[i] = a0, b.a1[i] = a1, b.b0[i] = b0, b.b1[i] = b1;
    b.slope[i] = a1 - a0 > 1e-6f ? (b1 - b0) / std::max(a1 - a0, 1e-6f) : 0.0f;
    b.x_major[i] = x_major ? 1 : 0;
  }
}

std::uint32_t RainLayer::Frame::lamp_level(const glm::vec3& p) const {
  float radiance = 0.0f;
  const glm::vec3 to_camera = -p / std::max(glm::length(p), 1e-3f);
  for (std::size_t k = 0; k < lamp_count; ++k) {
    const RainLamp& lamp = in.lamps[k];
    const glm::vec3 to = p - lamp.position;
    const float d2 = std::max(glm::dot(to, to), 0.25f);
    const glm::vec3 l = to / std::sqrt(d2);
    const float t = std::clamp((glm::dot(l, lamp.axis) - lamp.cos_outer) /
                                   std::max(lamp.cos_inner - lamp.cos_outer, 1e-4f),
                               0.0f, 1.0f);
    float beam = t * t * (3.0f - 2.0f * t);
    if (lamp.low_beam) beam *= dipped_cut(-glm::dot(l, lamp.left), glm::dot(l, in.up));
    radiance += lamp.intensity * drop_phase(glm::dot(l, to_camera)) * beam / d2;
  }
  const float level = std::sqrt(std::min(radiance / kLitMax, 1.0f)) * (kLitLevels - 1);
  return static_cast<std::uint32_t>(level + 0.5f);
}

RainLayer::RainLayer() : batches_{std::make_unique<Batch>(), std::make_unique<Batch>()} {}
RainLayer::~RainLayer() = default;

void RainLayer::reset(int width, int height) {
  const std::size_t texels = static_cast<std::size_t>(std::max(width, 0)) * std::max(height, 0);
  if (width != width_ || height != height_) {
    width_ = width;
    height_ = height;
    texels_.sum.assign(texels, Texel{});
    texels_.lit.assign(texels, 0);
    occluder_depth_.assign(texels, kUntouched);
    occluded_ = Bounds{};
    second_.sum.assign(texels, Texel{});
    second_.lit.assign(texels, 0);
    colour_.assign(texels, 0u);
    tiles_x_ = (width + kTile - 1) / kTile;
    tile_lit_.assign(static_cast<std::size_t>(tiles_x_) * ((height + kTile - 1) / kTile), 0);
  } else {
    // The texels were left clear by the last resolve; the output is cleared where it wrote.
    for (int y = bounds_.y0; y < bounds_.y1; ++y) {
      const std::size_t row = static_cast<std::size_t>(y) * width + bounds_.x0;
      std::fill_n(colour_.begin() + row, bounds_.x1 - bounds_.x0, 0u);
    }
  }
  bounds_ = Bounds{};
  runs_.clear();
  clear_runs_ = 0;
}

std::uint32_t RainLayer::build(const sim::RainState& rain, const RainLayerInputs& in, int width,
                               int height) {
  reset(width, height);
  if (rain.drops.empty() || width <= 0 || height <= 0) return 0;
  Frame f(rain, in, width, height);
  // What a streak leaves in a texel, unless a car nearer than it covers the texel.
  f.occluded = occlude(in, f.sx, f.sy, f.cx, f.cy);
  // Two shares of the drops on two threads, each into texels of its own, summed in a fixed order:
  // the same drops give the same layer. The second thread splats the splashes too, after its
  // drops, and so draws fewer of them, by the splashes' cost: the two end about together, where
  // this thread splatted them alone after both had drawn their halves (0.6 ms of 5.5 at 80,000
  // streaks). A second thread pays for itself only past a few thousand drops.
  const std::size_t n = rain.drops.size();
  Bounds dirty_first, dirty_second, dirty_splashes;
  std::uint32_t drawn = 0;
  if (n >= kDropsForTwoThreads) {
    const double splashes = kDropsPerSplash * static_cast<double>(rain.splashes.size());
    const auto second =
        static_cast<std::size_t>(std::max(0.0, 0.5 * (static_cast<double>(n) - splashes)));
    std::uint32_t drawn_second = 0;
    helper_.start([&] {
      drawn_second = draw(f, 0, second, second_, dirty_second, *batches_[1]);
      dirty_splashes = draw_splashes(rain, in, f.view, f.sx, f.sy, f.cx, f.cy, second_.sum);
    });
    drawn = draw(f, second, n, texels_, dirty_first, *batches_[0]);
    helper_.wait();
    drawn += drawn_second;
  } else {
    drawn = draw(f, 0, n, texels_, dirty_first, *batches_[0]);
    dirty_splashes = draw_splashes(rain, in, f.view, f.sx, f.sy, f.cx, f.cy, texels_.sum);
  }

  // The texels with rain: the dirty rectangles of both threads and of the splashes.
  Bounds b;
  for (const Bounds& d : {dirty_first, dirty_second, dirty_splashes}) {
    if (d.empty()) continue;
    b = b.empty() ? d
                  : Bounds{std::min(b.x0, d.x0), std::min(b.y0, d.y0), std::max(b.x1, d.x1),
                           std::max(b.y1, d.y1)};
  }
  if (b.empty()) return drawn;
  resolve(f, in, b);
  bounds_ = b;
  make_runs(in, b);
  return drawn;
}

std::uint32_t RainLayer::draw(const Frame& f, std::size_t begin, std::size_t end, Texels& out,
                              Bounds& dirty, Batch& bt) const {
  // Each thread works through its drops in batches: every drop of the batch as vector code
  // (Frame::project), then for each copy of the box, its copies of them as vector code as well
  // (Frame::project_copy) and the streaks that came out visible, one by one, as Wu lines.
  const SpeedTable& speeds = speed_table();
  std::uint32_t drawn = 0;
  Bounds touched{width_, height_, 0, 0};
  for (std::size_t first_drop = begin; first_drop < end; first_drop += kBatch) {
    const int n = static_cast<int>(std::min<std::size_t>(kBatch, end - first_drop));
    for (int i = 0; i < n; ++i) {
      const glm::vec4& drop = f.rain.drops[first_drop + i];
      bt.x[i] = drop.x, bt.y[i] = drop.y, bt.z[i] = drop.z, bt.diameter[i] = drop.w;
      bt.speed[i] = speeds.at(drop.w);
      // The drop's number for the thinning, from its index in the field, which it keeps while it
      // falls and when it is born again; the same in every copy of the box, which carry the field
      // on across its sides (a drop that wraps is drawn the same in the copy it moves into).
      bt.pick[i] = static_cast<std::int32_t>(sim::RandomStream::mix(first_drop + i) >> 40);
    }
    f.project(bt, n);
    for (int c = 0; c < f.copy_count; ++c) {
      f.project_copy(bt, n, c);
      // The visible streaks' indices first, without a branch (about half of the copies are
      // visible, at random: a branch per copy would mispredict often).
      int visible = 0;
      for (int i = 0; i < n; ++i) {
        bt.visible[visible] = static_cast<std::uint16_t>(i);
        visible += bt.alpha[i] > 0.0f;
      }
      drawn += static_cast<std::uint32_t>(visible);
      for (int v = 0; v < visible; ++v) draw_streak(f, bt, bt.visible[v], out, touched);
    }
  }
  dirty = touched.empty() ? Bounds{} : touched;
  return drawn;
}

void RainLayer::draw_streak(const Frame& f, const Batch& bt, int i, Texels& out,
                            Bounds& touched) const {
  const int width = f.width, height = f.height;
  const float depth = bt.depth[i], true_width = bt.width[i];
  const float units = bt.alpha[i] * kAlphaUnits;
  const auto whole = static_cast<std::uint32_t>(units + 0.5f);
  const std::uint16_t depth_c = depth_cm(depth);
  // The lamps' light at the streak's head (back from the screen to the camera's frame).
  const std::uint32_t level =
      f.lamp_count ? f.lamp_level(glm::vec3((bt.hx[i] - f.cx) / f.sx * depth,
                                            (bt.hy[i] - f.cy) / f.sy * depth, -depth))
                   : 0;

  // A Wu line, clipped to the layer: one texel a column along its major axis, shared by the
  // two nearest across (and whole texels between them for a drop wider than a texel).
  const bool x_major = bt.x_major[i] != 0;
  const float a0 = bt.a0[i], a1 = bt.a1[i];  // along the major axis, a0 <= a1
  const float b0 = bt.b0[i], b1 = bt.b1[i];  // across, at a0 and a1
  const float slope = bt.slope[i];
  const int major_size = x_major ? width : height, minor_size = x_major ? height : width;
  int first = std::max(0, static_cast<int>(std::floor(a0)));
  int last = std::min({major_size - 1, static_cast<int>(std::floor(a1)), first + f.max_steps});
  // Wide near drops cover whole texels between the two shared ones.
  const int extra = std::min(static_cast<int>(true_width / f.px * 0.5f), kMaxExtraTexels);
  // Clip the columns to those whose texels across lie inside the layer, so that the loop
  // below needs no test per texel: b(m) = b0 + (m + 0.5 - a0) * slope - 0.5 must stay in
  // [extra, minor_size - 2 - extra].
  const float b_lo = static_cast<float>(extra), b_hi = static_cast<float>(minor_size - 2 - extra);
  if (b_hi < b_lo) return;
  auto b_at = [&](float m) { return b0 + (m + 0.5f - a0) * slope - 0.5f; };
  // Most streaks lie well inside across (b(m) stays within half a texel of [b0, b1] less
  // half a texel): no clipping then.
  const bool inside = std::min(b0, b1) - 1.0f >= b_lo && std::max(b0, b1) <= b_hi;
  if (!inside && slope != 0.0f) {
    // m where b(m) crosses b_lo and b_hi; the columns between them are inside.
    const float m_lo = (b_lo + 0.5f - b0) / slope + a0 - 0.5f;
    const float m_hi = (b_hi + 0.5f - b0) / slope + a0 - 0.5f;
    // Within the layer before they become ints (a nearly flat streak's are far out).
    const float m_min = std::clamp(std::min(m_lo, m_hi), -1.0f, float(major_size));
    const float m_max = std::clamp(std::max(m_lo, m_hi), -1.0f, float(major_size));
    first = std::max(first, static_cast<int>(std::ceil(m_min)));
    last = std::min(last, static_cast<int>(std::floor(m_max)));
    // Rounding at the ends: step inwards while a column is still outside.
    while (first <= last && !(b_at(first) >= b_lo && b_at(first) <= b_hi)) ++first;
    while (last >= first && !(b_at(last) >= b_lo && b_at(last) <= b_hi)) --last;
  } else if (!inside && !(b_at(0.0f) >= b_lo && b_at(0.0f) <= b_hi)) {
    return;
  }
  if (first > last) return;
  const std::size_t major_stride = x_major ? 1 : static_cast<std::size_t>(width);
  const std::size_t minor_stride = x_major ? static_cast<std::size_t>(width) : 1;
  // The texels across stay in [base_lo, base_hi + 1 + extra]: b(m) is inside them but for
  // rounding, which the clamp absorbs (a texel out of the layer would be written else).
  const int base_lo = extra, base_hi = minor_size - 2 - extra;
  // b(m) is linear: its extremes are at the ends.
  int b_min = std::clamp(static_cast<int>(std::min(b_at(first), b_at(last))), base_lo, base_hi);
  int b_max = std::clamp(static_cast<int>(std::max(b_at(first), b_at(last))), base_lo, base_hi);
  // The occluders' depths only for a streak whose texels may lie inside one: most lie
  // wholly outside them, and the lookups would be a second cache miss per texel.
  const int minor_lo = b_min - extra, minor_hi = b_max + extra + 2;
  const bool near_occluder =
      f.occluded && (x_major ? first < occluded_.x1 && last >= occluded_.x0 &&
                                   minor_lo < occluded_.y1 && minor_hi > occluded_.y0
                             : first < occluded_.y1 && last >= occluded_.y0 &&
                                   minor_lo < occluded_.x1 && minor_hi > occluded_.x0);
  const std::uint16_t* occ = near_occluder ? f.occluded : nullptr;
  // What a streak leaves in a texel, unless a car nearer than it covers the texel (`occ`: the
  // occluders' depths, or null for a streak that lies wholly outside them).
  auto put = [&](std::size_t k, std::uint32_t alpha) {
    if (occ && depth_c > occ[k]) return;
    add(out.sum[k], alpha, depth_c);
    if (level) add_lit(out.lit[k], alpha, level);
  };
  // b(m) in 1/65536 texel, stepped in integers: off the line by the rounding of its start and
  // slope (at most 1/65536 a column, under a hundredth of a texel over the longest streak). The
  // clamp to the ends' texels keeps every write inside the bounds found above (`touched` and the
  // occluders' test).
  constexpr float kFixed = 65536.0f;
  std::int32_t b_fixed =
      static_cast<std::int32_t>(std::lround(b_at(static_cast<float>(first)) * kFixed));
  const auto b_step = static_cast<std::int32_t>(std::lround(slope * kFixed));
  for (int m = first; m <= last; ++m, b_fixed += b_step) {
    const int base = std::clamp(b_fixed >> 16, b_min, b_max);
    const auto frac = static_cast<std::uint32_t>(std::clamp(b_fixed - (base << 16), 0, 1 << 16));
    std::size_t k = m * major_stride + (base - extra) * minor_stride;
    const std::uint32_t next_share = (whole * frac + (1u << 15)) >> 16;
    put(k, whole - next_share);
    for (int e = 1 - extra; e <= extra; ++e) {
      k += minor_stride;
      put(k, whole);
    }
    put(k + minor_stride, next_share);
  }
  b_min -= extra;
  b_max += extra + 2;
  if (x_major) {
    touched.x0 = std::min(touched.x0, first), touched.x1 = std::max(touched.x1, last + 1);
    touched.y0 = std::min(touched.y0, b_min), touched.y1 = std::max(touched.y1, b_max);
  } else {
    touched.y0 = std::min(touched.y0, first), touched.y1 = std::max(touched.y1, last + 1);
    touched.x0 = std::min(touched.x0, b_min), touched.x1 = std::max(touched.x1, b_max);
  }
}

void RainLayer::resolve(const Frame& f, const RainLayerInputs& in, const Bounds& b) {
  // Each texel's light and opacity, from tables: summed opacities combine as independent
  // coverings, 1 - exp(-sum), whatever the order; the streaks carry the light, hazed by the
  // distance of the nearest. By the nearest streak's distance and, with lamps, the texel's mean
  // lamp light.
  const int levels = f.lamp_count ? kLitLevels : 1;
  hazed_.resize(static_cast<std::size_t>(kHazeSteps + 1) * levels);
  for (int k = 0; k < levels; ++k) {
    const float l = static_cast<float>(k) / (kLitLevels - 1);
    const glm::vec3 light = in.light + in.lamp_colour * (l * l * kLitMax);
    for (int i = 0; i <= kHazeSteps; ++i) {
      const glm::vec3 c = to_display(glm::mix(in.haze, light, f.transmittance[i]));
      hazed_[static_cast<std::size_t>(k) * (kHazeSteps + 1) + i] = glm::uvec3(c * 255.0f + 0.5f);
    }
  }
  // Two halves of the rows on two threads, split between rows of tiles (two threads mark tiles
  // apart).
  const int mid = (b.y0 + b.y1) / 2 / kTile * kTile;
  if (b.y1 - b.y0 < 32 || mid <= b.y0) {
    resolve_rows(f, in, b, b.y0, b.y1);
  } else {
    helper_.start([&] { resolve_rows(f, in, b, mid, b.y1); });
    resolve_rows(f, in, b, b.y0, mid);
    helper_.wait();
  }
}

// Rows [y0, y1) of `b`: branch-free over every texel of the rows (whether a texel has rain is as
// good as random, and a branch on it mispredicts often); untouched texels come out 0.
void RainLayer::resolve_rows(const Frame& f, const RainLayerInputs& in, const Bounds& b, int y0,
                             int y1) {
  const CoverageTable& coverage = coverage_table();
  const int levels = f.lamp_count ? kLitLevels : 1;
  const bool cabin = in.cabin_tiles.size() == tile_lit_.size();
  const int x0 = b.x0, n = b.x1 - b.x0;
  for (int y = y0; y < y1; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * width_ + x0;
    Texel* first = &texels_.sum[row];
    Texel* second = &second_.sum[row];
    std::uint16_t* first_lit = &texels_.lit[row];
    std::uint16_t* second_lit = &second_.lit[row];
    std::uint32_t* out = &colour_[row];
    const std::uint8_t* hidden_row =
        cabin ? &in.cabin_tiles[static_cast<std::size_t>(y / kTile) * tiles_x_] : nullptr;
    int next_tile = 0;  // the next texel (from x0) that starts a tile
    for (int i = 0; i < n; ++i) {
      if (i == next_tile) {
        // A tile the cabin hides wholly: left 0 (the composite leaves it out).
        const int tx = (x0 + i) / kTile;
        next_tile = (tx + 1) * kTile - x0;
        if (hidden_row && hidden_row[tx] == kCabinHidden) {
          i = std::min(next_tile, n) - 1;
          continue;
        }
      }
      const std::uint32_t sum = std::uint32_t{first[i].alpha} + second[i].alpha;
      const std::uint32_t depth = std::min(first[i].depth, second[i].depth);
      const std::uint32_t a = coverage.at_units(sum);
      const std::uint32_t level =
          levels > 1 ? std::min<std::uint32_t>((std::uint32_t{first_lit[i]} + second_lit[i]) *
                                                   kLitLevels / std::max(sum, 1u),
                                               kLitLevels - 1)
                     : 0;
      const glm::uvec3& c = hazed_[level * (kHazeSteps + 1) +
                                   std::min(depth / kHazeStepCm, std::uint32_t{kHazeSteps})];
      // Premultiplied: each channel times the coverage, rounded, in bytes.
      out[i] = ((c.r * a + 127) / 255) | ((c.g * a + 127) / 255) << 8 |
               ((c.b * a + 127) / 255) << 16 | a << 24;
    }
    // Left clear for the next frame.
    std::fill_n(first, n, Texel{});
    std::fill_n(second, n, Texel{});
    if (levels > 1) {
      std::fill_n(first_lit, n, std::uint16_t{0});
      std::fill_n(second_lit, n, std::uint16_t{0});
    }
    // Each tile of the row with rain, and which of its edges has rain (bilinear magnification
    // carries a quarter of an edge texel into the next tile's first pixels).
    std::uint8_t* tiles = &tile_lit_[static_cast<std::size_t>(y / kTile) * tiles_x_];
    const std::uint8_t row_edge =
        (y % kTile == 0 ? kTileBottom : 0) | (y % kTile == kTile - 1 ? kTileTop : 0);
    for (int tx = x0 / kTile; tx * kTile < b.x1; ++tx) {
      const int t0 = std::max(tx * kTile, x0), t1 = std::min((tx + 1) * kTile, b.x1);
      bool any = false;
      for (int x = t0; x < t1; ++x) any |= out[x - x0] != 0u;
      if (!any) continue;
      const bool left = tx * kTile >= x0 && out[tx * kTile - x0] != 0u;
      const bool right = (tx + 1) * kTile <= b.x1 && out[(tx + 1) * kTile - 1 - x0] != 0u;
      tiles[tx] |= kTileLit | row_edge | (left ? kTileLeft : 0) | (right ? kTileRight : 0);
    }
  }
}

void RainLayer::make_runs(const RainLayerInputs& in, const Bounds& b) {
  // The runs of tiles to draw, row by row: those with rain and those beside a lit edge of one.
  const bool cabin = in.cabin_tiles.size() == tile_lit_.size();
  const int tiles_y = static_cast<int>(tile_lit_.size()) / tiles_x_;
  const int tx0 = std::max(b.x0 / kTile - 1, 0), tx1 = std::min((b.x1 - 1) / kTile + 2, tiles_x_);
  const int ty0 = std::max(b.y0 / kTile - 1, 0), ty1 = std::min((b.y1 - 1) / kTile + 2, tiles_y);
  auto at = [&](int tx, int ty) -> std::uint8_t {
    return tx < 0 || ty < 0 || tx >= tiles_x_ || ty >= tiles_y
               ? 0
               : tile_lit_[static_cast<std::size_t>(ty) * tiles_x_ + tx];
  };
  // What each tile is to the composite: left out, drawn as it is, or drawn depth-tested (the
  // cabin reaches into it).
  enum Draw { kSkip, kClear, kEdge };
  auto draw_as = [&](int tx, int ty) {
    const std::uint8_t c = cabin ? in.cabin_tiles[static_cast<std::size_t>(ty) * tiles_x_ + tx]
                                 : std::uint8_t{kCabinClear};
    if (c == kCabinHidden) return kSkip;
    const bool rain = (at(tx, ty) & kTileLit) || (at(tx - 1, ty) & kTileRight) ||
                      (at(tx + 1, ty) & kTileLeft) || (at(tx, ty - 1) & kTileTop) ||
                      (at(tx, ty + 1) & kTileBottom);
    return !rain ? kSkip : c == kCabinEdge ? kEdge : kClear;
  };
  edge_runs_.clear();
  for (int ty = ty0; ty < ty1; ++ty) {
    for (int tx = tx0; tx < tx1;) {
      const Draw kind = draw_as(tx, ty);
      const int first = tx;
      while (tx < tx1 && draw_as(tx, ty) == kind) ++tx;
      if (kind == kSkip) continue;
      (kind == kClear ? runs_ : edge_runs_)
          .push_back({first * kTile, ty * kTile, std::min(tx * kTile, width_),
                      std::min((ty + 1) * kTile, height_)});
    }
  }
  clear_runs_ = runs_.size();
  runs_.insert(runs_.end(), edge_runs_.begin(), edge_runs_.end());
  for (int ty = ty0; ty < ty1; ++ty) {
    std::fill_n(tile_lit_.begin() + static_cast<std::size_t>(ty) * tiles_x_ + tx0, tx1 - tx0, 0);
  }
}

}  // namespace downpour::render
