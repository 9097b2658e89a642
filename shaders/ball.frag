#version 400 core
// A ball traced, not tessellated: each pixel of the layer casts the camera's rays through its multisample positions
// at the exact sphere, so the silhouette is the true projected outline (no polygon) and each sample's coverage is
// its own ray's hit (gl_SampleMask), as a 4x multisampled mesh would give. The surface is shaded once per pixel from
// the ray through its centre (or, where that misses, the nearest point of the rim): textured by the sphere's
// longitude and latitude, simply lit; linear light, premultiplied alpha (the same colour terms as object.frag).
uniform sampler2D u_texture;     // sRGB equirectangular texture: sampling returns linear values
uniform vec4 u_intrinsics;       // fx, fy, cx, cy (px)
uniform vec2 u_origin;           // the layer's top-left pixel in the image (framebuffer row = image row)
uniform vec3 u_center;           // the sphere's centre, camera frame (mm)
uniform float u_radius;          // mm
uniform mat3 u_camera_to_object; // camera-frame offsets from the centre -> the unit sphere's frame (spin undone)
uniform int u_samples;           // samples per pixel
uniform vec2 u_sample_at[16];    // each sample's position in its pixel (0..1 from the pixel's lower-left corner)
uniform vec3 u_light_dir;        // towards the light, camera frame, unit
uniform float u_ambient;
uniform float u_brightness;
uniform float u_contrast;
uniform vec3 u_white_balance;
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_depth;   // camera z (mm) of the surface, 0 where nothing is drawn

// Where the ray through image point `px` (pixel centres at integers) meets the sphere: x = distance along the ray
// direction (z = 1 units), y = the discriminant (< 0: a miss).
vec2 Hit(vec2 px) {
  vec3 d = vec3((px - u_intrinsics.zw) / u_intrinsics.xy, 1.0);
  float b = dot(d, u_center), a = dot(d, d);
  float disc = b * b - a * (dot(u_center, u_center) - u_radius * u_radius);
  return vec2((b - sqrt(max(disc, 0.0))) / a, disc);
}

void main() {
  vec2 corner = u_origin + floor(gl_FragCoord.xy) - 0.5;  // the pixel's lower-left corner in image coordinates
  int mask = 0;
  for (int i = 0; i < u_samples; ++i)
    if (Hit(corner + u_sample_at[i]).y >= 0.0) mask |= 1 << i;
  vec2 centre = corner + 0.5;
  vec3 d = vec3((centre - u_intrinsics.zw) / u_intrinsics.xy, 1.0);
  vec3 p = Hit(centre).x * d;
  vec3 n = normalize(p - u_center);
  vec3 o = normalize(u_camera_to_object * (p - u_center));
  // Longitude along u (its seam at u = 0 = 1), latitude along v (0 at the +z pole), as the texture is laid out. The
  // mip level comes from u's derivative on whichever side of the seam it is continuous (Tarini's two
  // parameterisations), so no line of the smallest mip shows along the seam.
  float u1 = atan(o.y, o.x) / 6.28318530718;
  float u0 = fract(u1);
  float v = acos(clamp(o.z, -1.0, 1.0)) / 3.14159265359;
  vec2 uv = vec2(u0, v), uv_alt = vec2(fract(u0 + 0.5) - 0.5, v);
  vec2 dx = dFdx(uv), dy = dFdy(uv), dx_alt = dFdx(uv_alt), dy_alt = dFdy(uv_alt);
  if (abs(dx_alt.x) + abs(dy_alt.x) < abs(dx.x) + abs(dy.x)) dx = dx_alt, dy = dy_alt;
  vec4 t = textureGrad(u_texture, uv, dx, dy);
  gl_SampleMask[0] = mask;
  if (mask == 0) discard;
  vec3 c = max((t.rgb - 0.18) * u_contrast + 0.18, 0.0) * u_brightness * u_white_balance;
  float shade = u_ambient + (1.0 - u_ambient) * max(dot(n, u_light_dir), 0.0);
  o_color = vec4(c * shade * t.a, t.a);
  o_depth = vec4(p.z, 0.0, 0.0, 1.0);
}
