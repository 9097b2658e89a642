#version 400 core
// A ball traced, not tessellated: each pixel of the layer casts the camera's rays through 4 x 4 points spread over
// it at the exact sphere, so the silhouette is the true projected outline (no polygon) and the pixel's coverage is
// the share of its rays that hit - what a 16x multisampled mesh would resolve to, with no multisample buffer to
// clear or resolve. Every pixel of the layer is written (0 where nothing is hit). The surface is shaded once per pixel from
// the ray through its centre (or, where that misses, the nearest point of the rim): textured by the sphere's
// longitude and latitude, simply lit; linear light, premultiplied alpha (the same colour terms as object.frag).
// Nothing here depends on where the layer lies or on its neighbours: a pixel is the same in any layer.
uniform sampler2D u_texture;     // sRGB equirectangular texture: sampling returns linear values
uniform vec4 u_intrinsics;       // fx, fy, cx, cy (px)
uniform vec2 u_origin;           // the layer's top-left pixel in the image (framebuffer row = image row)
uniform mat3 u_image_to_ideal;   // image px -> ideal (pinhole) px: the inverse of the lens distortion's local affine
                                 // map at the ball (scene::LocalImageMap); the identity without distortion
uniform vec3 u_center;           // the sphere's centre, camera frame (mm)
uniform float u_radius;          // mm
uniform mat3 u_camera_to_object; // camera-frame offsets from the centre -> the unit sphere's frame (spin undone)
uniform bool u_write_depth;      // write the depth layer (camera z x coverage, coverage) instead of the colour
uniform vec3 u_light_dir;        // towards the light, camera frame, unit
uniform float u_ambient;
uniform float u_brightness;
uniform float u_contrast;
uniform vec3 u_white_balance;
layout(location = 0) out vec4 o_layer;  // premultiplied colour x coverage; or camera z (mm) x coverage in .r

// Where the ray through image point `px` (pixel centres at integers) meets the sphere: x = distance along the ray
// direction (z = 1 units), y = the discriminant (< 0: a miss; also when the sphere is not in front of the eye).
vec2 Hit(vec2 px) {
  vec3 d = vec3(((u_image_to_ideal * vec3(px, 1.0)).xy - u_intrinsics.zw) / u_intrinsics.xy, 1.0);
  float b = dot(d, u_center), a = dot(d, d);
  float disc = b * b - a * (dot(u_center, u_center) - u_radius * u_radius);
  float t = (b - sqrt(max(disc, 0.0))) / a;
  return vec2(t, t > 0.0 ? disc : -1.0);  // a sphere behind the eye, or around it, is not seen
}

// The texture coordinates of the surface the ray through `px` meets (the nearest rim point where it misses):
// longitude along u (its seam at u = 0 = 1), latitude along v (0 at the +z pole), as the texture is laid out; and in
// .zw the camera-frame point's z and the discriminant.
vec4 SurfaceAt(vec2 px, out vec3 p) {
  vec3 d = vec3(((u_image_to_ideal * vec3(px, 1.0)).xy - u_intrinsics.zw) / u_intrinsics.xy, 1.0);
  vec2 hit = Hit(px);
  p = hit.x * d;
  vec3 o = normalize(u_camera_to_object * (p - u_center));
  return vec4(fract(atan(o.y, o.x) / 6.28318530718), acos(clamp(o.z, -1.0, 1.0)) / 3.14159265359, p.z, hit.y);
}

void main() {
  vec2 corner = u_origin + floor(gl_FragCoord.xy) - 0.5;  // the pixel's lower-left corner in image coordinates
  int hits = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      if (Hit(corner + (vec2(i, j) + 0.5) / 4.0).y >= 0.0) ++hits;
  float coverage = float(hits) / 16.0;
  if (hits == 0) {
    o_layer = vec4(0.0);
    return;
  }
  vec2 centre = corner + 0.5;
  vec3 p, p_x, p_y;
  vec4 s = SurfaceAt(centre, p);
  if (u_write_depth) {
    o_layer = vec4(p.z * coverage, 0.0, 0.0, coverage);
    return;
  }
  // The texture's footprint from the rays one pixel over, not from the GPU's 2 x 2 quads: a pixel's colour then
  // depends on nothing but its own place (a ball drawn in a small layer and in a whole frame match), and u's step
  // is taken the short way round the seam.
  vec2 sx = SurfaceAt(centre + vec2(1.0, 0.0), p_x).xy - s.xy, sy = SurfaceAt(centre + vec2(0.0, 1.0), p_y).xy - s.xy;
  sx.x = fract(sx.x + 0.5) - 0.5;
  sy.x = fract(sy.x + 0.5) - 0.5;
  vec4 t = textureGrad(u_texture, s.xy, sx, sy);
  vec3 n = normalize(p - u_center);
  vec3 c = max((t.rgb - 0.18) * u_contrast + 0.18, 0.0) * u_brightness * u_white_balance;
  float shade = u_ambient + (1.0 - u_ambient) * max(dot(n, u_light_dir), 0.0);
  o_layer = vec4(c * shade * t.a, t.a) * coverage;
}
