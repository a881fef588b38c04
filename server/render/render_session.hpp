// What the renderer keeps per session (RenderSession::Impl, renderer.hpp): each view's targets, the
// world outside its glass, and the simulation's state on the GPU as the session's frames last
// showed it (the water's surface on the glass, the road's water), uploaded only when it changes.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <vector>

#include "server/render/environment_probe.hpp"
#include "server/render/gl/gl_objects.hpp"
#include "server/render/render_targets.hpp"
#include "server/render/renderer.hpp"
#include "server/sim/glass_water_surface.hpp"
#include "server/sim/road_water.hpp"

namespace downpour::render {

struct RenderSession::Impl {
  std::vector<std::unique_ptr<ViewTarget>> views;
  // The water's surface on the glass (bodies, cells, entries: buffers, read as texture buffers),
  // in sets used in turn (kUploadCopies), and what the current set holds.
  struct GlassSurfaceBuffers {
    std::array<Buffer, 3> buffer;
    std::array<Texture, 3> texture;
    std::array<std::size_t, 3> bytes{};
  };
  std::array<GlassSurfaceBuffers, kUploadCopies> glass_surface;
  std::size_t glass_current = 0;
  std::shared_ptr<const sim::GlassWaterSurface> surface_shown;
  // The world outside the glass, shared by the session's views (made on first use).
  std::unique_ptr<EnvironmentProbe> environment;
  // The road's water window on the GPU, in textures used in turn (kUploadCopies), and the image
  // the current one shows (held, so that its address names it).
  std::array<Texture, kUploadCopies> road_water;
  std::size_t road_current = 0;
  int road_cells = 0, road_rings = 0;
  std::shared_ptr<const sim::RoadWaterImage> road_shown;
  bool road_dry_shown = false;
  // Each client-background view's picture and depth on the GPU, and the image they show.
  struct ClientPicture {
    Texture colour;  // RGBA8 (its alpha unused), display-encoded, rows bottom-up
    Texture depth;   // D32F, the view's reversed-Z: near / distance (1x1 0, the sky, without one)
    int width = 0, height = 0;
    bool has_depth = false;
    float near_m = 0.0f;              // the near plane its depth was made for
    std::vector<float> depth_buffer;  // the conversion's
    std::shared_ptr<const sim::ClientImage> shown;
    bool blank_shown = false;
  };
  std::array<ClientPicture, sim::kViewCount> client;

  // The water surface on the glass brought up to the frame's (a whole upload for each new one:
  // the step publishes one per tick), bound to its texture buffers.
  void upload_glass_surface(std::shared_ptr<const sim::GlassWaterSurface> surface);
  // The road water rings brought up to the frame's: a whole upload for each new image (one per
  // road step: 4 rings of 64 x 64 cells, two half floats each); the texture that holds them.
  GLuint upload_road_water(const std::shared_ptr<const sim::RoadWaterImage>& image);
  // A view's client picture brought up to the frame's (black before the first), its depth made
  // reversed-Z for a camera whose near plane is near_m, bound to their units (kClientImage,
  // kClientDepth).
  const ClientPicture& upload_client_image(sim::View view,
                                           const std::shared_ptr<const sim::ClientImage>& image,
                                           float near_m);
};

}  // namespace downpour::render
