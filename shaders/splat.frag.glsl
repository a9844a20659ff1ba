#version 330 core
// Sphere impostor: reconstructs the sphere's surface inside the point sprite, lights it and writes the true
// depth of that surface, so splats intersect each other and the wall meshes correctly.
flat in vec3 v_center;
flat in vec3 v_color;
flat in float v_half_size;
flat in vec2 v_center_px;

uniform mat4 u_proj;
uniform float u_radius;
uniform vec3 u_light_dir;  // view space, unit, towards the light
uniform float u_ambient;
uniform float u_diffuse;
uniform float u_specular;
uniform float u_shininess;

out vec4 frag_color;

void main() {
  // Offset from the exact projected centre, not gl_PointCoord: rasterisers may snap a sprite's size and
  // position to whole pixels, which would shift the sphere by up to half a pixel.
  vec2 p = (gl_FragCoord.xy - v_center_px) / max(v_half_size, 1e-3);
  float r = length(p);
  // The sprite is one pixel larger than the sphere so that the rim's partly covered pixels get a fragment;
  // alpha to coverage turns the distance to the rim into a sample mask (anti-aliased silhouettes).
  float rim_px = (1.0 - r) * v_half_size;
  if (rim_px < -0.5) discard;
  float alpha = clamp(rim_px + 0.5, 0.0, 1.0);
  float r2 = min(r * r, 1.0);
  vec3 n = vec3(p / max(r, 1.0), sqrt(1.0 - r2));
  vec4 clip = u_proj * vec4(v_center + n * u_radius, 1.0);
  gl_FragDepth = clip.z / clip.w * 0.5 + 0.5;
  float diffuse = max(dot(n, u_light_dir), 0.0);
  vec3 half_vec = normalize(u_light_dir + vec3(0.0, 0.0, 1.0));
  float spec = pow(max(dot(n, half_vec), 0.0), u_shininess);
  frag_color = vec4(v_color * (u_ambient + u_diffuse * diffuse) + vec3(u_specular * spec), alpha);
}
