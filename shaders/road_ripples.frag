#version 450
// The road with the road reflection and ripples in its puddles (road_surface.glsl).
#define ROAD_MIRROR
#define ROAD_RIPPLES
#include "road_surface.glsl"
