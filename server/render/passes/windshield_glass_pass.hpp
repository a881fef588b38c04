#pragma once

#include <map>

#include "server/render/frame_context.hpp"
#include "server/render/passes/windshield_water_pass.hpp"

namespace downpour::render {

struct WindshieldGlassConfig {
  // The refraction background (seed 000, section 1.5 step 5): the scene copied at a quarter of the
  // view's size and mipmapped; drops sample it at background_lod (the paper used a 64 x 64 copy).
  float background_lod = 1.0f;
  // A view ray leaving the water through a surface tilted by a (sin a = the normal's
  // glass-parallel part) turns by asin(n sin a) - a towards the glass's own normal side (a drop
  // is a converging lens: the world shows turned over); the tangent of that angle times the
  // focal length gives the lookup's screen offset.
  float water_ior = 1.33f;
  float fresnel_r0 = 0.02f;  // water
  // Drop rims: where the surface leans more than rim_lean[0] (up to rim_lean[1]) the rays bend so
  // far that they see the dark cabin and the car's body: darker by this much.
  float rim_darkening = 0.55f;
  float rim_lean[2] = {0.45f, 0.62f};
  // A camera of its own (ViewSpec::camera) is a lens focused beyond the glass: drops on the glass
  // blur over a circle of aperture * (1 - distance / focus) mm (thin lens). The driver's eye is
  // drawn in focus.
  float camera_aperture_mm = 2.0f;
  float camera_focus_m = 3.0f;
};

// The blur (mm on the glass) of drops seen by a view's camera: 0 for the driver's eye (drawn in
// focus); for a camera of its own (ViewSpec::camera), a thin lens focused at camera_focus_m:
// aperture * (1 - d / focus) at the distance d to the glass along its axis. In the image the blur
// is that over d: it grows as the camera nears the glass.
double camera_defocus_mm(const sim::ViewSpec& spec, const sim::GlassConfig& glass,
                         const WindshieldGlassConfig& config);

// COCKPIT view, after the scene: the windshield at its real place in the vehicle, depth-tested so
// that the cabin (pillars, dashboard, mirror) stays in front. Where there is water the scene shows
// refracted (a blurred copy, offset by the water normal, mirror-repeated at the borders) with a
// Fresnel reflection of the sky and darker rims; dry glass leaves the scene as it is. The wiper
// blades and arms are dark strips on the glass.
// Reads: the view's colour and depth (copied first, never sampled while drawn into), the water map
// of WindshieldWaterPass, the blade poses. Writes: the view's colour (blended, no depth write).
class WindshieldGlassPass {
 public:
  explicit WindshieldGlassPass(SharedResources& shared, WindshieldGlassConfig config = {});
  // The refraction background: the scene so far outside the glass, copied at a quarter size and
  // mipmapped. Before draw().
  void copy_scene(const FrameContext& frame);
  void draw(const FrameContext& frame, WindshieldWaterPass& water);

 private:
  struct SceneCopy {
    Texture colour;  // mipmapped, mirrored repeat
    Framebuffer fbo;
    int width = 0;
    int height = 0;
  };
  SceneCopy& scene_copy_for(int view_width, int view_height);
  // Nothing to draw on clear glass with no blade on it.
  static bool needed(const FrameContext& frame);

  SharedResources& shared_;
  WindshieldGlassConfig config_;
  ShaderProgram program_;
  ShaderProgram copy_program_;
  ShaderProgram blade_program_;
  VertexArray empty_vao_;
  std::map<std::pair<int, int>, SceneCopy> copies_;  // by view size
};

}  // namespace downpour::render
