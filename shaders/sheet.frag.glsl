#version 330 core
// Opaque, two-sided, smooth-lit sheet: the back face of a triangle is lit with the reversed normal, so a
// shell looks the same from either side (same lighting as the splats: ambient, diffuse, specular).
in vec3 v_view_pos;
in vec3 v_normal;
in vec3 v_color;

uniform vec3 u_light_dir;  // view space, unit, towards the light
uniform float u_ambient;
uniform float u_diffuse;
uniform float u_specular;
uniform float u_shininess;

out vec4 frag_color;

void main() {
  vec3 n = normalize(v_normal);
  if (!gl_FrontFacing) n = -n;
  // Interpolated vertex normals of a strongly bent sheet may still point away near a silhouette.
  if (dot(n, v_view_pos) > 0.0) n = -n;
  float diffuse = max(dot(n, u_light_dir), 0.0);
  vec3 half_vec = normalize(u_light_dir + vec3(0.0, 0.0, 1.0));
  float spec = pow(max(dot(n, half_vec), 0.0), u_shininess);
  frag_color = vec4(v_color * (u_ambient + u_diffuse * diffuse) + vec3(u_specular * spec), 1.0);
}
