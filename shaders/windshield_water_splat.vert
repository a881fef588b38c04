#version 450
// One metaball as a point sprite in glass space (seed 000, section 1.5 step 1): the map covers
// u_map_extent_mm from u_map_origin_mm; the sprite reaches u_extent_radii radii from the centre.
// Also the footprint of the compression pass.
layout(location = 0) in vec3 a_metaball;  // u, v (mm), radius R (mm)
uniform vec2 u_map_origin_mm;
uniform vec2 u_map_extent_mm;
uniform float u_extent_radii;
uniform float u_texels_per_mm;  // the map's texels are square
void main() {
  gl_PointSize = 2.0 * u_extent_radii * a_metaball.z * u_texels_per_mm;
  gl_Position = vec4((a_metaball.xy - u_map_origin_mm) / u_map_extent_mm * 2.0 - 1.0, 0.0, 1.0);
}
