#include "render/frame_compositor.h"

#include <algorithm>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/image.h"
#include "render/blur.h"
#include "render/gl_objects.h"
#include "render/shaders.h"

namespace blurcue::render {

using scene::BlurredObject;
using scene::Footprint;
using scene::FrameView;

struct FrameCompositor::Impl {
  Camera camera;
  FrameView view;
  int width = 0, height = 0;
  SceneRenderer renderer;
  GlBlur blur;
  CompositeShader composite;
  GrowingTarget uploaded;  // a depth-varying layer blurred on the CPU, back on the GPU (made once and grown)
  FullscreenPass pass;
  Texture photo, base, frame;  // the photo resampled; the frame without objects (photo placed, grey around); the frame
  Framebuffer photo_fb, base_fb, frame_fb;
  // Where the last frame drew: only those rectangles need the base back (the whole frame before the first).
  std::vector<cv::Rect> dirty;

  Impl(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec, const cv::Mat& photo_srgb,
       const FrameView& view)
      : camera(camera),
        view(view),
        width(view.width_px),
        height(view.height_px),
        renderer(view.CameraOf(camera), rvec, tvec),
        photo(Texture::FromSrgbImage(ResampleSrgb8(photo_srgb, {view.photo_width_px, view.photo_height_px}))),
        base(view.width_px, view.height_px, GL_SRGB8_ALPHA8),
        frame(view.width_px, view.height_px, GL_SRGB8_ALPHA8),
        photo_fb(photo),
        base_fb(base),
        frame_fb(frame) {
    Place(view.x_px, view.y_px);
  }

  // The base frame: grey (sRGB 128, as the text screens' field), the photo at (x, y), cut by the frame's edges.
  // True when SetFrame uploaded the photo straight into `base` (it fills the frame), leaving `photo` behind.
  bool photo_in_base = false;

  // SetFrame(compose_once) uploaded the photo straight into `frame`: frame_fresh until it is composed on, and the base
  // holds no photo until the next SetFrame.
  bool frame_fresh = false, base_stale = false;

  void Place(int x, int y) {
    if (base_stale) throw Error(ErrorKind::kInternal, "FrameCompositor: Place after SetFrame(compose_once)");
    if (photo_in_base) {  // base is the photo: the photo's texture gets it back before a crop of it is placed
      glBindFramebuffer(GL_READ_FRAMEBUFFER, base_fb.id());
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, photo_fb.id());
      glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
      photo_in_base = false;
    }
    view.x_px = x, view.y_px = y;
    renderer.SetCamera(view.CameraOf(camera));
    base_fb.Bind();
    glClearColor(0.5f, 0.5f, 0.5f, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    const cv::Rect to = cv::Rect(x, y, view.photo_width_px, view.photo_height_px) & cv::Rect(0, 0, width, height);
    if (!to.empty()) {
      glBindFramebuffer(GL_READ_FRAMEBUFFER, photo_fb.id());
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, base_fb.id());
      glBlitFramebuffer(to.x - x, to.y - y, to.x - x + to.width, to.y - y + to.height, to.x, to.y, to.x + to.width,
                        to.y + to.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    dirty.assign(1, cv::Rect(0, 0, width, height));
  }

  void StartFrame() {
    // The base's encoded bytes are copied as they are (both sRGB): no decode/encode round trip. One blit of the
    // rectangle around all of the last frame's layers: llvmpipe pays per blit more than per pixel copied.
    if (frame_fresh) {  // the bare photo was uploaded into the frame itself (compose_once)
      frame_fresh = false;
      return;
    }
    if (base_stale) throw Error(ErrorKind::kInternal, "FrameCompositor: Compose twice after SetFrame(compose_once)");
    if (dirty.empty()) return;
    cv::Rect r = dirty.front();
    for (const cv::Rect& d : dirty) r |= d;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, base_fb.id());
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, frame_fb.id());
    glBlitFramebuffer(r.x, r.y, r.x + r.width, r.y + r.height, r.x, r.y, r.x + r.width, r.y + r.height,
                      GL_COLOR_BUFFER_BIT, GL_NEAREST);
    dirty.clear();
  }

  // Each object's layer, grown by the kernel's margin (the region approach) or by the whole frame (the thesis's),
  // laid side by side in the atlas, then drawn, blurred and blended stage by stage: llvmpipe pays per pass, so a frame
  // of eight objects costs few more passes than a frame of one. Blended in the objects' order.
  struct Placed {
    const BlurredObject* object;
    cv::Rect roi;  // where it lands in the frame; empty: composed on its own (the per-pixel plan)
    cv::Point at;  // its layer's place in the atlas
  };
  std::vector<Placed> placed;              // this frame's layers (kept: a frame loop allocates nothing)
  std::vector<GlBlur::Region> regions;     // and their blurs
  GrowingTarget atlas;

