// The renderer: owns the headless GL context and every GL resource, renders the views of a
// session's scene and reads their pixels back asynchronously (pixel-pack buffers and fences).
// Plain C++ interface, no GL types: the session layer drives it from the render thread.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "server/render/cpu/spray_smoothing.hpp"
#include "server/render/gl/egl_context.hpp"
#include "server/sim/simulation.hpp"
#include "server/sim/types.hpp"

namespace downpour::render {

struct RendererOptions {
  EglPlatformChoice platform = EglPlatformChoice::kAuto;
  SpraySmoothing spray_smoothing = SpraySmoothing::kPlaneFit;
  // The chase view's road drawn at half size and brought in (view_passes.hpp): by default where
  // the renderer is a CPU rasterizer (llvmpipe), which pays for every pixel it shades.
  std::optional<bool> road_at_half = std::nullopt;
  // The cabin's pictures kept and copied back into the views that draw the same (CockpitPass): by
  // default likewise.
  std::optional<bool> keep_cabin = std::nullopt;
};

// The passes that draw a view's road (PassTiming::name): the road whole, or ROAD's near part into
// the road's layer, its composite and its far part (road_pass.hpp).
inline constexpr std::array<std::string_view, 4> kRoadPassNames = {"road", "road_layer",
                                                                   "road_composite", "road_far"};

struct PassTiming {
  std::string name;
  double ms = 0.0;
};

// What the renderer keeps for one session between frames: its views' render targets and readback
// buffers, and its glass water map on the GPU (uploaded once per simulation frame, shared by the
// views). Made by Renderer::open_session; destroyed on the render thread, after its readbacks
// have finished.
class RenderSession {
 public:
  ~RenderSession();
  RenderSession(const RenderSession&) = delete;
  RenderSession& operator=(const RenderSession&) = delete;

