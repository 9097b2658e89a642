#version 420 core
// One pass of the separable Gaussian (the thesis's appendix A shader, in linear light with premultiplied alpha).
// Weights exp(-i^2 / (2 s^2)) for |i| <= u_taps, normalised by their sum (eq. 4.6) so brightness is kept - worked
// out once per kernel on the CPU (GaussianBlurShader::SetKernel), not per pixel and tap: llvmpipe runs this on the
// CPU, where an exp per tap was most of a blur's cost. Texels are read exactly, as an image (imageLoad: on llvmpipe a
// third cheaper than texelFetch through the sampler); outside the region the border texel repeats (clamp to edge).
layout(rgba32f, binding = 0) uniform readonly image2D u_image;  // linear, premultiplied RGBA
uniform ivec4 u_region;        // the image: texels x0 <= x < x1, y0 <= y < y1 of the texture (x0, y0, x1, y1)
uniform ivec2 u_direction;     // (1, 0) horizontal pass, (0, 1) vertical pass
uniform int u_taps;            // kernel half-width, ceil(3 r / 2): as wide as it needs and no wider (0: a copy)
uniform float u_weights[1024]; // the normalised weights of taps 0 .. u_taps (the width GaussianKernelSigma(r / 2):
                               // the discrete kernel's variance is exactly (r / 2)^2)
out vec4 o_color;
void main() {
  ivec2 lo = u_region.xy, hi = u_region.zw - 1;
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec2 step = u_direction;
  vec4 sum = u_weights[0] * imageLoad(u_image, p);
  for (int i = 1; i <= u_taps; ++i) {
    ivec2 a = clamp(p - i * step, lo, hi);
    ivec2 b = clamp(p + i * step, lo, hi);
    sum += u_weights[i] * (imageLoad(u_image, a) + imageLoad(u_image, b));
  }
  o_color = sum;
}
