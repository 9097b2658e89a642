#version 330 core
// Blends one object layer over the frame: premultiplied linear RGBA out, with glBlendFunc(ONE, ONE_MINUS_SRC_ALPHA)
// on an sRGB framebuffer (GL decodes, blends in linear light and encodes).
uniform sampler2D u_layer;
uniform ivec2 u_origin;   // the frame pixel the layer texture's texel (0, 0) lands on (the layer's place in the
                          // frame less its place in the texture)
out vec4 o_color;
void main() {
  o_color = texelFetch(u_layer, ivec2(gl_FragCoord.xy) - u_origin, 0);
}