  void Compose(const std::vector<BlurredObject>& objects, bool whole_frame) {
    StartFrame();
    const double scale = view.Scale(camera);
    placed.clear(), regions.clear();
    int x = 0, y = 0, row = 0;
    for (const BlurredObject& o : objects) {
      if (o.r_of_depth_px && !whole_frame) {
        placed.push_back({&o, {}, {}});
        continue;
      }
      const Psf psf = PsfOf(o, scale);  // at screen resolution
      const int margin = whole_frame ? std::max(width, height) : KernelMarginPx(psf) + 1;
      const cv::Rect roi = renderer.LayerRoi(o.object, margin);
      if (roi.empty()) continue;
      if (x > 0 && x + roi.width > width) x = 0, y += row, row = 0;  // rows as wide as the frame
      placed.push_back({&o, roi, {x, y}});
      regions.push_back({cv::Rect(x, y, roi.width, roi.height), psf});
      x += roi.width, row = std::max(row, roi.height);
    }
    if (regions.empty() && placed.empty()) return;
    if (!regions.empty()) atlas.Reserve(width, y + row);  // grown before the first layer: growing loses the texture's content
    for (const Placed& p : placed)
      if (!p.roi.empty()) renderer.DrawLayerAt(p.object->object, p.roi, atlas, nullptr, p.at);
    blur.BlurRegions(atlas, regions);
    for (const Placed& p : placed) {
      if (p.roi.empty())
        ComposeVarying(*p.object, scale);
      else
        Blend(atlas.texture(), p.roi, p.at);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }

  // The per-pixel plan: the layer and its depth read back, each pixel blurred by the radius of its own depth on the
  // CPU (levels 0.5 px apart, each through the CPU blur - the GL one would make a texture and a framebuffer per level
  // and frame for a layer this small), and blended back. Only objects whose depth span asks for it pay this.
  void ComposeVarying(const BlurredObject& o, double scale) {
    const Footprint f = renderer.Measure(o.object);
    auto r_screen = [&](double z) { return std::max(0.0, o.r_of_depth_px(z) * scale); };
    Psf widest = PsfOf(o, scale);
    widest.r_px = std::max({widest.r_px, r_screen(f.z_min_mm), r_screen(f.z_max_mm)});
    Layer layer = renderer.Draw(o.object, KernelMarginPx(widest) + 1);
    if (layer.bgra.empty()) return;
    BlurLayerVarying(layer, widest, r_screen, nullptr);
    cv::Mat rgba;
    cv::cvtColor(layer.bgra, rgba, cv::COLOR_BGRA2RGBA);
    uploaded.Upload(rgba);
    Blend(uploaded.texture(), layer.roi, cv::Point(0, 0));
  }

  // Blends a layer (linear, premultiplied; its top-left pixel at texel `at` of `layer`) over the frame at roi. The
  // frame stays bound: the next layer's blend goes into the same pass.
  void Blend(const Texture& layer, const cv::Rect& roi, cv::Point at) {
    dirty.push_back(roi);
    frame_fb.Bind();
    glEnable(GL_FRAMEBUFFER_SRGB);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glEnable(GL_SCISSOR_TEST);
    glScissor(roi.x, roi.y, roi.width, roi.height);
    composite.Use().SetOrigin(roi.x - at.x, roi.y - at.y);
    layer.Bind(0);
    pass.Draw();
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_FRAMEBUFFER_SRGB);
  }
};

FrameCompositor::FrameCompositor(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec,
                                 const cv::Mat& background, std::optional<FrameView> view)
    : impl_(std::make_unique<Impl>(camera, rvec, tvec, background,
                                   view ? *view : FrameView::Identity(camera.image_width_px, camera.image_height_px))) {
  CV_Assert(background.cols == camera.image_width_px && background.rows == camera.image_height_px);
}

void FrameCompositor::SetFrame(const cv::Vec3d& rvec, const cv::Vec3d& tvec, const cv::Mat& background,
                               bool compose_once) {
  Impl& m = *impl_;
  const cv::Size scaled(m.view.photo_width_px, m.view.photo_height_px);
  CV_Assert(background.size() == scaled ||
            (background.cols == m.camera.image_width_px && background.rows == m.camera.image_height_px));
  m.renderer.SetPose(rvec, tvec);
  const bool fills = m.view.x_px == 0 && m.view.y_px == 0 && scaled == cv::Size(m.width, m.height) &&
                     background.size() == scaled;
  if (fills && compose_once) {
    // Straight into the frame the objects are blended over: the base-to-frame copy StartFrame makes is not needed
    // (the photo is composed on once), and the base is left stale.
    m.frame.UploadSrgb(background, false);
    m.frame_fresh = m.base_stale = true;
    m.photo_in_base = false;
    m.dirty.clear();
    return;
  }
  m.base_stale = m.frame_fresh = false;
  if (fills) {
    // The photo fills the frame as it is (a live view, ar): uploaded straight into the base frame, which saves a
    // clear and a whole-frame blit a frame (llvmpipe pays for each).
    m.base.UploadSrgb(background, false);
    m.photo_in_base = true;
    m.dirty.assign(1, cv::Rect(0, 0, m.width, m.height));
    return;
  }
  // The photo is only blitted (level 0, GL_NEAREST): its mipmaps, which llvmpipe makes on the CPU, are not made.
  m.photo.UploadSrgb(background.size() == scaled ? background : ResampleSrgb8(background, scaled), false);
  m.Place(m.view.x_px, m.view.y_px);  // the base frame from the new photo; the whole frame dirty
}

