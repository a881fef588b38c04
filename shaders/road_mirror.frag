#version 450
// The road with the road reflection (road_surface.glsl).
#define ROAD_MIRROR
#include "road_surface.glsl"
