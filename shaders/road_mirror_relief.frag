#version 450
// The road with the road reflection and relief shadows (road_surface.glsl).
#define ROAD_MIRROR
#define ROAD_RELIEF
#include "road_surface.glsl"
