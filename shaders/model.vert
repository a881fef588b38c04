#version 450
// Vehicle and cabin models, their wheels turned in the shader (mesh_vertex.glsl).
#define MESH_WHEELS
#include "mesh_vertex.glsl"
