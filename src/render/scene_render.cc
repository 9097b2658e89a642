#include "render/scene_render.h"

#include <algorithm>
#include <utility>
#include <cmath>
#include <map>
#include <vector>

#include <glm/glm.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/typed.h"
#include "render/blur.h"
#include "render/gl_objects.h"
#include "render/shaders.h"

namespace blurcue::render {

using scene::AxesOf;
using scene::CardAxes;
using scene::Footprint;
using scene::FootprintOf;
using scene::SurfaceTexture;
using scene::VirtualObject;

namespace {

struct Vertex {
  float position[3];
  float uv[2];
};

cv::Matx33d SpinAboutX(double deg) {
  const double a = deg * M_PI / 180, c = std::cos(a), s = std::sin(a);
  return {1, 0, 0, 0, c, -s, 0, s, c};
}

// A mesh drawn with indices (a vertex shared by triangles is shaded once). A card is one; a ball is traced
// (shaders/ball.frag), not tessellated: llvmpipe shades vertices on the CPU, one thread, and a sphere fine enough
// for a 0.1 px silhouette was most of a ball's cost.
struct Mesh {
  std::vector<Vertex> vertices;
  std::vector<GLuint> indices;
};

// The unit card (side 1, centred, in z = 0); texture row 0 (the image's top) on the far side (+y).
Mesh UnitCard() {
  return {{{{-0.5f, 0.5f, 0}, {0, 0}}, {{0.5f, 0.5f, 0}, {1, 0}}, {{0.5f, -0.5f, 0}, {1, 1}}, {{-0.5f, -0.5f, 0}, {0, 1}}},
          {0, 1, 2, 0, 2, 3}};
}

// Object -> board frame: translate to the centre; a ball spun (rolling about x) and scaled by its radius, a card's
// unit square stretched along its axes.
glm::mat4 ModelMatrix(const VirtualObject& o) {
  cv::Matx33d m3;
  if (o.kind == VirtualObject::Kind::kBall) {
    m3 = SpinAboutX(o.spin_deg) * o.size_mm;
  } else {
    const CardAxes a = AxesOf(o);
    for (int r = 0; r < 3; ++r) m3(r, 0) = a.u[r], m3(r, 1) = a.v[r], m3(r, 2) = a.n[r];
  }
  glm::mat4 m(1.0f);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[c][r] = float(m3(r, c));
    m[3][r] = float(o.center_board_mm[r]);
  }
  return m;
}

// The inverse of an affine image map (ideal px -> image px) as a GLSL mat3 (column-major): image px -> ideal px.
glm::mat3 ImageToIdeal(const cv::Matx23d& a) {
  const double det = a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0);
  const double i00 = a(1, 1) / det, i01 = -a(0, 1) / det, i10 = -a(1, 0) / det, i11 = a(0, 0) / det;
  glm::mat3 m(1.0f);
  m[0][0] = float(i00), m[1][0] = float(i01), m[2][0] = float(-(i00 * a(0, 2) + i01 * a(1, 2)));
  m[0][1] = float(i10), m[1][1] = float(i11), m[2][1] = float(-(i10 * a(0, 2) + i11 * a(1, 2)));
  return m;
}

}  // namespace

struct SceneRenderer::Impl {
  Camera camera;
  cv::Vec3d rvec, tvec;
  cv::Matx33d rotation;
  ObjectShader shader;
  GrowingTarget color, depth;  // the resolved layers, made once and grown
  GlName vao, vbo, ebo;  // the unit card, indexed
  GLsizei card_indices = 0;
  BallShader ball_shader;
  FullscreenPass pass;  // a ball covers its layer with one triangle
  // Textures by their identity (SurfaceTexture::id): a moving ball re-uses its texture every frame.
  std::map<uint64_t, std::unique_ptr<Texture>> textures;

  const Texture& TextureFor(const SurfaceTexture& surface) {
    if (surface.empty()) throw Error(ErrorKind::kInternal, "an object without a texture was drawn");
    // A caller that made a new SurfaceTexture every frame would grow the cache without end: past 64 it starts over.
    if (textures.size() > 64 && !textures.count(surface.id())) textures.clear();
    std::unique_ptr<Texture>& slot = textures[surface.id()];
    if (!slot) slot = std::make_unique<Texture>(Texture::FromSrgbImage(surface.image()));
    return *slot;
  }

