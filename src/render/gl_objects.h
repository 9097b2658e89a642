#pragma once
// Move-only RAII handles for the GL objects blurcue uses (after Magnum's GL layer): no copies, destroyed with the
// context current, errors that name the shader file and carry the driver's log.
#include <filesystem>
#include <memory>
#include <string>
#include <utility>

#include <epoxy/gl.h>
#include <opencv2/core.hpp>

namespace blurcue::render {

// Where shaders live: $BLURCUE_SHADER_DIR, else the source tree's shaders/.
std::filesystem::path ShaderDir();

class GlName {
 public:
  using Deleter = void (*)(GLuint);
  GlName() = default;
  GlName(GLuint id, Deleter deleter) : id_(id), deleter_(deleter) {}
  GlName(GlName&& o) noexcept : id_(std::exchange(o.id_, 0)), deleter_(o.deleter_) {}
  GlName& operator=(GlName&& o) noexcept {
    if (this != &o) {
      Reset();
      id_ = std::exchange(o.id_, 0);
      deleter_ = o.deleter_;
    }
    return *this;
  }
  GlName(const GlName&) = delete;
  GlName& operator=(const GlName&) = delete;
  ~GlName() { Reset(); }
  GLuint id() const { return id_; }

 private:
  void Reset() {
    if (id_ && deleter_) deleter_(id_);
    id_ = 0;
  }
  GLuint id_ = 0;
  Deleter deleter_ = nullptr;
};

class Program {
 public:
  // Compiles and links; throws Error(kInternal) "FILE: compile failed: <driver log>" on failure.
  static Program FromFiles(const std::filesystem::path& vertex, const std::filesystem::path& fragment);
  static Program FromSource(const std::string& vertex, const std::string& fragment, const std::string& name);
  void Use() const { glUseProgram(name_.id()); }
  // The uniform's location, looked up in GL: once, when a typed shader (shaders.h) is made. Throws Error(kInternal)
  // naming the program's files when the program has no such active uniform.
  GLint Uniform(const char* name) const;
  GLuint id() const { return name_.id(); }

 private:
  GlName name_;
  std::string files_;  // what it was made from, for errors
};

class Texture {
 public:
  // An empty RGBA texture; internal_format e.g. GL_RGBA32F (linear, premultiplied) or GL_RGBA8.
  Texture(int width_px, int height_px, GLenum internal_format = GL_RGBA32F);
  // An sRGB texture (sampling decodes to linear) from an 8-bit BGR/BGRA image, mipmapped and trilinear, for
  // object surfaces seen smaller than their texture.
  static Texture FromSrgbImage(const cv::Mat& bgr_or_bgra);
  // Replaces an sRGB texture's image (8-bit BGR/BGRA/grey of its size) and, with `mipmaps`, its mipmaps (a texture
  // that is only blitted, as a video frame's photo, needs none).
  void UploadSrgb(const cv::Mat& bgr_or_bgra, bool mipmaps = true);
  // Uploads CV_32FC4 (or CV_8UC4) rows top-down; row 0 of the Mat is texture row 0. Everything in blurcue keeps
  // that convention (image row = texture row = gl_FragCoord.y), so nothing is ever flipped.
  void Upload(const cv::Mat& rgba);
  // Reads the whole texture back as CV_32FC4.
  cv::Mat Download() const;
  void Bind(int unit) const;
  // Binds level 0 to image unit `unit` for imageLoad (a GL_RGBA32F texture only; throws Error(kInternal) else).
  void BindImageForReading(int unit) const;
  int width_px() const { return width_; }
  int height_px() const { return height_; }
  GLuint id() const { return name_.id(); }

 private:
  GlName name_;
  int width_ = 0, height_ = 0;
  GLenum format_ = GL_RGBA32F;
};

class Framebuffer {
 public:
  // Renders into `color` (which must outlive this framebuffer), with a depth buffer when `with_depth`, and into
  // `second_color` as draw buffer 1 when given.
  explicit Framebuffer(const Texture& color, bool with_depth = false, const Texture* second_color = nullptr);
  void Bind() const;
  GLuint id() const { return name_.id(); }

 private:
  GlName name_, depth_;
  int width_ = 0, height_ = 0;
};

// A colour texture with its framebuffer, made once and grown (to multiples of 64 px, never shrunk) when a larger
// region is asked for: a frame loop draws into its bottom-left w x h (image row = texture row) and, once the target
// has the size the session needs, allocates nothing.
class GrowingTarget {
 public:
  explicit GrowingTarget(GLenum internal_format = GL_RGBA32F) : format_(internal_format) {}
  // Makes room for w x h: a new texture and framebuffer only when the present ones are smaller (what the old one
  // held is then gone: reserve before drawing).
  void Reserve(int width_px, int height_px);
  // Whether w x h fits without growing.
  bool Holds(int width_px, int height_px) const {
    return texture_ && width_px <= texture_->width_px() && height_px <= texture_->height_px();
  }
  const Texture& texture() const { return *texture_; }
  GLuint framebuffer() const { return framebuffer_->id(); }
  // The bottom-left w x h read back as CV_32FC4, and written from one.
  cv::Mat Download(int width_px, int height_px) const;
  void Upload(const cv::Mat& rgba);

 private:
  GLenum format_;
  std::unique_ptr<Texture> texture_;
  std::unique_ptr<Framebuffer> framebuffer_;
};

// A full-screen triangle for image passes (vertex shader derives positions from gl_VertexID).
class FullscreenPass {
 public:
  FullscreenPass();
  void Draw() const;

 private:
  GlName vao_;
};

static_assert(!std::is_copy_constructible_v<Program>);
static_assert(!std::is_copy_constructible_v<Texture>);
static_assert(!std::is_copy_constructible_v<Framebuffer>);
static_assert(std::is_nothrow_move_constructible_v<Program>);

}  // namespace blurcue::render
