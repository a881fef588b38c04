#version 450
// One triangle over the road's mirror, never clipped (the mirror's passes clip at the road's
// plane; the spray's clouds all lie above it).
out vec2 v_uv;
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  v_uv = p;
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
  gl_ClipDistance[0] = 1.0;
}
