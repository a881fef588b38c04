// The interface between the C++ renderer and its shaders, defined once: texture units, material
// ids, storage buffers' bindings, the sizes of the shaders' arrays, the per-frame uniform block
// (std140) and its binding. The build writes the GLSL side of it (interface.glsl, made by
// downpour-shader-tool from these same lists), so that a binding number, an array's size or a
// block field cannot differ between the two. No GL.
#pragma once

#include <cstddef>
#include <type_traits>

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include "server/model/materials.hpp"

namespace downpour::render {

// Texture units: X(C++ name, unit, GLSL sampler type, GLSL name, what it holds).
#define DOWNPOUR_TEXTURE_UNITS(X)                                                                  \
  X(kNoise, 1, sampler2D, noise_tex, "value noise, 4 frequencies in rgba, repeating")              \
  X(kGroundRelief, 2, sampler2DArray, ground_relief_tex,                                           \
    "the road's reliefs over a 3 m tile, rgb normal, a height: the asphalt (seed 003, 3.1), the "  \
    "shoulder's setts")                                                                            \
  X(kSky, 3, sampler2D, sky_tex,                                                                   \
    "the clear sky by the sun's place, less the frame's gradient (sky_table.hpp): columns from "   \
    "the sun's azimuth round, rows sqrt(sin elevation)")                                           \
  X(kEnvironment, 4, samplerCube, environment_tex,                                                 \
    "the world outside the windshield from its centre, world axes, linear radiance with the sun "  \
    "and lamps at their energy, mipmapped (environment_probe.hpp)")                                \
  X(kViewColour, 5, sampler2D, view_colour_tex, "the view's colour so far")                        \
  X(kViewDepth, 6, sampler2D, view_depth_tex, "the view's depth so far (reversed-Z)")              \
  X(kGlassLayer, 7, sampler2D, glass_layer_tex,                                                    \
    "the water on the glass over the scene, reduced size, premultiplied")                          \
  X(kRainLayer, 8, sampler2D, rain_layer_tex,                                                      \
    "the rain streaks, reduced size, premultiplied (rain_layer.hpp)")                              \
  X(kRoadWater, 9, sampler2DArray, road_water_tex,                                                 \
    "the road's water in rings around the car, a layer per ring: r water, g standing water (mm)")  \
  X(kReflection, 10, sampler2D, reflection_tex,                                                    \
    "the scene mirrored in the road's plane, reduced size, mipmapped (display-encoded)")           \
  X(kReflectionDepth, 11, sampler2D, reflection_depth_tex, "its depth (reversed-Z)")               \
  X(kSprayDepth, 12, sampler2D, spray_depth_tex,                                                   \
    "the spray's depth maps (seed 001): r body front, g body back, b spray front, a spray "        \
    "back; distances (m), backs negated")                                                          \
  X(kSpraySmooth, 13, sampler2D, spray_smooth_tex,                                                 \
    "the body's front distance (r), being smoothed or smoothed")                                   \
  X(kSprayLayer, 14, sampler2D, spray_layer_tex,                                                   \
    "the spray over the scene, reduced size, premultiplied")                                       \
  X(kSprayHaze, 15, sampler2D, spray_haze_tex,                                                     \
    "the spray's haze, a quarter of the view: r optical depth, g that times distance (m)")         \
  X(kHorizon, 17, sampler2DArray, horizon_tex,                                                     \
    "the reliefs' horizon maps (seed 002), a layer per azimuth k, the asphalt's then the setts': " \
    "rg tan(beta) and distance at k, ba at k + 1, encoded (relief.hpp)")                           \
  X(kLampMap, 18, sampler2DArray, lamp_map_tex,                                                    \
    "the lamps' light on the ground in rings around the camera, a layer per ring: rgb the "        \
    "illuminance of an upward surface times the frame's exposure (lamp_map.hpp)")                  \
  X(kEnvironmentLevels, 19, sampler2DArray, environment_levels_tex,                                \
    "the environment probe's faces as layers, one level at a time (environment_probe.cpp)")        \
  X(kGlassBodies, 20, samplerBuffer, glass_bodies_tex,                                             \
    "the water's bodies on the glass, three texels each (sim::WaterBody)")                         \
  X(kGlassCells, 21, usamplerBuffer, glass_cells_tex,                                              \
    "per cell of the glass's grid, rows from v = 0: first entry << count bits | count "            \
    "(sim::GlassWaterSurface)")                                                                    \
  X(kGlassEntries, 22, usamplerBuffer, glass_entries_tex, "the cells' lists of body indices")      \
  X(kClientImage, 23, sampler2D, client_image_tex,                                                 \
    "a client-background view's picture (display-encoded)")                                        \
  X(kClientDepth, 24, sampler2D, client_depth_tex,                                                 \
    "its depth, the view's reversed-Z (0 the sky or unknown)")                                     \
  X(kSprayMirrorHaze, 25, sampler2D, spray_mirror_haze_tex,                                        \
    "the spray's haze seen in the road's mirror: r optical depth, g that times distance (m)")      \
  X(kModelTexture, 26, sampler2DArray, model_tex,                                                  \
    "the model being drawn's base-colour textures, a layer each (sRGB, mipmapped)")                \
  X(kRoadLayer, 27, sampler2D, road_layer_tex,                                                     \
    "the road at half the view's size (display-encoded), alpha 1 where drawn (road_pass.hpp)")

// The per-frame uniform block: X(GLSL type, name, comment). Every field is a vec4 or a mat4, so
// the C++ struct below has the std140 layout as it is.
#define DOWNPOUR_FRAME_BLOCK(X)                                                               \
  X(mat4, view_proj, "world to clip")                                                         \
  X(mat4, inv_view_proj, "clip to world")                                                     \
  X(vec4, camera_pos, "xyz world position of the camera")                                     \
  X(vec4, sun_dir, "xyz unit direction towards the sun")                                      \
  X(vec4, sun_radiance, "rgb direct sunlight reaching the ground")                            \
  X(vec4, sky_zenith, "rgb")                                                                  \
  X(vec4, sky_horizon, "rgb")                                                                 \
  X(vec4, ambient, "rgb light from the whole sky on an upward surface")                       \
  X(vec4, fog, "rgb colour, a extinction per metre")                                          \
  X(scalar, time_s, "the session's sim time (s)")                                             \
  X(scalar, overcast, "0 a clear sky to 1 overcast (atmosphere.hpp)")                         \
  X(scalar, wetness, "the ground's wetness, 0 dry to 1 (atmosphere.hpp)")                     \
  X(scalar, rain_rate_mm_h, "the weather's rain rate (mm/h)")                                 \
  X(vec4, wind, "xy wind velocity (m/s, world)")                                              \
  X(mat4, mirror_view_proj, "world to the reflection's clip: view_proj times the mirror")     \
  X(vec4, clip_plane, "what is drawn: n.p + w >= 0 (the road reflection's, else everything)") \
  X(vec4, road_water,                                                                         \
    "x the water's rings (0: none), y a ring's cells a side over 4 (its fading band: 4 "      \
    "cells), w 1 with a reflection drawn, else 0")                                            \
  X(mat4, road_water_rings,                                                                   \
    "column l: ring l's window, xy its lower-left corner (world m), z 1 / its side (m), "     \
    "w its cell (m)")                                                                         \
  X(vec4, road_water_reach,                                                                   \
    "[l]: ring l's reach from ring 0's middle along x or y (m, "                              \
    "RoadWaterImage::reach_m); past the rings, the largest float")                            \
  X(vec4, road_water_state,                                                                   \
    "x capacity (mm), y z the window's mean water and standing water "                        \
    "(mm), w 1 with the window, else 0 (the wetness alone)")                                  \
  X(vec4, lamp_map,                                                                           \
    "x the lamp map's rings (0: none), y the exposure: radiance per lux, z the ego car's "    \
    "headlights (first in the lamp block), w all the lamp block's lamps")                     \
  X(mat4, lamp_rings,                                                                         \
    "column l: the lamp map's ring l, as road_water_rings: xy lower-left corner, z 1 / "      \
    "side, w cell (m)")

// Material ids: model/materials.hpp (the models write them, the shaders read them).
namespace material = model::material;

// Shader storage buffers: X(C++ name, binding, GLSL macro, what it holds). A shader declares its
// block at the macro: layout(std430, binding = RUNS_BUFFER).
#define DOWNPOUR_STORAGE_BUFFERS(X)                                                               \
  X(kRunsBuffer, 0, RUNS_BUFFER,                                                                  \
    "runs of a layer's tiles, uv x0 y0 x1 y1 (rain.vert: the rain layer's; spray_runs.vert: the " \
    "spray layer's)")                                                                             \
  X(kParcelsBuffer, 1, PARCELS_BUFFER, "the spray's parcels (spray_depth.vert)")                  \
  X(kHazeBuffer, 2, HAZE_BUFFER, "the spray's haze splats (spray_haze.vert)")

namespace storage_buffer {
#define DOWNPOUR_BUFFER_CONSTANT(name, binding, glsl, what) \
  inline constexpr unsigned name = binding;
DOWNPOUR_STORAGE_BUFFERS(DOWNPOUR_BUFFER_CONSTANT)
#undef DOWNPOUR_BUFFER_CONSTANT
}  // namespace storage_buffer

inline constexpr unsigned kFrameBlockBinding = 0;
// The frame's lamps (light_set.hpp's pack_lamps), a second uniform block: per lamp four vec4s,
//   [0] xyz position (world), w the height of the ground under it,
//   [1] xyz the beam's axis (unit), w the cosine of its outer cone (nothing beyond),
//   [2] rgb luminous intensity on the axis (cd), w the cosine of its inner cone (full within),
//   [3] x 1 for a dipped beam's cut-off, else 0; yz the beam's left, level (unit).
inline constexpr unsigned kLampBlockBinding = 1;

// The sizes of the arrays that shaders declare, as constants in the generated GLSL:
// X(C++ name, size, GLSL name, what).
#define DOWNPOUR_ARRAY_SIZES(X)                                                            \
  X(kMaxLamps, 64, MAX_LAMPS, "lamps a frame knows: the lamp block, the lamp map's boxes") \
  X(kMaxGlows, 96, MAX_GLOWS, "lamp glows drawn, the strongest (lamp_glow_pass.hpp)")      \
  X(kWiperBlades, 2, WIPER_BLADES, "wiper blades (wiper_blades.hpp)")                      \
  X(kSkyTableWidth, 32, SKY_TABLE_WIDTH, "the sky's table: columns (sky_scattering.hpp)")  \
  X(kSkyTableHeight, 24, SKY_TABLE_HEIGHT, "and rows")
#define DOWNPOUR_ARRAY_SIZE_CONSTANT(name, size, glsl, what) inline constexpr int name = size;
DOWNPOUR_ARRAY_SIZES(DOWNPOUR_ARRAY_SIZE_CONSTANT)
#undef DOWNPOUR_ARRAY_SIZE_CONSTANT

namespace texture_unit {
#define DOWNPOUR_UNIT_CONSTANT(name, unit, type, glsl, what) inline constexpr unsigned name = unit;
DOWNPOUR_TEXTURE_UNITS(DOWNPOUR_UNIT_CONSTANT)
#undef DOWNPOUR_UNIT_CONSTANT
}  // namespace texture_unit

// A field's C++ type from its name in the list; a scalar is GLSL's float. std140 packs four
// scalars in a row into one vec4's slot, as the C++ struct does: keep them in fours.
namespace detail {
using mat4 = glm::mat4;
using vec4 = glm::vec4;
using scalar = float;
}  // namespace detail

struct FrameBlock {
#define DOWNPOUR_BLOCK_FIELD(type, name, what) detail::type name;
  DOWNPOUR_FRAME_BLOCK(DOWNPOUR_BLOCK_FIELD)
#undef DOWNPOUR_BLOCK_FIELD
};
static_assert(sizeof(FrameBlock) % 16 == 0, "std140: the block fills whole vec4 slots");
#define DOWNPOUR_BLOCK_ALIGNED(type, name, what)                                             \
  static_assert(std::is_same_v<detail::type, float> || offsetof(FrameBlock, name) % 16 == 0, \
                "std140: a vec4 or mat4 field starts on 16 bytes: keep scalars in fours");
DOWNPOUR_FRAME_BLOCK(DOWNPOUR_BLOCK_ALIGNED)
#undef DOWNPOUR_BLOCK_ALIGNED

struct LampBlock {
  glm::vec4 count{0.0f};  // x the ego car's headlights, y all the lamps
  glm::vec4 lamp[4 * kMaxLamps];
};

}  // namespace downpour::render
