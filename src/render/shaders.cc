#include "render/shaders.h"

#include <cmath>

#include <glm/gtc/type_ptr.hpp>

namespace blurcue::render {
namespace {
Program FullscreenProgram(const char* fragment) {
  return Program::FromFiles(ShaderDir() / "fullscreen.vert", ShaderDir() / fragment);
}
// Every program here samples one texture, from unit 0.
void ImageOnUnitZero(const Program& program, const char* sampler) {
  program.Use();
  glUniform1i(program.Uniform(sampler), 0);
}
}  // namespace

ColourUniforms::ColourUniforms(const Program& program)
    : brightness_(program.Uniform("u_brightness")),
      contrast_(program.Uniform("u_contrast")),
      white_balance_(program.Uniform("u_white_balance")) {}
void ColourUniforms::SetColour(float brightness, float contrast, const glm::vec3& white_balance) const {
  glUniform1f(brightness_, brightness);
  glUniform1f(contrast_, contrast);
  glUniform3f(white_balance_, white_balance.x, white_balance.y, white_balance.z);
}

ObjectShader::ObjectShader()
    : program_(Program::FromFiles(ShaderDir() / "object.vert", ShaderDir() / "object.frag")),
      colour_(program_),
      model_to_camera_(program_.Uniform("u_model_to_camera")),
      projection_(program_.Uniform("u_projection")) {
  ImageOnUnitZero(program_, "u_texture");
}

ObjectShader& ObjectShader::Use() {
  program_.Use();
  return *this;
}
ObjectShader& ObjectShader::SetModelToCamera(const glm::mat4& model_to_camera) {
  glUniformMatrix4fv(model_to_camera_, 1, GL_FALSE, glm::value_ptr(model_to_camera));
  return *this;
}
ObjectShader& ObjectShader::SetProjection(const glm::mat4& projection) {
  glUniformMatrix4fv(projection_, 1, GL_FALSE, glm::value_ptr(projection));
  return *this;
}
ObjectShader& ObjectShader::SetColour(float brightness, float contrast, const glm::vec3& white_balance) {
  colour_.SetColour(brightness, contrast, white_balance);
  return *this;
}

BallShader::BallShader()
    : program_(FullscreenProgram("ball.frag")),
      colour_(program_),
      intrinsics_(program_.Uniform("u_intrinsics")),
      origin_(program_.Uniform("u_origin")),
      image_to_ideal_(program_.Uniform("u_image_to_ideal")),
      center_(program_.Uniform("u_center")),
      radius_(program_.Uniform("u_radius")),
      camera_to_object_(program_.Uniform("u_camera_to_object")),
      write_depth_(program_.Uniform("u_write_depth")),
      light_dir_(program_.Uniform("u_light_dir")),
      ambient_(program_.Uniform("u_ambient")) {
  ImageOnUnitZero(program_, "u_texture");
}
BallShader& BallShader::Use() {
  program_.Use();
  return *this;
}
BallShader& BallShader::SetCamera(const glm::vec4& k, const glm::vec2& origin, const glm::mat3& image_to_ideal) {
  glUniform4f(intrinsics_, k.x, k.y, k.z, k.w);
  glUniform2f(origin_, origin.x, origin.y);
  glUniformMatrix3fv(image_to_ideal_, 1, GL_FALSE, glm::value_ptr(image_to_ideal));
  return *this;
}
BallShader& BallShader::SetSphere(const glm::vec3& center, float radius_mm, const glm::mat3& camera_to_object) {
  glUniform3f(center_, center.x, center.y, center.z);
  glUniform1f(radius_, radius_mm);
  glUniformMatrix3fv(camera_to_object_, 1, GL_FALSE, glm::value_ptr(camera_to_object));
  return *this;
}
BallShader& BallShader::SetWriteDepth(bool depth) {
  glUniform1i(write_depth_, depth ? 1 : 0);
  return *this;
}
BallShader& BallShader::SetLight(const glm::vec3& direction, float ambient) {
  glUniform3f(light_dir_, direction.x, direction.y, direction.z);
  glUniform1f(ambient_, ambient);
  return *this;
}
BallShader& BallShader::SetColour(float brightness, float contrast, const glm::vec3& white_balance) {
  colour_.SetColour(brightness, contrast, white_balance);
  return *this;
}

GaussianBlurShader::GaussianBlurShader()
    : program_(FullscreenProgram("blur_gaussian.frag")),
      region_(program_.Uniform("u_region")),
      taps_(program_.Uniform("u_taps")),
      weights_(program_.Uniform("u_weights")),
      direction_(program_.Uniform("u_direction")) {
}
GaussianBlurShader& GaussianBlurShader::Use() {
  program_.Use();
  return *this;
}
GaussianBlurShader& GaussianBlurShader::SetRegion(int x0, int y0, int x1, int y1) {
  glUniform4i(region_, x0, y0, x1, y1);
  return *this;
}
GaussianBlurShader& GaussianBlurShader::SetKernel(double sigma_px, int taps) {
  CV_Assert(taps >= 0 && taps <= kMaxTaps);
  double raw[kMaxTaps + 1];
  float weights[kMaxTaps + 1];
  double sum = 0;
  for (int i = 0; i <= taps; ++i) raw[i] = std::exp(-0.5 * i * i / (sigma_px * sigma_px)), sum += i ? 2 * raw[i] : raw[i];
  for (int i = 0; i <= taps; ++i) weights[i] = float(raw[i] / sum);
  glUniform1i(taps_, taps);
  glUniform1fv(weights_, taps + 1, weights);
  return *this;
}
GaussianBlurShader& GaussianBlurShader::SetDirection(int dx, int dy) {
  glUniform2i(direction_, dx, dy);
  return *this;
}

DiscBlurShader::DiscBlurShader()
    : program_(FullscreenProgram("blur_disc.frag")),
      region_(program_.Uniform("u_region")),
      radius_(program_.Uniform("u_radius_px")),
      taps_(program_.Uniform("u_taps")) {
}
DiscBlurShader& DiscBlurShader::Use() {
  program_.Use();
  return *this;
}
DiscBlurShader& DiscBlurShader::SetRegion(int x0, int y0, int x1, int y1) {
  glUniform4i(region_, x0, y0, x1, y1);
  return *this;
}
DiscBlurShader& DiscBlurShader::SetKernel(float coverage_radius_px, int taps) {
  glUniform1f(radius_, coverage_radius_px);
  glUniform1i(taps_, taps);
  return *this;
}

KernelBlurShader::KernelBlurShader()
    : program_(FullscreenProgram("blur_kernel.frag")),
      region_(program_.Uniform("u_region")),
      origin_(program_.Uniform("u_kernel_origin")),
      taps_(program_.Uniform("u_taps")) {}
KernelBlurShader& KernelBlurShader::Use() {
  program_.Use();
  return *this;
}
KernelBlurShader& KernelBlurShader::SetRegion(int x0, int y0, int x1, int y1) {
  glUniform4i(region_, x0, y0, x1, y1);
  return *this;
}
KernelBlurShader& KernelBlurShader::SetKernel(int origin_x, int origin_y, int taps) {
  glUniform2i(origin_, origin_x, origin_y);
  glUniform1i(taps_, taps);
  return *this;
}

CompositeShader::CompositeShader()
    : program_(FullscreenProgram("composite.frag")), origin_(program_.Uniform("u_origin")) {
  ImageOnUnitZero(program_, "u_layer");
}
CompositeShader& CompositeShader::Use() {
  program_.Use();
  return *this;
}
CompositeShader& CompositeShader::SetOrigin(int x_px, int y_px) {
  glUniform2i(origin_, x_px, y_px);
  return *this;
}

}  // namespace blurcue::render
