// The rain streaks of one view, drawn on the CPU into a reduced-size layer that a pass composites
// over the scene. On llvmpipe a GPU quad per drop costs about 0.8 us in vertex work and triangle
// setup whatever its size (75,000 drops: 60-90 ms); here a streak costs its projection and a few
// texels (a Wu line), so 80,000 fit in a few milliseconds. Each texel keeps the streaks' opacity,
// summed so that the order of the drops does not matter, and the depth of its nearest streak,
// which sets the haze between it and the camera. What hides the rain is settled here too: the cars
// (their silhouettes on the layer, against each streak's depth); the cabin is the composite's
// (rain_pass.hpp). No GL.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/ext/matrix_double4x4.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "server/sim/rain_field.hpp"
#include "server/sim/worker_thread.hpp"

namespace downpour::render {

// A box that hides the rain behind it (a car): its corners lo..hi in its own frame.
struct RainOccluder {
  glm::dmat4 to_world{1.0};
  glm::vec3 lo{0.0f}, hi{0.0f};
};

// A lamp that lights the drops in its beam (the ego car's headlights, and the strongest others),
// in the camera's frame.
struct RainLamp {
  glm::vec3 position{0.0f};
  glm::vec3 axis{0.0f, 0.0f, -1.0f};  // the beam's, unit
  glm::vec3 left{1.0f, 0.0f, 0.0f};   // level, unit: a dipped beam's cut-off rises on the right
  float intensity = 0.0f;             // cd times the exposure times a drop's scattering share
  float cos_outer = -1.0f, cos_inner = -1.0f;
  bool low_beam = false;
};

struct RainLayerInputs {
  glm::mat4 view{1.0f};  // world to camera (GL axes: looking down -z)
  double tan_half_fov_x = 0.0;
  double tan_half_fov_y = 0.0;
  glm::dvec3 camera_velocity{0.0};  // world, m/s
  double dt_s = 0.0;                // the frame's time after the drops' (they move on by it)
  double exposure_s = 1.0 / 60.0;   // a view's camera that sets none: a streak is the motion in it
  glm::vec3 light{0.5f};            // linear light a drop carries (before the haze)
  glm::vec3 haze{0.5f};             // linear colour of the haze between the drop and the camera
  float haze_per_m = 0.0f;          // extinction
  // The lamps whose beams light the drops (at most kMaxLamps), their light's colour, and the
  // world's up in the camera's frame (for a dipped beam's cut-off).
  static constexpr std::size_t kMaxLamps = 4;
  std::span<const RainLamp> lamps;
  glm::vec3 lamp_colour{1.0f, 0.96f, 0.88f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float opacity = 0.55f;
  // The share of the far streaks drawn (1: all; at least a quarter): all of them up to
  // kThinFromM, this share from kThinToM on, linearly between. Each is drawn by a number of the
  // drop's own, the same every frame, and the more opaque by as much, so that the rain is as
  // opaque on average (docs/techniques.md: far streaks are faint and many, and each costs its
  // set-up whatever its size).
  static constexpr float kThinFromM = 10.0f, kThinToM = 20.0f;
  float far_share = 0.5f;
  float pixels_per_texel = 2.0f;     // the view's pixels per layer texel, across
  glm::dmat4 vehicle_to_world{1.0};  // the ego car at the frame's time, for the splashes on it
  // What hides the rain behind it: the cars, and in the driver's view the bonnet. A streak is left
  // out of the texels that its box covers on the layer (the convex outline of its corners, at its
  // nearest depth) where the streak is further away than that.
  std::span<const RainOccluder> occluders;
  // What a client's picture shows behind each texel (client_background.hpp): its distance along
  // the view's axis in centimetres (rows bottom-up, 0xffff far), hiding the streaks beyond it as
  // an occluder's outline does. Empty: none.
  std::span<const std::uint16_t> scene_depth_cm;
  // Per tile of RainLayer::kTile texels (rows bottom-up), what the cabin does to it (CabinTile,
  // cabin_tiles.hpp): the runs leave out the tiles it hides, and put those it reaches into apart.
  // Empty: no cabin (every tile clear).
  std::span<const std::uint8_t> cabin_tiles;
};

class RainLayer {
 public:
  RainLayer();
  ~RainLayer();

