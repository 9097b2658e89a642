#version 420 core
// One pass of a general 2-D kernel (render/psf.h: defocus x lens floor x motion streak), its normalised weights
// worked out on the CPU and read from a kernel atlas (the red channel), over a rectangle of a texture in linear,
// premultiplied RGBA; outside the rectangle the border texel repeats (clamp to edge). Taps of weight 0 are skipped:
// a streak's kernel is mostly empty.
layout(rgba32f, binding = 0) uniform readonly image2D u_image;
layout(rgba32f, binding = 1) uniform readonly image2D u_kernel;
uniform ivec4 u_region;        // the image: texels x0 <= x < x1, y0 <= y < y1
uniform ivec2 u_kernel_origin; // the kernel's top-left texel in the atlas: weight (dx, dy) at origin + (dx, dy) + taps
uniform int u_taps;            // the kernel's half-width
out vec4 o_color;
void main() {
  ivec2 lo = u_region.xy, hi = u_region.zw - 1;
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 sum = vec4(0.0);
  for (int dy = -u_taps; dy <= u_taps; ++dy) {
    for (int dx = -u_taps; dx <= u_taps; ++dx) {
      float w = imageLoad(u_kernel, u_kernel_origin + ivec2(dx + u_taps, dy + u_taps)).r;
      if (w != 0.0) sum += w * imageLoad(u_image, clamp(p + ivec2(dx, dy), lo, hi));
    }
  }
  o_color = sum;
}
