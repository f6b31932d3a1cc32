// One triangle that covers the viewport (vertices 0, 1, 2, no attributes), v_uv from 0 to 1
// across it: the full-screen passes.
#version 450 core
out vec2 v_uv;
void main() {
  vec2 p = vec2((gl_VertexID & 1) * 4.0 - 1.0, (gl_VertexID & 2) * 2.0 - 1.0);
  v_uv = 0.5 * p + 0.5;
  gl_Position = vec4(p, 0.0, 1.0);
}
