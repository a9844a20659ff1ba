#version 330 core
// Translucent, two-sided, flat-lit surface. The face normal comes from screen-space derivatives of the
// position, so meshes need no normal buffer and a plane's shade is exactly computable (golden tests).
in vec3 v_view_pos;

uniform vec3 u_color;
uniform float u_alpha;
uniform vec3 u_light_dir;  // view space, unit, towards the light
uniform float u_ambient;
uniform float u_diffuse;

out vec4 frag_color;

void main() {
  vec3 n = normalize(cross(dFdx(v_view_pos), dFdy(v_view_pos)));
  if (dot(n, v_view_pos) > 0.0) n = -n;  // light the side that faces the camera
  float diffuse = max(dot(n, u_light_dir), 0.0);
  frag_color = vec4(u_color * (u_ambient + u_diffuse * diffuse), u_alpha);
}
