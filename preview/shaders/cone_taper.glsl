// The blend taper of a luminaire folder's orientation: core/luminaire_set.h's ConeTaper in GLSL
// (tests/preview's PreviewLuminaire.ShaderTaperEqualsConeTaper pins the two equal). cone: d, the
// usable half-width and half-height on the screen plane (mm, OrientationCone); w: a unit
// direction in the orientation's capture frame.
float ConeMarginDeg(vec3 cone, vec3 w) {
  if (w.z <= 0.0) return -90.0;  // behind S
  const float to_deg = 57.295779513082323;
  const float limit_x = atan(cone.y, cone.x) * to_deg, limit_y = atan(cone.z, cone.x) * to_deg;
  return min(limit_x - atan(abs(w.x), w.z) * to_deg, limit_y - atan(abs(w.y), w.z) * to_deg);
}
// 0 outside the cone, smoothstep 3t^2 - 2t^3 of t = margin / taper_deg inside, 1 beyond.
float TaperOfMargin(float margin_deg, float taper_deg) {
  const float t = margin_deg / taper_deg;
  if (t <= 0.0) return 0.0;
  if (t >= 1.0) return 1.0;
  return t * t * (3.0 - 2.0 * t);
}
float ConeTaper(vec3 cone, vec3 w, float taper_deg) {
  return TaperOfMargin(ConeMarginDeg(cone, w), taper_deg);
}
