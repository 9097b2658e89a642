#version 330 core
// A card placed in the board frame (mm), projected with the calibrated pose and intrinsics.
layout(location = 0) in vec3 a_position;  // object frame (the unit card)
layout(location = 1) in vec2 a_uv;
uniform mat4 u_model_to_camera;           // object -> camera frame (mm): the calibrated pose x the object's placement
uniform mat4 u_projection;                // camera frame -> clip, image rows = framebuffer rows
out vec2 v_uv;
out float v_depth_mm;
void main() {
  vec4 p = u_model_to_camera * vec4(a_position, 1.0);
  v_uv = a_uv;
  v_depth_mm = p.z;
  gl_Position = u_projection * p;
}
