// The spray's parcels drawn on the CPU (for llvmpipe, where the GL is itself on the CPU and each
// small triangle costs about a microsecond of set-up: 20,000 parcels as squares took 20 ms), into
// the same maps the GPU path draws (spray_depth.frag, spray_haze.frag):
// - the four depth maps of seed 001, step 3: per pixel, the distances along the view axis where
//   the pixel's ray enters and leaves the nearest and farthest sphere of the body and of the spray
//   (the exact ray-sphere intersection at the pixel's centre, as the GPU's ray-cast squares), and
//   a mask of the pixels any sphere covers;
// - the haze: per pixel, the optical depth summed over the parcels' clouds, and its depth-weighted
//   distance (the clouds all scatter the same light, so their order does not matter).
// No GL.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace downpour::render {

inline constexpr float kSprayFar = 1.0e6f;  // where nothing is, in the depth maps
inline constexpr float kSprayMaskSpray = 0.25f, kSprayMaskBody = 0.5f;

struct SprayCamera {
  int width = 0, height = 0;  // the maps' size
  glm::vec2 tan_half_fov{1.0f};
};

// A sphere or a cloud in view space (the camera looks along -z), radius in metres.
struct SprayBall {
  glm::vec3 centre{0.0f};
  float radius = 0.0f;
};

struct SprayDepthMaps {
  int width = 0, height = 0;
  // Per pixel: body front, body back (negated), spray front, spray back (negated), as the GPU's
  // MIN-blended target holds them; kSprayFar (or -0 for a back) where none is.
  std::vector<glm::vec4> depth;
  // kSprayMaskSpray where only the spray's spheres cover the pixel, kSprayMaskBody where the
  // body's do, else 0 (a depth texture's values: the passes after test against them).
  std::vector<float> mask;
};

// Fills maps with the body's spheres, then the spray's.
void splat_depth(const SprayCamera& camera, const std::vector<SprayBall>& body,
                 const std::vector<SprayBall>& spray, SprayDepthMaps& maps);

struct SprayHazeBall {
  SprayBall ball;
  float depth = 0.0f;  // optical depth through the centre
};

// Per pixel (x optical depth, y optical depth times distance): the clouds' optical depth
// 2 tau0 (1 - b^2)^2 at b of their radius from their centre.
void splat_haze(const SprayCamera& camera, const std::vector<SprayHazeBall>& clouds,
                std::vector<glm::vec2>& out);

}  // namespace downpour::render
