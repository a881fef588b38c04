#version 450
// The cabin in the car's frame (cockpit_pass.hpp): u_model the identity, v_world the car's frame,
// and the clip position from u_clip_from_car, which is the same every frame for a camera fixed in
// the car, so that a cached picture of the cabin and a drawn one are the same pixels.
#define MESH_WHEELS
#define MESH_IN_CAR
#include "mesh_vertex.glsl"
