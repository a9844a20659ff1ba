#version 330 core
// Particle splats: one GL_POINT per particle, drawn as a lit sphere impostor by splat.frag.glsl.
// The point size is the sphere's projected diameter in pixels, so splats scale with distance.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec4 a_color;

uniform mat4 u_view;
uniform mat4 u_proj;
uniform float u_radius;           // world units (spacing / 2)
uniform vec2 u_viewport;  // pixels
uniform float u_max_point_size;   // the implementation's limit (255 on llvmpipe)

flat out float v_view_z;  // the centre's view-space z (the fragment's depth needs only that)
flat out vec3 v_color;
flat out float v_half_size;  // radius in pixels
flat out vec2 v_center_px;   // window coordinates of the centre
flat out float v_inv_half_size;

void main() {
  vec4 view = u_view * vec4(a_position, 1.0);
  v_view_z = view.z;
  v_color = a_color.rgb;
  gl_Position = u_proj * view;
  float w = max(gl_Position.w, 1e-6);
  float diameter = u_radius * u_proj[1][1] * u_viewport.y / w;
  // Slack so that the anti-aliased rim gets every sample it covers: the rim's alpha reaches 0 half a pixel
  // outside the sphere (pixel centre), and a pixel's samples lie up to 0.375 px off its centre (4x MSAA),
  // so the square must reach 0.5 + 0.375 px past the sphere on each side: 1.75 px in all. (2 px until stop
  // 65: identical images, 8 % more fragments on 4-pixel sprites; 1.5 px drops rim samples, visibly.)
  gl_PointSize = clamp(diameter + 1.75, 1.0, u_max_point_size);
  v_half_size = 0.5 * min(diameter, u_max_point_size - 2.0);
  v_inv_half_size = 1.0 / max(v_half_size, 1e-3);
  v_center_px = (gl_Position.xy / w * 0.5 + 0.5) * u_viewport;
}