  // The multisample targets objects are drawn into: made once and grown (to multiples of 64 px) when a layer is
  // larger, never per frame; a layer of w x h uses their bottom-left w x h.
  GlName ms_fb, ms_color, ms_depth_value, ms_depth;
  int ms_w = 0, ms_h = 0;
  GLuint Targets(int w, int h) {
    if (w <= ms_w && h <= ms_h) return ms_fb.id();
    ms_w = std::max(ms_w, (w + 63) / 64 * 64), ms_h = std::max(ms_h, (h + 63) / 64 * 64);
    GLint max_samples = 1;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    // 4 samples: coverage in quarters is plenty under any blur, and llvmpipe pays per sample.
    const GLsizei samples = std::min<GLint>(4, max_samples);
    auto renderbuffer = [&](GLenum format) {
      GLuint id = 0;
      glGenRenderbuffers(1, &id);
      glBindRenderbuffer(GL_RENDERBUFFER, id);
      glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, ms_w, ms_h);
      return GlName(id, [](GLuint i) { glDeleteRenderbuffers(1, &i); });
    };
    ms_color = renderbuffer(GL_RGBA32F), ms_depth_value = renderbuffer(GL_RGBA32F);
    ms_depth = renderbuffer(GL_DEPTH_COMPONENT24);
    GLuint id = 0;
    glGenFramebuffers(1, &id);
    ms_fb = GlName(id, [](GLuint i) { glDeleteFramebuffers(1, &i); });
    glBindFramebuffer(GL_FRAMEBUFFER, id);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, ms_color.id());
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_RENDERBUFFER, ms_depth_value.id());
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, ms_depth.id());
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw Error(ErrorKind::kInternal, "GL: multisample framebuffer incomplete");
    return id;
  }
};

SceneRenderer::SceneRenderer(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec)
    : impl_(std::make_unique<Impl>()) {
  impl_->camera = camera;
  impl_->rvec = rvec;
  impl_->tvec = tvec;
  cv::Rodrigues(rvec, impl_->rotation);
  GLuint id = 0;
  glGenVertexArrays(1, &id);
  impl_->vao = GlName(id, [](GLuint i) { glDeleteVertexArrays(1, &i); });
  glGenBuffers(1, &id);
  impl_->vbo = GlName(id, [](GLuint i) { glDeleteBuffers(1, &i); });
  glGenBuffers(1, &id);
  impl_->ebo = GlName(id, [](GLuint i) { glDeleteBuffers(1, &i); });
  glBindVertexArray(impl_->vao.id());
  glBindBuffer(GL_ARRAY_BUFFER, impl_->vbo.id());
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, impl_->ebo.id());
  // The unit card, uploaded once: a frame only sets matrices.
  const Mesh mesh = UnitCard();
  impl_->card_indices = GLsizei(mesh.indices.size());
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.vertices.size() * sizeof(Vertex)), mesh.vertices.data(),
               GL_STATIC_DRAW);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh.indices.size() * sizeof(GLuint)), mesh.indices.data(),
               GL_STATIC_DRAW);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<void*>(offsetof(Vertex, position)));
  glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<void*>(offsetof(Vertex, uv)));
  for (int i = 0; i < 2; ++i) glEnableVertexAttribArray(i);
  glBindVertexArray(0);
}

SceneRenderer::~SceneRenderer() = default;

void SceneRenderer::SetPose(const cv::Vec3d& rvec, const cv::Vec3d& tvec) {
  impl_->rvec = rvec;
  impl_->tvec = tvec;
  cv::Rodrigues(rvec, impl_->rotation);
}

Footprint SceneRenderer::Measure(const VirtualObject& o) const {
  return FootprintOf(impl_->camera, impl_->rvec, impl_->tvec, o);
}

void SceneRenderer::SetCamera(const Camera& camera) { impl_->camera = camera; }

