// Clip coordinates of luminaire-frame point x seen from c (z = 0): xy of NDC = slab texture
// coordinates 2u-1, 2v-1 (u from -W/2, v from +H/2), so shadow maps share the slab texel layout;
// NDC z = A + B / z (u_depth, between the shadow maps' near and far planes).
uniform float u_d;
uniform vec2 u_window;  // W, H (mm)
uniform vec2 u_depth;   // A, B of the depth mapping
vec4 LightClip(vec3 x, vec2 c) {
  vec3 rel = x - vec3(c, 0.0);
  return vec4(2.0 * u_d / u_window.x * rel.x + 2.0 * c.x / u_window.x * rel.z,
              -2.0 * u_d / u_window.y * rel.y - 2.0 * c.y / u_window.y * rel.z,
              u_depth.x * rel.z + u_depth.y, rel.z);
}
