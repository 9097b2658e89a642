#version 330 core
// Blends one object layer over the frame: premultiplied linear RGBA out, with glBlendFunc(ONE, ONE_MINUS_SRC_ALPHA)
// on an sRGB framebuffer (GL decodes, blends in linear light and encodes).
uniform sampler2D u_layer;
uniform ivec2 u_origin;   // the layer's top-left pixel in the frame
out vec4 o_color;
void main() {
  o_color = texelFetch(u_layer, ivec2(gl_FragCoord.xy) - u_origin, 0);
}