Layer SceneRenderer::Draw(const VirtualObject& o, int margin_px) {
  GpuLayer gpu = DrawToTexture(o, margin_px, /*depth_map=*/true);
  Layer layer;
  layer.roi = gpu.roi;
  if (!gpu.color) {
    layer.bgra = cv::Mat(0, 0, CV_32FC4);
    return layer;
  }
  cv::cvtColor(gpu.color->Download(gpu.roi.width, gpu.roi.height), layer.bgra, cv::COLOR_RGBA2BGRA);
  const cv::Mat depth = gpu.depth->Download(gpu.roi.width, gpu.roi.height);
  layer.depth_mm = cv::Mat(depth.size(), CV_32F);
  for (int y = 0; y < depth.rows; ++y)
    for (int x = 0; x < depth.cols; ++x) {
      const cv::Vec4f d = depth.at<cv::Vec4f>(y, x);
      layer.depth_mm.at<float>(y, x) = d[3] > 1e-3f ? d[0] / d[3] : 0.f;
    }
  return layer;
}

cv::Rect SceneRenderer::LayerRoi(const VirtualObject& o, int margin_px) const {
  const cv::Rect bounds = Measure(o).bounds;
  return cv::Rect(bounds.x - margin_px, bounds.y - margin_px, bounds.width + 2 * margin_px,
                  bounds.height + 2 * margin_px) &
         cv::Rect(0, 0, impl_->camera.image_width_px, impl_->camera.image_height_px);
}

GpuLayer SceneRenderer::DrawToTexture(const VirtualObject& o, int margin_px, bool depth_map) {
  GpuLayer layer;
  layer.roi = LayerRoi(o, margin_px);
  if (layer.roi.empty()) return layer;
  impl_->color.Reserve(layer.roi.width, layer.roi.height);
  layer.color = &impl_->color;
  if (depth_map) impl_->depth.Reserve(layer.roi.width, layer.roi.height), layer.depth = &impl_->depth;
  DrawLayerAt(o, layer.roi, *layer.color, layer.depth, cv::Point(0, 0));
  return layer;
}

