#pragma once
// Typed shader programs (after Magnum's Shaders::): each owns its Program, looks its uniform locations up once when
// it is made, and offers setters in the shader's own units - a frame sets numbers, never names. Shaders are the files
// in shaders/ (ShaderDir()); a missing uniform is a compile-time mistake of the file, refused when the program is made.
#include <glm/glm.hpp>

#include "render/gl_objects.h"

namespace blurcue::render {

// The uniforms of an object's surface that object.frag and ball.frag share: the thesis's colour matching.
class ColourUniforms {
 public:
  explicit ColourUniforms(const Program& program);
  // Brightness multiplies, contrast scales about mid grey (0.18), white balance multiplies red, green, blue.
  void SetColour(float brightness, float contrast, const glm::vec3& white_balance) const;

 private:
  GLint brightness_, contrast_, white_balance_;
};

// shaders/object.{vert,frag}: a textured card in the board frame, unlit, drawn into a layer.
class ObjectShader {
 public:
  ObjectShader();
  ObjectShader& Use();
  // Object -> camera frame (mm): the calibrated pose times the object's model matrix.
  ObjectShader& SetModelToCamera(const glm::mat4& model_to_camera);
  // Camera frame -> clip space.
  ObjectShader& SetProjection(const glm::mat4& projection);
  ObjectShader& SetColour(float brightness, float contrast, const glm::vec3& white_balance);

 private:
  Program program_;
  ColourUniforms colour_;
  GLint model_to_camera_, projection_;
};

// shaders/ball.frag (over fullscreen.vert): a ball ray-traced into a layer - the exact sphere, each pixel's coverage
// the share of its 16 rays that hit it; the colour layer, or with SetWriteDepth(true) the depth layer.
class BallShader {
 public:
  BallShader();
  BallShader& Use();
  // The pinhole camera (px), the layer's top-left pixel in its image, and the affine map from image px to the
  // pinhole's (the inverse of scene::LocalImageMap; the identity without distortion).
  BallShader& SetCamera(const glm::vec4& fx_fy_cx_cy, const glm::vec2& layer_origin_px, const glm::mat3& image_to_ideal);
  // The sphere in the camera frame (mm), and the rotation from the camera frame to its texture's frame.
  BallShader& SetSphere(const glm::vec3& center_camera_mm, float radius_mm, const glm::mat3& camera_to_object);
  BallShader& SetWriteDepth(bool depth);
  // Lambert light towards `direction` (camera frame, unit) with `ambient` of it undirected.
  BallShader& SetLight(const glm::vec3& direction, float ambient);
  BallShader& SetColour(float brightness, float contrast, const glm::vec3& white_balance);

 private:
  Program program_;
  ColourUniforms colour_;
  GLint intrinsics_, origin_, image_to_ideal_, center_, radius_, camera_to_object_, write_depth_, light_dir_, ambient_;
};

// shaders/blur_gaussian.frag: one pass of the separable Gaussian over a rectangle of a texture (no taps: a copy).
class GaussianBlurShader {
 public:
  GaussianBlurShader();
  GaussianBlurShader& Use();
  // The region read, texels x0 <= x < x1, y0 <= y < y1 (texels outside it repeat its border, as an image's would).
  GaussianBlurShader& SetRegion(int x0, int y0, int x1, int y1);
  // The kernel exp(-i^2 / 2 sigma^2), |i| <= taps (at most kMaxTaps), normalised; taps 0 copies.
  GaussianBlurShader& SetKernel(double sigma_px, int taps);
  static constexpr int kMaxTaps = 1023;
  GaussianBlurShader& SetDirection(int dx, int dy);

 private:
  Program program_;
  GLint region_, taps_, weights_, direction_;
};

// shaders/blur_disc.frag: the pillbox over a rectangle of a texture.
class DiscBlurShader {
 public:
  DiscBlurShader();
  DiscBlurShader& Use();
  DiscBlurShader& SetRegion(int x0, int y0, int x1, int y1);
  DiscBlurShader& SetKernel(float coverage_radius_px, int taps);

 private:
  Program program_;
  GLint region_, radius_, taps_;
};

// shaders/blur_kernel.frag: a general 2-D kernel (render/psf.h) read from a kernel atlas on image unit 1, over a
// rectangle of a texture.
class KernelBlurShader {
 public:
  KernelBlurShader();
  KernelBlurShader& Use();
  KernelBlurShader& SetRegion(int x0, int y0, int x1, int y1);
  // The kernel's top-left texel in the atlas and its half-width.
  KernelBlurShader& SetKernel(int origin_x, int origin_y, int taps);

 private:
  Program program_;
  GLint region_, origin_, taps_;
};

// shaders/composite.frag: a layer blended over the frame, texel (0, 0) of its texture landing on frame pixel `origin`.
class CompositeShader {
 public:
  CompositeShader();
  CompositeShader& Use();
  CompositeShader& SetOrigin(int x_px, int y_px);

 private:
  Program program_;
  GLint origin_;
};

static_assert(!std::is_copy_constructible_v<ObjectShader>);
static_assert(!std::is_copy_constructible_v<GaussianBlurShader>);
static_assert(!std::is_copy_constructible_v<KernelBlurShader>);

}  // namespace blurcue::render
