#version 450
// The metaball's density N = 1 / (1 + (h/R)^4) from the precomputed profile across the sprite,
// added (blending ONE, ONE) into the height map.
layout(binding = 3) uniform sampler2D profile_tex;
out float out_height;
void main() { out_height = texture(profile_tex, gl_PointCoord).r; }