void SceneRenderer::DrawLayerAt(const VirtualObject& o, const cv::Rect& roi, GrowingTarget& color,
                                GrowingTarget* depth, cv::Point at) {
  const Camera& cam = impl_->camera;
  const int w = roi.width, h = roi.height;
  const bool depth_map = depth != nullptr;
  // The targets may hold the frame's other layers (an atlas): growing them here would lose those without a word, so
  // the caller reserves the whole frame's room first.
  if (!color.Holds(at.x + w, at.y + h) || (depth && !depth->Holds(at.x + w, at.y + h)))
    throw Error(ErrorKind::kInternal, "a layer was drawn past its target's reserved room (reserve before drawing)");
  const auto k = cam.Intrinsics();
  // Under lens distortion the object is drawn through the distortion's local affine map at its centre
  // (scene::LocalImageMap: image px = A ideal px + t), as its blur is stretched (Psf::shape); the identity without.
  const cv::Matx23d a = scene::LocalImageMap(cam, impl_->rvec, impl_->tvec, o);
  // Camera (x, y, z) -> image px x z: rows m (x, y, z) with m = A [fx 0 cx; 0 fy cy] + t e_z (skew ignored, as
  // cv::projectPoints does).
  const cv::Matx23d m(a(0, 0) * k[0], a(0, 1) * k[4], a(0, 0) * k[2] + a(0, 1) * k[5] + a(0, 2),
                      a(1, 0) * k[0], a(1, 1) * k[4], a(1, 0) * k[2] + a(1, 1) * k[5] + a(1, 2));
  // Camera frame -> clip for this sub-window; framebuffer row r is image row roi.y + r (nothing is flipped).
  const double n = 1.0, far = 1e5;
  glm::mat4 projection(0.0f);  // column-major: projection[col][row]
  projection[0][0] = float(2 * m(0, 0) / w);
  projection[1][0] = float(2 * m(0, 1) / w);
  projection[0][1] = float(2 * m(1, 0) / h);
  projection[1][1] = float(2 * m(1, 1) / h);
  projection[2][0] = float(2 * (m(0, 2) + 0.5 - roi.x) / w - 1);
  projection[2][1] = float(2 * (m(1, 2) + 0.5 - roi.y) / h - 1);
  projection[2][2] = float((far + n) / (far - n));
  projection[3][2] = float(-2 * far * n / (far - n));
  projection[2][3] = 1.0f;
  glm::mat4 pose(1.0f);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) pose[c][r] = float(impl_->rotation(r, c));
    pose[3][r] = float(impl_->tvec[r]);
  }
  const glm::mat4 model_to_camera = pose * ModelMatrix(o);
  const glm::vec3 white_balance(float(o.white_balance[0]), float(o.white_balance[1]), float(o.white_balance[2]));
  impl_->TextureFor(o.texture).Bind(0);
  if (o.kind == VirtualObject::Kind::kBall) {
    // Traced straight into the layer (its pixels' coverage from 16 rays each, no multisample buffer): the sphere's
    // centre and the rotation back to its texture's frame (the spin); the depth layer in a second pass when asked.
    // Light from above the table and behind the camera: camera frame has y down.
    const glm::vec3 light = glm::normalize(glm::vec3(-0.3f, -1.0f, -0.6f));
    const float ambient = 0.45f;
    BallShader& shader = impl_->ball_shader;
    shader.Use()
        .SetCamera(glm::vec4(float(k[0]), float(k[4]), float(k[2]), float(k[5])),
                   glm::vec2(float(roi.x - at.x), float(roi.y - at.y)),  // framebuffer pixel -> image pixel
                   ImageToIdeal(a))
        .SetSphere(glm::vec3(model_to_camera[3]), float(o.size_mm), glm::inverse(glm::mat3(model_to_camera)))
        .SetLight(light, ambient)
        .SetColour(float(o.brightness), float(o.contrast), white_balance);
    for (GrowingTarget* target : {&color, depth}) {
      if (!target) continue;
      shader.SetWriteDepth(target == depth);
      glBindFramebuffer(GL_FRAMEBUFFER, target->framebuffer());
      glViewport(at.x, at.y, w, h);
      impl_->pass.Draw();
    }
    return;  // the target stays bound: the next layer into it joins the same pass
  }
  // A card is drawn multisampled (4x) and resolved, so its outline carries its pixel coverage like a camera's edges
  // do (an aliased outline is sharper than any optics and reads ~0.3 px too sharp under the calibration's
  // measurement). The targets are the renderer's own, made once; the scissor keeps the clear to this layer's part.
  const GLuint ms_id = impl_->Targets(w, h);
  glBindFramebuffer(GL_FRAMEBUFFER, ms_id);
  const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glDrawBuffers(depth_map ? 2 : 1, buffers);
  glViewport(0, 0, w, h);
  glEnable(GL_SCISSOR_TEST);
  glScissor(0, 0, w, h);
  glClearColor(0, 0, 0, 0);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  impl_->shader.Use()
      .SetModelToCamera(model_to_camera)  // one matrix made here, not per vertex
      .SetProjection(projection)
      .SetColour(float(o.brightness), float(o.contrast), white_balance);
  glBindVertexArray(impl_->vao.id());
  glDrawElements(GL_TRIANGLES, impl_->card_indices, GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_SCISSOR_TEST);
  // Resolve: averaging the samples gives premultiplied colour x coverage, and depth x coverage in .r with the
  // coverage in .a (the depth target writes alpha 1), so depth = r / a.
  for (int i = 0; i < (depth_map ? 2 : 1); ++i) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, ms_id);
    glReadBuffer(GL_COLOR_ATTACHMENT0 + i);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, (i == 0 ? &color : depth)->framebuffer());
    glBlitFramebuffer(0, 0, w, h, at.x, at.y, at.x + w, at.y + h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

int KernelMarginPx(const std::string& method, double r_px) {
  CheckBlurRadius(r_px);  // a NaN or huge radius would make the margin (an int) undefined
  if (r_px <= 0) return 0;
  return method == "disc" ? int(std::ceil(r_px + 0.5)) : GaussianTaps(r_px / 2);
}

int KernelMarginPx(const Psf& psf) { return PsfHalfWidth(psf); }

Psf PsfOf(const scene::BlurredObject& object, double scale) {
  Psf psf;
  psf.method = object.method;
  psf.r_px = object.r_px * scale;
  psf.floor_sigma_px = object.floor_sigma_px * scale;
  psf.motion_px = object.motion_px * scale;
  psf.shape = object.shape;  // the view's scale is the same along x and y: the shape is the photo's
  return psf;
}

void BlurLayer(Layer& layer, const std::string& method, double r_px, GlBlur* gl) {
  Psf psf;
  psf.method = method, psf.r_px = r_px;
  BlurLayer(layer, psf, gl);
}

void BlurLayer(Layer& layer, const Psf& psf, GlBlur* gl) {
  CheckPsf(psf);
  if ((psf.r_px <= 0 && psf.MotionLengthPx() <= 0) || layer.bgra.empty()) return;
  if (gl) {
    layer.bgra = gl->BlurImage(layer.bgra, psf);
  } else if (psf.General()) {
    cv::Mat out;
    cv::filter2D(layer.bgra, out, CV_32F, PsfKernel(psf), cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
    layer.bgra = out;
  } else {
    layer.bgra = psf.method == "disc" ? DiscBlurCpu(layer.bgra, psf.r_px) : GaussianBlurCpu(layer.bgra, psf.r_px);
  }
}

void BlurLayerVarying(Layer& layer, const std::string& method, const std::function<double(double)>& r_of_depth,
                      GlBlur* gl) {
  Psf psf;
  psf.method = method;
  BlurLayerVarying(layer, psf, r_of_depth, gl);
}

void BlurLayerVarying(Layer& layer, const Psf& psf, const std::function<double(double)>& r_of_depth, GlBlur* gl) {
  if (layer.bgra.empty()) return;
  CV_Assert(layer.depth_mm.size() == layer.bgra.size());
  // Radius per covered pixel; uncovered pixels take their nearest covered pixel's radius.
  const cv::Mat uncovered = layer.depth_mm <= 0;
  if (size_t(cv::countNonZero(uncovered)) == uncovered.total()) return;
  cv::Mat distance, labels;
  cv::distanceTransform(uncovered, distance, labels, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
  std::vector<float> r_of_label(1, 0.f);  // labels number the covered pixels in raster order from 1
  double r_lo = 1e300, r_hi = 0;
  for (int y = 0; y < layer.depth_mm.rows; ++y)
    for (int x = 0; x < layer.depth_mm.cols; ++x) {
      const float z = layer.depth_mm.at<float>(y, x);
      if (z <= 0) continue;
      const double r = std::max(0.0, r_of_depth(z));
      r_of_label.push_back(float(r));
      r_lo = std::min(r_lo, r), r_hi = std::max(r_hi, r);
    }
  cv::Mat r_map(layer.bgra.size(), CV_32F);
  for (int y = 0; y < r_map.rows; ++y)
    for (int x = 0; x < r_map.cols; ++x) r_map.at<float>(y, x) = r_of_label[labels.at<int>(y, x)];
  // Levels 0.5 px apart from r_lo to r_hi: finer than any participant tells apart (DESIGN.md).
  std::vector<double> levels;
  for (double r = r_lo; r < r_hi; r += 0.5) levels.push_back(r);
  levels.push_back(r_hi);
  std::vector<cv::Mat> blurred;
  for (double r : levels) {
    Layer copy{layer.roi, layer.bgra.clone(), {}};
    Psf level = psf;
    level.r_px = r;
    BlurLayer(copy, level, gl);
    blurred.push_back(copy.bgra);
  }
  for (int y = 0; y < r_map.rows; ++y)
    for (int x = 0; x < r_map.cols; ++x) {
      const double r = r_map.at<float>(y, x);
      size_t k = 0;
      while (k + 2 < levels.size() && levels[k + 1] < r) ++k;
      const size_t k1 = std::min(k + 1, levels.size() - 1);
      const double a = levels[k] * levels[k], b = levels[k1] * levels[k1];
      const double w = b > a ? std::clamp((b - r * r) / (b - a), 0.0, 1.0) : 1.0;  // mix variances exactly
      layer.bgra.at<cv::Vec4f>(y, x) =
          float(w) * blurred[k].at<cv::Vec4f>(y, x) + float(1 - w) * blurred[k1].at<cv::Vec4f>(y, x);
    }
}

void CompositeOver(cv::Mat& background, const Layer& layer) {
  CV_Assert(background.type() == CV_32FC3);
  if (layer.bgra.empty()) return;
  for (int y = 0; y < layer.roi.height; ++y) {
    cv::Vec3f* bg = background.ptr<cv::Vec3f>(layer.roi.y + y) + layer.roi.x;
    const cv::Vec4f* fg = layer.bgra.ptr<cv::Vec4f>(y);
    for (int x = 0; x < layer.roi.width; ++x) {
      const float keep = 1.0f - fg[x][3];
      bg[x] = cv::Vec3f(fg[x][0] + keep * bg[x][0], fg[x][1] + keep * bg[x][1], fg[x][2] + keep * bg[x][2]);
    }
  }
}

}  // namespace blurcue::render
