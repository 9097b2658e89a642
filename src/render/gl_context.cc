#include "render/gl_context.h"

#include <chrono>
#include <cstdio>

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "core/error.h"

namespace blurcue::render {
namespace {

// The GL every context asks for: 4.2 core, the first with the image loads the blur shaders read their texels by.
constexpr int kGlMajor = 4, kGlMinor = 2;
const std::string kGlName = "GL " + std::to_string(kGlMajor) + "." + std::to_string(kGlMinor) + " core";

std::string Hex(int v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%04x", v);
  return b;
}

class EglContext final : public GlContext {
 public:
  EglContext() {
    // The surfaceless platform needs no X server, no GBM device and no config: exactly what batch jobs want.
    auto get_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!get_display) throw Error(ErrorKind::kInternal, "EGL: eglGetPlatformDisplayEXT is missing");
    display_ = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLint major = 0, minor = 0;
    if (display_ == EGL_NO_DISPLAY || !eglInitialize(display_, &major, &minor))
      throw Error(ErrorKind::kInternal, "EGL: cannot initialise the surfaceless display, error " + Hex(eglGetError()) +
                                            " (is Mesa's libegl1 installed?)");
    eglBindAPI(EGL_OPENGL_API);
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, kGlMajor, EGL_CONTEXT_MINOR_VERSION, kGlMinor,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    context_ = eglCreateContext(display_, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
    if (context_ == EGL_NO_CONTEXT) {
      const int err = eglGetError();
      eglTerminate(display_);
      throw Error(ErrorKind::kInternal, "EGL: cannot create a " + kGlName + " context, error " + Hex(err));
    }
    MakeCurrent();
  }
  ~EglContext() override {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    eglTerminate(display_);
  }
  void MakeCurrent() override {
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
      throw Error(ErrorKind::kInternal, "EGL: eglMakeCurrent failed, error " + Hex(eglGetError()));
  }
  void SwapBuffers() override { glFinish(); }

 private:
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
};

std::string& LastGlfwError() {
  static std::string text;
  return text;
}

class GlfwContext final : public GlContext {
 public:
  explicit GlfwContext(const WindowOptions& o) {
    // GLFW's own words go into the one-line error rather than onto stderr.
    glfwSetErrorCallback([](int, const char* text) { LastGlfwError() = text ? text : ""; });
    // No display to open a window on is the station's set-up, not a bug: a usage error like a bad option.
    if (!glfwInit())
      throw Error(ErrorKind::kUsage, "GLFW: cannot open a window: " + LastGlfwError() +
                                            " (a window needs a display: set DISPLAY, or run under xvfb-run)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, kGlMajor);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, kGlMinor);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    GLFWmonitor* monitor = nullptr;
    if (o.fullscreen) {
      int count = 0;
      GLFWmonitor** monitors = glfwGetMonitors(&count);
      if (o.monitor < 0 || o.monitor >= count) {
        glfwTerminate();
        throw Error(ErrorKind::kInput, "display monitor " + std::to_string(o.monitor) + " does not exist (" +
                                           std::to_string(count) + " connected)");
      }
      monitor = monitors[o.monitor];
    }
    window_ = glfwCreateWindow(o.width_px, o.height_px, o.title.c_str(), monitor, nullptr);
    if (!window_) {
      glfwTerminate();
      throw Error(ErrorKind::kInternal, "GLFW: cannot open a " + kGlName + " window: " + LastGlfwError());
    }
    MakeCurrent();
    glfwSwapInterval(o.vsync ? 1 : 0);
    const GLFWvidmode* mode = glfwGetVideoMode(monitor ? monitor : glfwGetPrimaryMonitor());
    refresh_hz_ = mode ? mode->refreshRate : 0;
    glfwSetWindowUserPointer(window_, this);
    glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int, int action, int) {
      if (action != GLFW_PRESS) return;  // presses only: a held key does not repeat an answer
      auto* self = static_cast<GlfwContext*>(glfwGetWindowUserPointer(w));
      const std::string name = KeyName(key);
      if (!name.empty()) self->events_.push_back({name, glfwGetTime()});
    });
    glfwSetMouseButtonCallback(window_, [](GLFWwindow* w, int button, int action, int) {
      if (action != GLFW_PRESS) return;
      auto* self = static_cast<GlfwContext*>(glfwGetWindowUserPointer(w));
      if (button == GLFW_MOUSE_BUTTON_LEFT) self->events_.push_back({"MouseLeft", glfwGetTime()});
      if (button == GLFW_MOUSE_BUTTON_RIGHT) self->events_.push_back({"MouseRight", glfwGetTime()});
    });
    glfwSetScrollCallback(window_, [](GLFWwindow* w, double, double dy) {
      auto* self = static_cast<GlfwContext*>(glfwGetWindowUserPointer(w));
      if (dy != 0) self->events_.push_back({dy > 0 ? "WheelUp" : "WheelDown", glfwGetTime()});
    });
  }
  ~GlfwContext() override {
    glfwDestroyWindow(window_);
    glfwTerminate();
  }
  void MakeCurrent() override { glfwMakeContextCurrent(window_); }
  void SwapBuffers() override {
    glfwSwapBuffers(window_);
    glfwPollEvents();
  }
  bool ShouldClose() const override { return glfwWindowShouldClose(window_); }
  std::vector<InputEvent> TakeEvents() override {
    glfwPollEvents();
    std::vector<InputEvent> out;
    out.swap(events_);
    return out;
  }
  double Now() const override { return glfwGetTime(); }
  void SetTitle(const std::string& title) override { glfwSetWindowTitle(window_, title.c_str()); }
  double RefreshHz() const override { return refresh_hz_; }
  int width_px() const override {
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    return w;
  }
  int height_px() const override {
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    return h;
  }

