#version 330 core
// One pass of the separable Gaussian (the thesis's appendix A shader, in linear light with premultiplied alpha).
// Weights exp(-i^2 / (2 s^2)) for |i| <= u_taps, normalised by their sum (eq. 4.6) so brightness is kept.
// Texels are fetched exactly; outside the region the border texel repeats (clamp to edge).
uniform sampler2D u_image;     // linear, premultiplied RGBA
uniform ivec4 u_region;        // the image: texels x0 <= x < x1, y0 <= y < y1 of the texture (x0, y0, x1, y1)
uniform ivec2 u_direction;     // (1, 0) horizontal pass, (0, 1) vertical pass
uniform float u_sigma_px;      // GaussianKernelSigma(r / 2): the width whose discrete kernel has variance (r / 2)^2
uniform int u_taps;            // kernel half-width, ceil(3 r / 2): as wide as it needs and no wider
out vec4 o_color;
void main() {
  ivec2 lo = u_region.xy, hi = u_region.zw - 1;
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec2 step = u_direction;
  vec4 sum = texelFetch(u_image, p, 0);
  float weight_sum = 1.0;
  float k = -0.5 / (u_sigma_px * u_sigma_px);
  for (int i = 1; i <= u_taps; ++i) {
    float w = exp(k * float(i * i));
    ivec2 a = clamp(p - i * step, lo, hi);
    ivec2 b = clamp(p + i * step, lo, hi);
    sum += w * (texelFetch(u_image, a, 0) + texelFetch(u_image, b, 0));
    weight_sum += 2.0 * w;
  }
  o_color = sum / weight_sum;
}