  // Clears and draws the drops' streaks into a width x height layer; returns the streaks drawn.
  std::uint32_t build(const sim::RainState& rain, const RainLayerInputs& in, int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }
  // Premultiplied RGBA8 rows bottom-up (GL's order), display-encoded like the scene's colour.
  const std::vector<std::uint32_t>& colour() const { return colour_; }
  // A rectangle of texels, [x0, x1) x [y0, y1) (rows bottom-up); empty if none.
  struct Bounds {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    bool empty() const { return x1 <= x0 || y1 <= y0; }
  };
  // The tiles (kTile x kTile texels) with rain, and those beside an edge of one with rain on it,
  // but for those the cabin hides (RainLayerInputs::cabin_tiles), as runs along each row of
  // tiles: rectangles of texels, clipped to the layer. The composite draws only these. First the
  // runs of tiles clear of the cabin (clear_runs() of them, rows bottom-up), which need no depth
  // test, then those of the tiles that the cabin reaches into.
  static constexpr int kTile = 8;
  const std::vector<Bounds>& runs() const { return runs_; }
  std::size_t clear_runs() const { return clear_runs_; }

  // The nearest a drop is drawn: nearer, it is far out of focus for an eye or camera looking at the
  // road, a faint blur that would be the largest streak of all.
  static constexpr float kNearestM = 1.5f;
  // Splashes on the bonnet are nearer than that to the driver; nothing lands nearer than this.
  static constexpr float kNearestSplashM = 0.3f;
  // A splash's crown is brighter than a streak of the same area: its droplets and sheet face
  // every way and catch the sky.
  static constexpr float kSplashBrightness = 2.0f;

 private:
  // What the streaks leave in a texel: one cache access per texel drawn. Every drop carries the
  // same light, so a texel needs only how much of it and the distance of its nearest streak, for
  // the haze between and the occluders. In 16-bit integers, four bytes a texel: the two threads'
  // layers (and the occluders' depths) then take little of the cache, which matters in a frame
  // whose other passes have evicted them (in the quiet microbenchmark floats drew as fast; with the
  // cache cold between frames the layer took 0.3-0.5 ms more at 10,000 streaks). The lamps' light
  // is apart (Texels::lit): only a streak a lamp lights touches it.
  static constexpr std::uint16_t kUntouched = 0xffff;  // depth of a texel no streak has touched
  static constexpr float kAlphaUnits = 4096.0f;        // opacity's units: sums up to 16
  struct Texel {
    std::uint16_t alpha = 0;           // sum of the streaks' opacities, saturating
    std::uint16_t depth = kUntouched;  // nearest streak (cm)
  };
  // One thread's texels, and per texel the sum of the opacities times their lamp light's level /
  // kLitLevels (0 where no lit streak was drawn).
  struct Texels {
    std::vector<Texel> sum;
    std::vector<std::uint16_t> lit;
  };
  // A streak's lamp light in levels, 0 .. kLitLevels - 1, of up to kLitMax radiance (squared:
  // finer where it is dim).
  static constexpr int kLitLevels = 16;
  static constexpr float kLitMax = 6.0f;
  static std::uint16_t depth_cm(float depth_m) {
    return static_cast<std::uint16_t>(std::clamp(depth_m * 100.0f + 0.5f, 0.0f, 65534.0f));
  }
  static void add(Texel& t, std::uint32_t alpha, std::uint16_t depth) {
    t.alpha = static_cast<std::uint16_t>(std::min<std::uint32_t>(t.alpha + alpha, 0xffff));
    t.depth = std::min(t.depth, depth);
  }
  static void add_lit(std::uint16_t& lit, std::uint32_t alpha, std::uint32_t level) {
    lit = static_cast<std::uint16_t>(
        std::min<std::uint32_t>(lit + alpha * level / kLitLevels, 0xffff));
  }
  // The most whole texels across a streak between its two shared ones (a drop a few texels
  // wide, just past kNearestM).
  static constexpr int kMaxExtraTexels = 4;
  // Each drop is drawn in the box and in a copy to each side of it, and behind those three for a
  // camera behind the box (rain_layer.cpp).
  static constexpr int kMaxCopies = 6;
  // Drops projected together (rain_layer.cpp), in arrays the compiler vectorizes.
  static constexpr int kBatch = 256;
  // The most points a splash's point is drawn as along its motion in the exposure.
  static constexpr int kMaxSplashSteps = 6;
  // Below this many drops one thread draws them all.
  static constexpr std::size_t kDropsForTwoThreads = 4096;
  // What a splash costs to splat, in drops drawn (about 0.16 us against 0.18 from the driver's
  // eye in heavy rain, downpour-rain-layer-bench, before the far streaks were thinned, which took a
  // drop to about 0.86 of that): the thread that splats them draws fewer drops.
  static constexpr double kDropsPerSplash = 1.0;
  // A batch of drops being projected (rain_layer.cpp).
  struct Batch;