 private:
  // The protocol's name of a GLFW key ("" for keys it has no name for).
  static std::string KeyName(int key) {
    switch (key) {
      case GLFW_KEY_LEFT: return "Left";
      case GLFW_KEY_RIGHT: return "Right";
      case GLFW_KEY_UP: return "Up";
      case GLFW_KEY_DOWN: return "Down";
      case GLFW_KEY_SPACE: return "Space";
      case GLFW_KEY_ENTER: case GLFW_KEY_KP_ENTER: return "Return";
      case GLFW_KEY_TAB: return "Tab";
      case GLFW_KEY_BACKSPACE: return "Backspace";
      case GLFW_KEY_ESCAPE: return "Escape";
      default: break;
    }
    if (key >= GLFW_KEY_A && key <= GLFW_KEY_Z) return std::string(1, char('A' + key - GLFW_KEY_A));
    if (key >= GLFW_KEY_0 && key <= GLFW_KEY_9) return std::string(1, char('0' + key - GLFW_KEY_0));
    if (key >= GLFW_KEY_F1 && key <= GLFW_KEY_F12) return "F" + std::to_string(key - GLFW_KEY_F1 + 1);
    if (key >= GLFW_KEY_KP_0 && key <= GLFW_KEY_KP_9) return "KP_" + std::to_string(key - GLFW_KEY_KP_0);
    return "";
  }

  GLFWwindow* window_ = nullptr;
  std::vector<InputEvent> events_;
  double refresh_hz_ = 0;
};

}  // namespace

std::unique_ptr<GlContext> GlContext::CreateOffscreen() { return std::make_unique<EglContext>(); }
std::unique_ptr<GlContext> GlContext::CreateWindow(const WindowOptions& options) {
  return std::make_unique<GlfwContext>(options);
}

double GlContext::Now() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string GlContext::Describe() const {
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  return std::string(renderer ? renderer : "?") + " | " + (version ? version : "?");
}

}  // namespace blurcue::render
