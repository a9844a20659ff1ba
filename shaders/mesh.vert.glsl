#version 330 core
// Wall surfaces (render: "surface"): world-space triangles, cut by the clip plane when the body is clipped.
layout(location = 0) in vec3 a_position;

uniform mat4 u_view;
uniform mat4 u_proj;
uniform vec4 u_clip_plane;  // (n, -dot(n, p0)) in world space; the +n side is removed

out vec3 v_view_pos;

void main() {
  vec4 view = u_view * vec4(a_position, 1.0);
  v_view_pos = view.xyz;
  gl_Position = u_proj * view;
  // Only used while GL_CLIP_DISTANCE0 is enabled (clipped bodies).
  gl_ClipDistance[0] = -dot(u_clip_plane, vec4(a_position, 1.0));
}
