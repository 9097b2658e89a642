#pragma once
// An OpenGL 4.2 core context (the blur shaders' image loads need it), offscreen through EGL on Mesa's surfaceless
// platform (no display: batch rendering and every test) or in a GLFW window for participants. GL calls go through
// libepoxy.
#include <memory>
#include <string>
#include <vector>

namespace blurcue::render {

struct WindowOptions {
  int width_px = 1280, height_px = 720;
  bool fullscreen = false;
  int monitor = 0;      // which monitor when fullscreen
  bool vsync = true;
  std::string title = "blurcue";
};

// A key press, mouse click or wheel step in a window. `key` uses the protocol's key names ("Left", "Right", "Up",
// "Down", "Space", "Return", "Tab", "Backspace", "Escape", "A".."Z", "0".."9", "F1".."F12", "KP_0".."KP_9") and
// "MouseLeft", "MouseRight", "WheelUp", "WheelDown". time_s is the context's clock when the event was polled
// (GLFW 3.3 gives events no timestamp of their own: the resolution is one poll, i.e. one refresh).
struct InputEvent {
  std::string key;
  double time_s = 0;
};

class GlContext {
 public:
  // Throws Error(kInternal) with the EGL error code when no surfaceless GL 4.2 core context can be made.
  static std::unique_ptr<GlContext> CreateOffscreen();
  // Throws Error(kUsage) when GLFW finds no display to open a window on (run under one or Xvfb), Error(kInternal)
  // when it has one but cannot open the window there.
  static std::unique_ptr<GlContext> CreateWindow(const WindowOptions& options);

  virtual ~GlContext() = default;
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  virtual void MakeCurrent() = 0;
  // Window: present the back buffer (blocks to the refresh with vsync). Offscreen: glFinish.
  virtual void SwapBuffers() = 0;
  // Window: true once the user asked to close it. Offscreen: false.
  virtual bool ShouldClose() const { return false; }
  // Size of the default framebuffer in pixels (0 x 0 offscreen: render to framebuffers).
  virtual int width_px() const { return 0; }
  virtual int height_px() const { return 0; }
  // Window: sets its title (what is on screen; tests wait for it). Offscreen: nothing.
  virtual void SetTitle(const std::string&) {}
  // Events since the last call (window); always empty offscreen.
  virtual std::vector<InputEvent> TakeEvents() { return {}; }
  // Seconds on a monotonic clock (the window's glfwGetTime, steady_clock offscreen).
  virtual double Now() const;
  // Window: the monitor's refresh rate in Hz (0 when unknown). Offscreen: 0.
  virtual double RefreshHz() const { return 0; }
  // GL_RENDERER and GL_VERSION, for the session record.
  std::string Describe() const;

 protected:
  GlContext() = default;
};

}  // namespace blurcue::render
