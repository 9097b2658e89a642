#include "render/gl_objects.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/data_dir.h"
#include "core/error.h"

namespace blurcue::render {
namespace {

std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "cannot open shader file");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

GLuint Compile(GLenum type, const std::string& source, const std::string& name) {
  const GLuint shader = glCreateShader(type);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(std::max(length, 1));
    glGetShaderInfoLog(shader, length, nullptr, log.data());
    glDeleteShader(shader);
    throw Error(ErrorKind::kInternal, name + ": compile failed: " + std::string(log.data()));
  }
  return shader;
}

}  // namespace

std::filesystem::path ShaderDir() {
  if (const char* dir = std::getenv("BLURCUE_SHADER_DIR")) return dir;
  return DataDir().path / "shaders";
}

Program Program::FromFiles(const std::filesystem::path& vertex, const std::filesystem::path& fragment) {
  return FromSource(ReadText(vertex), ReadText(fragment), vertex.string() + " + " + fragment.string());
}

GLint Program::Uniform(const char* name) const {
  const GLint location = glGetUniformLocation(name_.id(), name);
  if (location < 0) throw Error(ErrorKind::kInternal, files_ + ": no active uniform '" + std::string(name) + "'");
  return location;
}

Program Program::FromSource(const std::string& vertex, const std::string& fragment, const std::string& name) {
  const GLuint vs = Compile(GL_VERTEX_SHADER, vertex, name + " (vertex)");
  GLuint fs = 0;
  try {
    fs = Compile(GL_FRAGMENT_SHADER, fragment, name + " (fragment)");
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  Program p;
  p.files_ = name;
  p.name_ = GlName(glCreateProgram(), [](GLuint id) { glDeleteProgram(id); });
  glAttachShader(p.id(), vs);
  glAttachShader(p.id(), fs);
  glLinkProgram(p.id());
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(p.id(), GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetProgramiv(p.id(), GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(std::max(length, 1));
    glGetProgramInfoLog(p.id(), length, nullptr, log.data());
    throw Error(ErrorKind::kInternal, name + ": link failed: " + std::string(log.data()));
  }
  return p;
}

Texture::Texture(int width_px, int height_px, GLenum internal_format)
    : width_(width_px), height_(height_px), format_(internal_format) {
  // GL refuses a larger texture with no more than an error flag, and every later pass would read nothing: say so.
  GLint max_side = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_side);
  if (width_px < 1 || height_px < 1 || width_px > max_side || height_px > max_side)
    throw Error(ErrorKind::kInput, "an image of " + std::to_string(width_px) + " x " + std::to_string(height_px) +
                                       " px does not fit this GL's textures (1 to " + std::to_string(max_side) +
                                       " px a side); use the CPU back end (--backend cpu)");
  GLuint id = 0;
  glGenTextures(1, &id);
  name_ = GlName(id, [](GLuint i) { glDeleteTextures(1, &i); });
  glBindTexture(GL_TEXTURE_2D, id);
  glTexImage2D(GL_TEXTURE_2D, 0, internal_format, width_px, height_px, 0, GL_RGBA, GL_FLOAT, nullptr);
  // Blur passes fetch texels exactly (texelFetch or pixel-centre coordinates): no filtering, clamp at borders.
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

Texture Texture::FromSrgbImage(const cv::Mat& image) {
  Texture t(image.cols, image.rows, GL_SRGB8_ALPHA8);
  t.UploadSrgb(image);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  // Longitude wraps around a sphere; latitude and card edges clamp.
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return t;
}

void Texture::UploadSrgb(const cv::Mat& image, bool mipmaps) {
  CV_Assert(image.depth() == CV_8U && (image.channels() == 3 || image.channels() == 4 || image.channels() == 1));
  CV_Assert(image.cols == width_ && image.rows == height_ && format_ == GL_SRGB8_ALPHA8);
  glBindTexture(GL_TEXTURE_2D, name_.id());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (image.channels() != 1 && image.isContinuous()) {
    // BGR(A) as it is: the driver swizzles while it copies, no converted copy made on the CPU (a video's every frame).
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, image.cols, image.rows, image.channels() == 3 ? GL_BGR : GL_BGRA,
                    GL_UNSIGNED_BYTE, image.data);
  } else {
    cv::Mat rgba;
    const int code = image.channels() == 1 ? cv::COLOR_GRAY2RGBA
                     : image.channels() == 3 ? cv::COLOR_BGR2RGBA : cv::COLOR_BGRA2RGBA;
    cv::cvtColor(image, rgba, code);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, rgba.cols, rgba.rows, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
  }
  if (mipmaps) glGenerateMipmap(GL_TEXTURE_2D);
}

void Texture::Upload(const cv::Mat& rgba) {
  CV_Assert(rgba.cols == width_ && rgba.rows == height_ && rgba.channels() == 4);
  CV_Assert(rgba.depth() == CV_32F || rgba.depth() == CV_8U);
  const cv::Mat data = rgba.isContinuous() ? rgba : rgba.clone();
  glBindTexture(GL_TEXTURE_2D, name_.id());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width_, height_, GL_RGBA,
                  rgba.depth() == CV_32F ? GL_FLOAT : GL_UNSIGNED_BYTE, data.data);
}