cv::Mat FrameCompositor::ScaledPhoto(const cv::Mat& background) const {
  return ResampleSrgb8(background, {impl_->view.photo_width_px, impl_->view.photo_height_px});
}

void FrameCompositor::Place(int x_px, int y_px) {
  if (x_px != impl_->view.x_px || y_px != impl_->view.y_px) impl_->Place(x_px, y_px);
}

const FrameView& FrameCompositor::view() const { return impl_->view; }

FrameCompositor::~FrameCompositor() = default;

SceneRenderer& FrameCompositor::renderer() { return impl_->renderer; }

void FrameCompositor::Compose(const std::vector<BlurredObject>& objects) { impl_->Compose(objects, false); }

void FrameCompositor::ComposeWholeFrame(const std::vector<BlurredObject>& objects) { impl_->Compose(objects, true); }

void FrameCompositor::Finish() { glFinish(); }

cv::Mat FrameCompositor::Read() {
  cv::Mat rgba(impl_->height, impl_->width, CV_8UC4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, impl_->frame_fb.id());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, impl_->width, impl_->height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  cv::Mat bgr;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  return bgr;
}

namespace {
// Blits a framebuffer of src_w x src_h (image rows, top first) to the window's, letterboxed on grey; a window's
// rows count from the bottom, so the blit flips.
void BlitToWindow(GLuint read_fb, int src_w, int src_h, int width_px, int height_px) {
  const double scale = std::min(double(width_px) / src_w, double(height_px) / src_h);
  const int w = int(src_w * scale), h = int(src_h * scale);  // scene::FitScale: w / src_w
  const int x0 = (width_px - w) / 2, y0 = (height_px - h) / 2;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, read_fb);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  // One to one into a window of the frame's size (a live view): no letterbox to clear, and the nearest texel is the
  // one a linear filter would read at every pixel's centre - the same pixels, for less of llvmpipe's time.
  const bool one_to_one = w == src_w && h == src_h;
  if (!(one_to_one && w == width_px && h == height_px)) {
    glClearColor(0.5f, 0.5f, 0.5f, 1);
    glClear(GL_COLOR_BUFFER_BIT);
  }
  glBlitFramebuffer(0, 0, src_w, src_h, x0, y0 + h, x0 + w, y0, GL_COLOR_BUFFER_BIT, one_to_one ? GL_NEAREST : GL_LINEAR);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
}
}  // namespace

cv::Mat ReadWindow(int width_px, int height_px) {
  cv::Mat rgba(height_px, width_px, CV_8UC4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_px, height_px, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
  cv::Mat bgr;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  cv::flip(bgr, bgr, 0);  // a window's rows count from the bottom
  return bgr;
}

void FrameCompositor::Present(int width_px, int height_px) {
  BlitToWindow(impl_->frame_fb.id(), impl_->width, impl_->height, width_px, height_px);
}

struct WindowImage::Impl {
  Texture texture;
  Framebuffer fb{texture};
  explicit Impl(const cv::Mat& image) : texture(Texture::FromSrgbImage(image)) {}
};

WindowImage::WindowImage(const cv::Mat& image) : impl_(std::make_unique<Impl>(image)) {}
WindowImage::~WindowImage() = default;

void WindowImage::Present(int width_px, int height_px) const {
  BlitToWindow(impl_->fb.id(), impl_->texture.width_px(), impl_->texture.height_px(), width_px, height_px);
}

void WindowImage::Update(const cv::Mat& image) { impl_->texture.UploadSrgb(image); }

void WindowImage::PresentAt(int x_px, int y_px, int height_px) const {
  const int w = impl_->texture.width_px(), h = impl_->texture.height_px();
  const int y0 = height_px - y_px - h;  // GL counts rows from the bottom
  glBindFramebuffer(GL_READ_FRAMEBUFFER, impl_->fb.id());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glBlitFramebuffer(0, 0, w, h, x_px, y0 + h, x_px + w, y0, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
}

}  // namespace blurcue::render