  // What stays the same for every drop of one build: the camera, the drops' motion in its frame,
  // the projection, the copies of the box, the haze table, the lamps (rain_layer.cpp).
  struct Frame;
  // The layer sized width x height, its texels clear and last build's output cleared.
  void reset(int width, int height);
  // Draws drops [begin, end) into `out`, in batches; `dirty` gets the texels it touched. Returns
  // the streaks drawn.
  std::uint32_t draw(const Frame& f, std::size_t begin, std::size_t end, Texels& out, Bounds& dirty,
                     Batch& batch) const;
  // One streak (drop i of the batch, in the copy being drawn) as a Wu line into `out`, widening
  // `touched`.
  void draw_streak(const Frame& f, const Batch& batch, int i, Texels& out, Bounds& touched) const;
  // The texels of `b` to premultiplied colour, both threads' texels summed and cleared, and the
  // tiles with rain marked.
  void resolve(const Frame& f, const RainLayerInputs& in, const Bounds& b);
  void resolve_rows(const Frame& f, const RainLayerInputs& in, const Bounds& b, int y0, int y1);
  // The runs of tiles the composite draws (runs_), from the tiles marked in `b`.
  void make_runs(const RainLayerInputs& in, const Bounds& b);

  // Splats the splashes' crowns into `out`, each point along its motion relative to the camera
  // during the exposure; returns the texels touched. Those on the car itself are never behind an
  // occluder (its bonnet is one, in the driver's view).
  Bounds draw_splashes(const sim::RainState& rain, const RainLayerInputs& in, const glm::mat4& view,
                       float sx, float sy, float cx, float cy, std::vector<Texel>& out) const;

  // The occluders' nearest depth per texel (kUntouched where none), over occluded_ only: the texels
  // whose centres lie inside the outline of an occluder's corners.
  const std::uint16_t* occlude(const RainLayerInputs& in, float sx, float sy, float cx, float cy);

  int width_ = 0, height_ = 0;
  std::vector<std::uint16_t> occluder_depth_;  // cm
  std::vector<glm::uvec3> hazed_;              // the resolve's colours by lamp light and distance
  Bounds occluded_;
  sim::WorkerThread helper_{"dp-rain"};
  // Each thread's batch of drops being projected (rain_layer.cpp), made once.
  std::unique_ptr<Batch> batches_[2];  // draws half the drops, resolves half the rows
  Texels texels_;
  Texels second_;  // the second thread's
  std::vector<std::uint32_t> colour_;
  Bounds bounds_;  // the texels the last build wrote to colour_, cleared by the next
  // Per tile: whether a texel has rain, and which of its edges (cleared once the runs are made).
  enum : std::uint8_t {
    kTileLit = 1,
    kTileLeft = 2,
    kTileRight = 4,
    kTileBottom = 8,
    kTileTop = 16,
  };
  int tiles_x_ = 0;
  std::vector<std::uint8_t> tile_lit_;
  std::vector<Bounds> runs_;
  std::size_t clear_runs_ = 0;
  std::vector<Bounds> edge_runs_;  // this frame's runs of edge tiles, before they join runs_
};

}  // namespace downpour::render
