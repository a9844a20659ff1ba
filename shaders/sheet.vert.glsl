#version 330 core
// Shell sheets: triangles through the shell particles at their current positions, with per-vertex normals
// (area-weighted from the triangles) and per-vertex colours (the frame's field through the colormap, or the
// body colour); cut by the clip plane when the body is clipped.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_color;

uniform mat4 u_view;
uniform mat4 u_proj;
uniform vec4 u_clip_plane;  // (n, -dot(n, p0)) in world space; the +n side is removed

out vec3 v_view_pos;
out vec3 v_normal;  // view space
out vec3 v_color;

void main() {
  vec4 view = u_view * vec4(a_position, 1.0);
  v_view_pos = view.xyz;
  v_normal = mat3(u_view) * a_normal;  // the view matrix is a rotation and a translation
  v_color = a_color.rgb;
  gl_Position = u_proj * view;
  gl_ClipDistance[0] = -dot(u_clip_plane, vec4(a_position, 1.0));
}