 private:
  friend class Renderer;
  struct Impl;
  explicit RenderSession(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// One view's pixels on their way back from the GPU.
struct PendingReadback {
  RenderSession* session = nullptr;
  int view_index = 0;
  int slot = 0;
  void* fence = nullptr;
  int width = 0;
  int height = 0;
  sim::Outputs outputs;  // the ground truth read back with it
  float near_m = 0.0f;   // its camera's near plane (its depth's scale)
};

// A view's ground truth read back with its pixels (sim::Outputs), rows bottom-up; each empty where
// the view did not ask for it. finish() fills the buffers it is given (a pool's, already of the
// right size, are not reallocated).
struct GroundTruthPixels {
  std::vector<std::uint8_t> clean;  // RGBA8: the frame without its water (clean or water mask)
  std::vector<float> depth_m;       // along the view's axis; 0 where nothing was drawn (the sky)
};

// The simulation's state after the frame's step (the water on the glass, the rain): called once a
// pass needs it (on the render thread); it may wait for the step, which runs beside the scene's
// passes.
using StepSource = std::function<const sim::SceneState&()>;

class Renderer {
 public:
  // Creates the context on the calling thread, which must be the only one to use the renderer.
  // Throws std::runtime_error when no context can be made or a shader does not build.
  static std::unique_ptr<Renderer> create(const RendererOptions& options);
  ~Renderer();

  const std::string& gl_renderer() const;
  const std::string& platform() const;

  // glFinish after each pass, so that pass timings are real (benchmarks); off in service. On
  // llvmpipe a finish mid-frame leaves the context several times slower from then on, so profile
  // with a renderer of its own and take the times as a ranking of the passes.
  void set_profiling(bool on);
  // Seed 001's smoothing of the spray's body (RendererOptions::spray_smoothing at start).
  void set_spray_smoothing(SpraySmoothing smoothing);
  SpraySmoothing spray_smoothing() const;
  // The relief's shadows on the road under the sun (seed 002), on by default; and whether the last
  // frame drew them (not where the direct sunlight is too faint).
  void set_relief_shadows(bool on);
  bool last_drew_relief() const;
  // Whether frames light the scene with their lamps (on by default; off for the lights' benchmark:
  // no lamp map, no lamp in the shaders' loops or the rain; the lit lenses still glow).
  void set_lamps(bool on);
  // Whether the road's mirror shows the spray's clouds (on by default; off for the tests that
  // compare).
  void set_spray_in_mirror(bool on);
  // Whether the CPU draws the spray's parcels (llvmpipe's choice) or the GPU.
  void set_spray_cpu_splat(bool cpu);
  bool spray_cpu_splat() const;
  // The spray's parcels the last frame drew: the body's, lone spray, clouds of haze.
  std::array<std::uint32_t, 3> last_spray_drawn() const;
  // Tests: a body's front distances along the view axis (width x height, bottom row first, 1e6
  // where none) smoothed as the spray pass smooths them, seen through a camera with these tangents
  // of its half fields of view.
  std::vector<float> smooth_spray_body(int width, int height, float tan_half_fov_x,
                                       float tan_half_fov_y, const std::vector<float>& front);
  const std::vector<PassTiming>& last_pass_timings() const;
  // Rain streaks drawn by the last render() (0 if it drew no rain).
  std::uint32_t last_rain_streaks() const;
  // Frames whose cabin was copied from a kept picture, frames that drew it, and pictures kept
  // (RendererOptions::keep_cabin), since the renderer was made.
  struct CabinCounts {
    std::uint64_t restored = 0, drawn = 0, kept = 0;
  };
  CabinCounts cabin_counts() const;

  std::unique_ptr<RenderSession> open_session();

  // Renders a session's view `view_index` (its target made on first use, remade when the size
  // changes) and starts its readback. `scene` holds the frame's inputs, the rain drawn among them
  // (its windshield is not read); `stepped` gives the state after the step when a pass needs it.
  PendingReadback render(RenderSession& session, int view_index, const sim::ViewSpec& spec,
                         const sim::SceneState& scene, const StepSource& stepped);
  // render() in two halves, so that a tick's views overlap: begin() draws the passes that need
  // only the frame's inputs (all but the glass's) and hands them to the rasterizer, end() the
  // rest and starts the readback. Between them other views may begin or end; each
  // view begun is ended once, or dropped (then its frame is lost, and its target kept). `session`,
  // `spec`, `scene` and `stepped` must live until end(). (A session's first frame waits for the
  // step in begin(): no rain has been published before it.) With `rain_ahead` (a tick of two views
  // or more), the view's rain layer is built beside its world's passes, and where it is not built
  // when the rain pass comes, the rain pass and those after it are left to end(), for the render
  // thread to begin the next view meanwhile. A view alone builds it when its pass comes: measured
  // at 1280x720, building it ahead slowed the view's own frame (its threads took the cores from the
  // world's passes, with nothing else to draw meanwhile).
  class ViewFrame {
   public:
    ~ViewFrame();
    ViewFrame(const ViewFrame&) = delete;
    ViewFrame& operator=(const ViewFrame&) = delete;

   private:
    friend class Renderer;
    struct State;
    explicit ViewFrame(std::unique_ptr<State> state);
    std::unique_ptr<State> state_;
  };
  std::unique_ptr<ViewFrame> begin(RenderSession& session, int view_index,
                                   const sim::ViewSpec& spec, const sim::SceneState& scene,
                                   const StepSource& stepped, bool rain_ahead = false);
  PendingReadback end(ViewFrame& view);
  // The same with the scene's own windshield and rain.
  PendingReadback render(RenderSession& session, int view_index, const sim::ViewSpec& spec,
                         const sim::SceneState& scene);
  bool is_ready(const PendingReadback& pending) const;
  // Waits if needed; out gets RGBA8 rows bottom-up, and truth (where given) the ground truth the
  // view asked for.
  void finish(const PendingReadback& pending, std::vector<std::uint8_t>& out,
              GroundTruthPixels* truth = nullptr);

  // Renders one view of the scene by itself and waits for its pixels, rows top-down (tests,
  // tools).
  std::vector<std::uint8_t> render_image(const sim::ViewSpec& spec, const sim::SceneState& scene);
  // The same with the ground truth the spec asks for (ViewSpec::outputs), rows top-down as well:
  // a client's picture's depth as the server holds it (sim::ClientImage::depth_m) is the flipped
  // depth_m (rows bottom-up).
  std::vector<std::uint8_t> render_image(const sim::ViewSpec& spec, const sim::SceneState& scene,
                                         GroundTruthPixels& truth);

  // Frees the shared intermediate targets (remade on demand): after sessions close, so that the
  // memory of their sizes goes back. Between frames only.
  void release_shared_targets();

  // Tests: the world outside the windshield fixed (six cube faces of linear radiance, face_size^2
  // texels each, GL's face order, rows from the bottom) instead of drawn from the world; COCKPIT
  // then shows it as its background too. Sessions opened after the call take it; nullopt goes
  // back to the world.
  void set_fixed_environment(std::optional<std::array<std::vector<glm::vec3>, 6>> faces,
                             int face_size = 0);

 private:
  struct Impl;
  explicit Renderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Renderer::render_image, for callers that hold a renderer by reference.
inline std::vector<std::uint8_t> render_image(Renderer& renderer, const sim::ViewSpec& spec,
                                              const sim::SceneState& scene) {
  return renderer.render_image(spec, scene);
}

}  // namespace downpour::render
