#pragma once

#include <memory>

#include <glm/vec3.hpp>

#include "server/render/pass.hpp"
#include "server/render/passes/glass_quad.hpp"

namespace downpour::render {

struct Atmosphere;

// The optics of the water on the glass (seed 000, section 1.5 step 5, traced; beyond the paper).
struct GlassWaterConfig {
  float water_ior = 1.333f;
  // Samples of the optics per glass layer pixel (2, 4 or 16) by the layer's scale (1 to 4): where
  // the layer is as sharp as the view (a pinhole), enough to resolve drops smaller than a pixel;
  // where the lens's blur widens its pixels, about one for every two to four pixels of the view.
  int samples_by_scale[4] = {16, 2, 4, 4};
  // What a ray that the water reflects back down into the car meets: the dashboard's dark plastic
  // under the sky's light, as a share of the frame's ambient light.
  float cabin_per_ambient = 0.04f;
};

// The cabin's radiance seen down through the glass (the dark rim of every drop).
glm::vec3 cabin_radiance(const Atmosphere& atmosphere, const GlassWaterConfig& config = {});

// COCKPIT: the water on the glass as the view sees it, into the glass layer at 1 / layer_scale of
// the view's size (GlassView: its pixels as wide as the lens's blur of the glass). Each sample of
// a layer pixel traces the eye's ray through the water's surface (glass_water_surface.hpp) by
// Snell's law and Fresnel: the rays that leave look up the world outside in the environment
// probe (or the view's own image where they barely turn), the rest go back down into the dark
// cabin (glass_water.frag). A drop shows the world turned over, with a dark rim where its surface
// is too steep for the rays to leave.
class GlassWaterPass final : public Pass {
 public:
  explicit GlassWaterPass(SharedResources& shared, GlassWaterConfig config = {});
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override;
  void execute(const FrameContext& frame, const FrameResources& resources) override;
  // The optics' samples a layer pixel at this layer scale (2, 4 or 16), and whether they are the
  // pair (glass_water_pair.frag, whose mask tests the pair's own cells).
  int samples(int layer_scale) const;
  bool pair(int layer_scale) const { return layer_scale > 1 && samples(layer_scale) == 2; }

 private:
  const PassDecl decl_{"glass_water",
                       {Resource::kGlassSurface, Resource::kEnvironment, Resource::kViewColour,
                        Resource::kViewDepth},
                       {Resource::kGlassLayer},
                       // Only where GlassWaterMaskPass found that water may be.
                       {DepthTest::kNearer, false, Blend::kOff},
                       true};
  // A program of the optics and its uniforms: the sharp one (a pinhole's full-size layer), the
  // blurred one, and the blurred one for a pair of samples a pixel (glass_water.glsl).
  struct Optics {
    Optics(const char* fragment_file, bool sharp, const GlassWaterConfig& config);
    std::unique_ptr<ShaderProgram> program;  // (where the quad's uniforms point)
    GlassQuad quad;
    GlassSurfaceGrid grid;
    Uniform env_per_rad, env_max_lod, env_from_world, cabin, glass_depth, view_pixel_rad;
    Uniform inv_target, samples;
  };
  GlassWaterConfig config_;
  Optics sharp_, blurred_, pair_;
};

}  // namespace downpour::render