cv::Mat Texture::Download() const {
  cv::Mat out(height_, width_, CV_32FC4);
  glBindTexture(GL_TEXTURE_2D, name_.id());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, out.data);
  return out;
}

void Texture::Bind(int unit) const {
  glActiveTexture(GL_TEXTURE0 + unit);
  glBindTexture(GL_TEXTURE_2D, name_.id());
}

void Texture::BindImageForReading(int unit) const {
  if (format_ != GL_RGBA32F)
    throw Error(ErrorKind::kInternal, "an image read as rgba32f must be a GL_RGBA32F texture");
  glBindImageTexture(GLuint(unit), name_.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
}

Framebuffer::Framebuffer(const Texture& color, bool with_depth, const Texture* second_color)
    : width_(color.width_px()), height_(color.height_px()) {
  GLuint id = 0;
  glGenFramebuffers(1, &id);
  name_ = GlName(id, [](GLuint i) { glDeleteFramebuffers(1, &i); });
  glBindFramebuffer(GL_FRAMEBUFFER, id);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color.id(), 0);
  if (second_color) {
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, second_color->id(), 0);
    const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(2, buffers);
  }
  if (with_depth) {
    GLuint rb = 0;
    glGenRenderbuffers(1, &rb);
    depth_ = GlName(rb, [](GLuint i) { glDeleteRenderbuffers(1, &i); });
    glBindRenderbuffer(GL_RENDERBUFFER, rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width_, height_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, rb);
  }
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw Error(ErrorKind::kInternal, "GL: framebuffer incomplete, status " + std::to_string(status));
}

void Framebuffer::Bind() const {
  glBindFramebuffer(GL_FRAMEBUFFER, name_.id());
  glViewport(0, 0, width_, height_);
}

void GrowingTarget::Reserve(int w, int h) {
  if (Holds(w, h)) return;
  const int grown_w = std::max(texture_ ? texture_->width_px() : 0, (w + 63) / 64 * 64);
  const int grown_h = std::max(texture_ ? texture_->height_px() : 0, (h + 63) / 64 * 64);
  framebuffer_.reset();
  texture_ = std::make_unique<Texture>(grown_w, grown_h, format_);
  framebuffer_ = std::make_unique<Framebuffer>(*texture_);
}

cv::Mat GrowingTarget::Download(int w, int h) const {
  CV_Assert(texture_ && w <= texture_->width_px() && h <= texture_->height_px());
  cv::Mat out(h, w, CV_32FC4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer_->id());
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, out.data);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  return out;
}

void GrowingTarget::Upload(const cv::Mat& rgba) {
  CV_Assert(rgba.type() == CV_32FC4);
  Reserve(rgba.cols, rgba.rows);
  const cv::Mat data = rgba.isContinuous() ? rgba : rgba.clone();
  glBindTexture(GL_TEXTURE_2D, texture_->id());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, rgba.cols, rgba.rows, GL_RGBA, GL_FLOAT, data.data);
}

FullscreenPass::FullscreenPass() {
  GLuint id = 0;
  glGenVertexArrays(1, &id);
  vao_ = GlName(id, [](GLuint i) { glDeleteVertexArrays(1, &i); });
}

void FullscreenPass::Draw() const {
  glBindVertexArray(vao_.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

}  // namespace blurcue::render
