#version 450
// The road, with its curvature for the relief shadows (mesh_vertex.glsl).
#define MESH_CURVATURE
#define ROAD_LANES
#include "mesh_vertex.glsl"
