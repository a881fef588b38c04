#version 450
#include "common.glsl"
in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;  // x material id (MATERIAL_*, interface.glsl), y a trim colour (trim_colour)
in vec4 v_fog;
out vec4 out_colour;
uniform vec3 u_body_colour;
// The lamps lit: x tail lamps, y brake lamps, z the left indicator, w the right (0 or 1); and the
// headlamps (a street light's lamp): 0 off, 1 on (low beam), 2 high beam.
uniform vec4 u_lamps;
uniform float u_head;
uniform float u_wet;  // how wet the spray has made this body (0 dry to 1)
in vec3 v_texture;  // where it reads model_tex: uv, layer (-1: none)
uniform float u_textured;  // 1 where the model has textures, else 0
// A lit lamp's lens as radiance: its luminance (cd/m^2) times the exposure, at least `floor`
// (by day a lit lamp still stands out from its housing), at most `cap` (a camera's red channel
// clips long before the others: a red lamp's core stays red).
vec3 lens(vec3 colour, float luminance, float floor_radiance, float cap) {
  return colour * clamp(3.14159 * frame.lamp_map.y * luminance, floor_radiance, cap);
}
void main() {
  vec3 n = normalize(v_normal);
  vec3 outward = n;  // the closed shapes' own side: what a lamp can light
  vec3 view = normalize(frame.camera_pos.xyz - v_world);
  n = dot(n, view) < 0.0 ? -n : n;
  int material = int(v_uv.x + 0.5);
  vec3 albedo = u_body_colour;
  float r0 = 0.04, gloss = 1.0;
  vec3 emit = vec3(0.0);
  const vec3 red = vec3(1.0, 0.005, 0.003), amber = vec3(1.0, 0.45, 0.0);
  if (material == MATERIAL_GLASS) {
    albedo = vec3(0.02, 0.025, 0.03);
    r0 = 0.06;
  } else if (material == MATERIAL_TYRE) {
    albedo = vec3(0.02);
    gloss = 0.1;
  } else if (material == MATERIAL_LAMP) {  // tail and brake
    albedo = vec3(0.3, 0.02, 0.02);
    emit = lens(red, 100.0 * u_lamps.x + 1500.0 * u_lamps.y,
                0.5 * u_lamps.x + 1.2 * u_lamps.y, 1.5 + 1.5 * u_lamps.y);
  } else if (material == MATERIAL_TRIM) {
    albedo = trim_colour(v_uv.y, vec3(0.03));
    gloss = 0.2;
  } else if (material == MATERIAL_HEADLAMP || material == MATERIAL_STREET_LAMP) {
    albedo = vec3(0.45);
    float intensity = material == MATERIAL_STREET_LAMP ? 5e4 : 2e5 * u_head;
    emit = lens(vec3(1.0, 0.96, 0.88), intensity, 1.5, 1e4) * step(0.5, u_head);
  } else if (material == MATERIAL_INDICATOR_LEFT || material == MATERIAL_INDICATOR_RIGHT) {
    albedo = vec3(0.35, 0.2, 0.02);
    float on = material == MATERIAL_INDICATOR_LEFT ? u_lamps.z : u_lamps.w;
    emit = lens(amber, 5000.0, 1.0, 3.0) * on;
  }
  // A glTF model's base-colour texture times the paint's or the trim's colour (sampled in uniform
  // control flow, for its derivatives; a vertex without one reads none).
  if (u_textured > 0.5) {
    vec3 t = texture(model_tex, v_texture).rgb;
    float own = step(-0.5, v_texture.z) *
                float(material == MATERIAL_BODY || material == MATERIAL_TRIM);
    albedo *= mix(vec3(1.0), t, own);
  }
  // Wet paint and trim (the weather's wetness, or the spray's that this body stopped): water in
  // the finish's roughness deepens its colour, as on the wet ground, and a film of it makes the
  // sheen a mirror.
  float wet = max(frame.wetness, u_wet) * float(material == MATERIAL_BODY || material == MATERIAL_TRIM);
  albedo *= mix(1.0, 0.72, wet);
  gloss = mix(gloss, 1.0, wet);
  r0 = mix(r0, 0.05, wet);
  // The lamps' light on the ground as what falls on this face: whole on a roof, a tenth on a side
  // (the street lights shine down; the cars' own beams are the ego car's, per pixel).
  vec3 light = diffuse_light(n) + lamp_ground(v_world) * (0.1 + 0.9 * max(outward.z, 0.0)) +
               ego_headlights(v_world, outward);
  vec3 colour = albedo * light + emit;
  float f = schlick(dot(n, view), r0);
  colour += surroundings(reflect(-view, n)) * f * gloss;
  out_colour = vec4(to_display(apply_fog(colour, v_fog)), 1.0);
}
