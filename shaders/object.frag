#version 330 core
// A textured card, unlit (a printed card under the scene's light; balls are traced and lit in ball.frag); output is
// linear light with premultiplied alpha.
uniform sampler2D u_texture;   // sRGB texture: sampling returns linear values
uniform float u_brightness;    // multiplies the linear colour
uniform float u_contrast;      // scales around the texture's mid grey (0.18 linear)
uniform vec3 u_white_balance;  // gains of red, green and blue
in vec2 v_uv;
in float v_depth_mm;
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_depth;   // camera z (mm) of the surface, 0 where nothing is drawn
void main() {
  vec4 t = texture(u_texture, v_uv);
  vec3 c = max((t.rgb - 0.18) * u_contrast + 0.18, 0.0) * u_brightness * u_white_balance;
  o_color = vec4(c * t.a, t.a);
  o_depth = vec4(v_depth_mm, 0.0, 0.0, 1.0);
}
