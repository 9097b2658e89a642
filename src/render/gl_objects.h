#pragma once
// Move-only RAII handles for the GL objects blurcue uses (after Magnum's GL layer): no copies, destroyed with the
// context current, errors that name the shader file and carry the driver's log.
#include <filesystem>
#include <map>
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
  // -1 when the uniform is absent or optimised out (setting it is then a no-op, as in GL). Looked up in GL once per
  // name, then from the program's own table: a frame loop makes no glGetUniformLocation calls.
  GLint Uniform(const char* name) const {
    const auto it = uniforms_.find(name);
    if (it != uniforms_.end()) return it->second;
    return uniforms_.emplace(name, glGetUniformLocation(name_.id(), name)).first->second;
  }
  GLuint id() const { return name_.id(); }

 private:
  GlName name_;
  mutable std::map<std::string, GLint, std::less<>> uniforms_;
};

class Texture {
 public:
  // An empty RGBA texture; internal_format e.g. GL_RGBA32F (linear, premultiplied) or GL_RGBA8.
  Texture(int width_px, int height_px, GLenum internal_format = GL_RGBA32F);
  // An sRGB texture (sampling decodes to linear) from an 8-bit BGR/BGRA image, mipmapped and trilinear, for
  // object surfaces seen smaller than their texture.
  static Texture FromSrgbImage(const cv::Mat& bgr_or_bgra);
  // Uploads CV_32FC4 (or CV_8UC4) rows top-down; row 0 of the Mat is texture row 0. Everything in blurcue keeps
  // that convention (image row = texture row = gl_FragCoord.y), so nothing is ever flipped.
  void Upload(const cv::Mat& rgba);
  // Reads the whole texture back as CV_32FC4.
  cv::Mat Download() const;
  void Bind(int unit) const;
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
