#version 450
// The road, dry or wet without a mirror (road_surface.glsl).
#include "road_surface.glsl"
