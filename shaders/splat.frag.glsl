#version 330 core
// Sphere impostor: reconstructs the sphere's surface inside the point sprite, lights it and writes the true
// depth of that surface, so splats intersect each other and the wall meshes correctly.
flat in float v_view_z;
flat in vec3 v_color;
flat in float v_half_size;
flat in vec2 v_center_px;
flat in float v_inv_half_size;  // 1 / max(v_half_size, 1e-3), once per sprite instead of per fragment

uniform mat4 u_proj;
uniform float u_radius;
uniform vec3 u_light_dir;  // view space, unit, towards the light
uniform float u_ambient;
uniform float u_diffuse;
uniform float u_specular;
uniform vec3 u_half_vec;     // normalize(u_light_dir + (0, 0, 1)), the Blinn half vector

out vec4 frag_color;

void main() {
  // Offset from the exact projected centre, not gl_PointCoord: rasterisers may snap a sprite's size and
  // position to whole pixels, which would shift the sphere by up to half a pixel.
  vec2 p = (gl_FragCoord.xy - v_center_px) * v_inv_half_size;
  float r = length(p);
  // The sprite is larger than the sphere (splat.vert.glsl) so that the rim's partly covered pixels get a
  // fragment; alpha to coverage turns the distance to the rim into a sample mask (anti-aliased silhouettes).
  float rim_px = (1.0 - r) * v_half_size;
  if (rim_px < -0.5) discard;
  float alpha = clamp(rim_px + 0.5, 0.0, 1.0);
  float r2 = min(r * r, 1.0);
  vec3 n = vec3(p * (1.0 / max(r, 1.0)), sqrt(1.0 - r2));
  // The depth of the sphere's surface: a perspective projection's clip z and w depend on the view z only
  // (clip z = P22 z + P32, clip w = P23 z), so two of its entries do what the whole matrix product did.
  float z = v_view_z + n.z * u_radius;
  gl_FragDepth = (u_proj[2][2] * z + u_proj[3][2]) / (u_proj[2][3] * z) * 0.5 + 0.5;
  float diffuse = max(dot(n, u_light_dir), 0.0);
  float s1 = max(dot(n, u_half_vec), 0.0);
  // s1^24 (the shininess, Lighting::kShininess) by squaring: pow() is an exp2(log2()) per fragment.
  float s3 = s1 * s1 * s1, s6 = s3 * s3, s12 = s6 * s6;
  float spec = s12 * s12;
  frag_color = vec4(v_color * (u_ambient + u_diffuse * diffuse) + vec3(u_specular * spec), alpha);
}
