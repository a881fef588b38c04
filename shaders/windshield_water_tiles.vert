#version 450
// The water map's tiles that some metaball reaches, in the map's clip space: the compression's
// footprint when the sprites pile up (windshield_water_pass.cpp).
layout(location = 0) in vec2 a_position;
void main() { gl_Position = vec4(a_position, 0.0, 1.0); }
