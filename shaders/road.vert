#version 450
// The road, with its curvature for the relief shadows (mesh_vertex.glsl).
#define MESH_CURVATURE
#include "mesh_vertex.glsl"
