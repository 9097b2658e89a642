#version 420 core
// The thin-lens pillbox: every texel within radius R (= r, DESIGN.md) of the pixel, weighted by how much of it the
// disc covers (1 inside, a linear ramp over the last pixel, 0 outside), normalised. Linear, premultiplied RGBA.
layout(rgba32f, binding = 0) uniform readonly image2D u_image;  // read as an image, as the Gaussian's
uniform ivec4 u_region;        // the image: texels x0 <= x < x1, y0 <= y < y1 (outside it the border texel repeats)
uniform float u_radius_px;
uniform int u_taps;            // ceil(R + 0.5)
out vec4 o_color;
void main() {
  ivec2 lo = u_region.xy, hi = u_region.zw - 1;
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 sum = vec4(0.0);
  float weight_sum = 0.0;
  for (int dy = -u_taps; dy <= u_taps; ++dy) {
    for (int dx = -u_taps; dx <= u_taps; ++dx) {
      float w = clamp(u_radius_px + 0.5 - length(vec2(dx, dy)), 0.0, 1.0);
      if (w > 0.0) {
        sum += w * imageLoad(u_image, clamp(p + ivec2(dx, dy), lo, hi));
        weight_sum += w;
      }
    }
  }
  o_color = sum / weight_sum;
}
