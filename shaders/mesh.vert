#version 450
// Static meshes: the terrain, the street lights' poles (mesh_vertex.glsl).
#include "mesh_vertex.glsl"
