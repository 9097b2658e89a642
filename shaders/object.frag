#version 330 core
// Textured, simply lit surface; output is linear light with premultiplied alpha.
uniform sampler2D u_texture;   // sRGB texture: sampling returns linear values
uniform vec3 u_light_dir;      // towards the light, camera frame, unit
uniform float u_ambient;       // share of light that is not directional
uniform float u_lit;           // 1: Lambert lighting (ball); 0: flat (card, picture)
uniform float u_brightness;    // multiplies the linear colour
uniform float u_contrast;      // scales around the texture's mid grey (0.18 linear)
uniform vec3 u_white_balance;  // gains of red, green and blue
in vec3 v_normal_camera;
in vec2 v_uv;
in float v_depth_mm;
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_depth;   // camera z (mm) of the surface, 0 where nothing is drawn
void main() {
  vec4 t = texture(u_texture, v_uv);
  vec3 c = max((t.rgb - 0.18) * u_contrast + 0.18, 0.0) * u_brightness * u_white_balance;
  float shade = mix(1.0, u_ambient + (1.0 - u_ambient) * max(dot(normalize(v_normal_camera), u_light_dir), 0.0), u_lit);
  o_color = vec4(c * shade * t.a, t.a);
  o_depth = vec4(v_depth_mm, 0.0, 0.0, 1.0);
}
