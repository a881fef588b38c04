#version 450
// The road, dry or wet without a mirror, with relief shadows (road_surface.glsl).
#define ROAD_RELIEF
#include "road_surface.glsl"
