#version 450
// Static meshes: the terrain, the vehicles (mesh_vertex.glsl).
#include "mesh_vertex.glsl"
