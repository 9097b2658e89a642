#include "bench/render_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <cstdio>
#include <functional>
#include <sstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/clock.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/stats.h"
#include "core/image.h"
#include "optics/thin_lens.h"
#include "render/blur.h"
#include "render/frame_compositor.h"
#include "render/gl_context.h"
#include "render/gl_objects.h"
#include "scene/frame.h"
#include "scene/objects.h"
#include "scene/stimuli.h"
#include "synth/scene.h"

namespace blurcue::bench {
namespace {

using detail::Clock;
using detail::Ms;

// A frame-sized test image: a few bright shapes on a dark field, linear premultiplied, opaque.
cv::Mat TestFrame(int w, int h) {
  cv::Mat img(h, w, CV_32FC4, cv::Scalar(0.05, 0.05, 0.05, 1));
  for (int i = 0; i < 6; ++i) {
    const cv::Point c(w * (i + 1) / 7, h / 2 + ((i % 2) ? h / 6 : -h / 6));
    cv::circle(img, c, std::max(4, h / 12), cv::Scalar(0.8, 0.6, 0.3, 1), cv::FILLED);
    cv::rectangle(img, cv::Rect(c.x - h / 30, c.y + h / 10, h / 15, h / 40), cv::Scalar(0.9, 0.9, 0.9, 1), cv::FILLED);
  }
  // As a lens would deliver it: nearly band-limited (aliased drawn edges have no exact convolution to compare to).
  cv::GaussianBlur(img, img, cv::Size(0, 0), 0.7);
  return img;
}

// The exact reference: the image taken as band-limited samples and multiplied in the frequency domain by the
// continuous PSF's transfer function - exp(-2 pi^2 s^2 f^2) for the Gaussian of std s = r/2, the Airy-like
// 2 J1(2 pi R f) / (2 pi R f) for the disc of radius R = r - so it carries neither the shader's sampled kernel nor
// its coverage ramp.
cv::Mat ExactBlur(const cv::Mat& rgba, const std::string& method, double r) {
  if (method == "disc")
    return render::FilterInFrequency(rgba, [r](double f) {
      const double x = 2 * M_PI * r * f;
      return x < 1e-9 ? 1.0 : 2 * std::cyl_bessel_j(1.0, x) / x;
    });
  const double s = r / 2;
  return render::FilterInFrequency(rgba, [s](double f) { return std::exp(-2 * M_PI * M_PI * s * s * f * f); });
}

// Mean and max |a - b| in 8-bit levels after sRGB encoding (what a participant would see), first channel.
void Error8(const cv::Mat& a, const cv::Mat& b, double& mean, double& max) {
  cv::Mat ea, eb, ca, cb;
  cv::extractChannel(a, ca, 0);
  cv::extractChannel(b, cb, 0);
  ea = EncodeSrgb8(ca);
  eb = EncodeSrgb8(cb);
  cv::Mat diff;
  cv::absdiff(ea, eb, diff);
  mean = cv::mean(diff)[0];
  cv::minMaxLoc(diff, nullptr, &max);
}

using Say = std::function<void(const std::string&)>;

// Part 1 at one frame size: each method and radius through GL and the CPU, timed on the whole frame; accuracy on a
// crop (the right edge of the first disc and its surroundings, 192 px square or the frame) against the exact
// convolution.
void AddBlurRows(render::GlBlur& gl, const RenderBenchOptions& options, const std::vector<double>& radii,
                 const cv::Mat& frame, const Say& say, std::vector<RenderRow>& rows) {
  const cv::Size size = frame.size();
  const int repeats = options.quick ? 1 : 3;
  const int disc_radius = std::max(4, size.height / 12);
  const cv::Rect around(size.width / 7 + disc_radius - 96, size.height / 2 - size.height / 6 - 96, 192, 192);
  const cv::Mat crop = frame(around & cv::Rect(0, 0, size.width, size.height)).clone();
  for (const std::string method : {"gaussian", "disc"})
    for (double r : radii) {
      // Accuracy: the crop through each path against the exact convolution.
      const cv::Mat exact = ExactBlur(crop, method, r);
      const cv::Mat gl_crop = method == "disc" ? gl.Disc(crop, r) : gl.Gaussian(crop, r);
      const cv::Mat cpu_crop = method == "disc" ? render::DiscBlurCpu(crop, r) : render::GaussianBlurCpu(crop, r);
      for (const std::string backend : {"gl", "cpu"}) {
        RenderRow row{"blur", method, backend, r, size.width, size.height};
        // Compared away from the crop's border, where edge handling (clamp vs mirror) and not accuracy differs.
        const int m = int(std::ceil(2 * r)) + 2;
        const cv::Rect inner(m, m, crop.cols - 2 * m, crop.rows - 2 * m);
        Error8((backend == "gl" ? gl_crop : cpu_crop)(inner), exact(inner), row.mean_abs_error, row.max_abs_error);
        std::vector<double> times;
        // A GL disc of r = 16 over 4592 x 3056 takes many seconds: once is enough to place it on the chart.
        const int n = size.width > 2000 && backend == "gl" ? 1 : repeats;
        render::Texture texture(size.width, size.height);
        if (backend == "gl") texture.Upload(frame);
        for (int i = 0; i < n; ++i) {
          glFinish();
          const auto t0 = Clock::now();
          if (backend == "gl") {
            gl.BlurTexture(texture, method, r);
            glFinish();
          } else {
            const cv::Mat out = method == "disc" ? render::DiscBlurCpu(frame, r) : render::GaussianBlurCpu(frame, r);
          }
          times.push_back(Ms(t0));
        }
        row.samples = n;
        row.median_ms = Percentile(times, 0.5);
        row.p99_ms = Percentile(times, 0.99);
        rows.push_back(row);
        char line[200];
        std::snprintf(line, sizeof line, "blur %-8s %-3s r=%-4g %4dx%-4d %8.1f ms  error mean %.3f max %.0f levels",
                      method.c_str(), backend.c_str(), r, size.width, size.height, row.median_ms, row.mean_abs_error,
                      row.max_abs_error);
        say(line);
      }
    }
}

// The library's own Gaussian on the same float image, what the CPU Gaussian (r = 8) must not be slower than: the two
// timed in turn (this machine is shared: alternating keeps a slow moment from favouring either), and the CPU row of
// r = 8 takes these times. OpenCV picks its kernel from sigma alone, with the same border. Then Butterworth: CPU
// only, frequency domain, no radius: timed at a middling cut-off.
void AddReferenceRows(const RenderBenchOptions& options, const cv::Mat& frame, const Say& say,
                      std::vector<RenderRow>& rows) {
  const cv::Size size = frame.size();
  {
    RenderRow row{"reference", "opencv_gaussianblur", "cpu", 8, size.width, size.height};
    std::vector<double> ours, library;
    for (int i = 0; i < (options.quick ? 1 : 5); ++i) {
      auto t0 = Clock::now();
      const cv::Mat a = render::GaussianBlurCpu(frame, 8);
      ours.push_back(Ms(t0));
      t0 = Clock::now();
      cv::Mat b;
      cv::GaussianBlur(frame, b, cv::Size(0, 0), 8 / 2.0, 8 / 2.0, cv::BORDER_REPLICATE);
      library.push_back(Ms(t0));
    }
    for (RenderRow& r : rows)
      if (r.kind == "blur" && r.method == "gaussian" && r.backend == "cpu" && r.radius_px == 8 &&
          r.width == size.width && r.height == size.height)
        r.samples = int(ours.size()), r.median_ms = Percentile(ours, 0.5), r.p99_ms = Percentile(ours, 0.99);
    row.samples = int(library.size());
    row.median_ms = Percentile(library, 0.5);
    row.p99_ms = Percentile(library, 0.99);
    row.mean_abs_error = row.max_abs_error = NAN;
    rows.push_back(row);
  }
  const int repeats = options.quick ? 1 : 3;
  RenderRow row{"blur", "butterworth", "cpu", 0, size.width, size.height};
  std::vector<double> times;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = Clock::now();
    render::ButterworthBlurCpu(frame, size.width / 40.0);
    times.push_back(Ms(t0));
  }
  row.median_ms = Percentile(times, 0.5);
  row.p99_ms = Percentile(times, 0.99);
  row.samples = repeats;
  row.mean_abs_error = row.max_abs_error = NAN;  // not measured (no radius to hold it to): empty cells, not 0
  rows.push_back(row);
  say("blur butterworth cpu " + std::to_string(size.width) + "x" + std::to_string(size.height) + " " +
      std::to_string(int(row.median_ms)) + " ms");
}

// Part 2: the test-2 frame, two soccer balls rolling side by side from edge 1 towards edge 11, blurred by the thin
// lens x 3 (stronger, as observers liked), composed region by region and the whole-frame way; each timed, and the two
// outputs compared on a few frames.
void AddTestTwoFrameRows(const RenderBenchOptions& options, const synth::Scene& scene,
                         render::FrameCompositor& compositor, const scene::SurfaceTexture& soccer, const Say& say,
                         std::vector<RenderRow>& rows) {
  const optics::Lens lens = optics::Lens::FromCamera(scene.camera);
  const cv::Size frame_size(scene.camera.image_width_px, scene.camera.image_height_px);
  const int frames = options.quick ? 10 : 120;
  for (const std::string approach : {"region", "whole_frame"}) {
    std::vector<double> times;
    bool warmed_up = false;
    double mean_err = 0, max_err = 0;
    for (int i = 0; i < frames; ++i) {
      const double y = 250.0 * i / std::max(1, frames - 1);  // edge 1 -> edge 11
      std::vector<scene::BlurredObject> balls(2);
      for (int b = 0; b < 2; ++b) {
        auto& o = balls[b].object;
        o = scene::BallOnBoard(scene.board, b == 0 ? 3 : 5, y, 10, 0);  // test 2's balls on sections 3 and 5
        o.texture = soccer;
        cv::Matx33d rot;
        cv::Rodrigues(scene.rvec, rot);
        const double z = (rot * o.center_board_mm + scene.tvec)[2];
        balls[b].r_px = 3 * optics::BlurRadiusPx(lens, scene.focus_mm, z) * (b == 0 ? 1.0 : 0.6);
      }
      if (!warmed_up) {  // the first frame uploads and mipmaps the ball's texture: not a frame-rate cost
        compositor.Compose(balls);
        compositor.Finish();
        warmed_up = true;
      }
      glFinish();
      const auto t0 = Clock::now();
      if (approach == "region") compositor.Compose(balls); else compositor.ComposeWholeFrame(balls);
      compositor.Finish();
      times.push_back(Ms(t0));
      if (approach == "whole_frame" && i % std::max(1, frames / 4) == 0) {
        // Equal output: the same frame through the region approach.
        const cv::Mat whole = compositor.Read();
        compositor.Compose(balls);
        const cv::Mat region = compositor.Read();
        cv::Mat diff;
        cv::absdiff(whole, region, diff);
        mean_err = std::max(mean_err, cv::mean(diff)[0]);
        double m = 0;
        cv::minMaxLoc(diff.reshape(1), nullptr, &m);
        max_err = std::max(max_err, m);
      }
    }
    RenderRow row{"frame", approach, "gl", 0, frame_size.width, frame_size.height};
    row.objects = 2;
    row.samples = frames;
    row.median_ms = Percentile(times, 0.5);
    row.p99_ms = Percentile(times, 0.99);
    row.mean_abs_error = mean_err;
    row.max_abs_error = max_err;
    rows.push_back(row);
    char line[200];
    std::snprintf(line, sizeof line, "frame %-11s %dx%d: median %.1f ms, p99 %.1f ms over %d frames", approach.c_str(),
                  frame_size.width, frame_size.height, row.median_ms, row.p99_ms, frames);
    say(line);
  }
}

// Part 3, one row: `objects` balls spread over the board's 7 sections and along it, rolling over `s` for
// `growth_frames` timed frames (frame 0 uploads the texture: not timed), at the thin lens's blur x 3 or at
// `fixed_r_px`.
void AddGrowthRow(const std::string& swept, int growth_frames, const synth::Scene& s, render::FrameCompositor& c,
                  const scene::SurfaceTexture& soccer, int objects, double fixed_r_px, const Say& say,
                  std::vector<RenderRow>& rows) {
  const optics::Lens l = optics::Lens::FromCamera(s.camera);
  cv::Matx33d rot;
  cv::Rodrigues(s.rvec, rot);
  std::vector<double> times;
  double r_sum = 0;
  for (int i = 0; i <= growth_frames; ++i) {
    std::vector<scene::BlurredObject> balls(static_cast<size_t>(objects));
    for (int b = 0; b < objects; ++b) {
      const double y = std::fmod(250.0 * i / growth_frames + 37.0 * b, 250.0);
      auto& o = balls[size_t(b)].object;
      o = scene::BallOnBoard(s.board, 1 + b % 7, y, 10, 0);
      o.texture = soccer;
      const double z = (rot * o.center_board_mm + s.tvec)[2];
      balls[size_t(b)].r_px = fixed_r_px > 0 ? fixed_r_px : 3 * optics::BlurRadiusPx(l, s.focus_mm, z);
      if (i > 0) r_sum += balls[size_t(b)].r_px;
    }
    glFinish();
    const auto t0 = Clock::now();
    c.Compose(balls);
    c.Finish();
    if (i > 0) times.push_back(Ms(t0));
  }
  RenderRow row{"growth", swept, "gl", r_sum / (growth_frames * objects), s.camera.image_width_px,
                s.camera.image_height_px};
  row.objects = objects;
  row.samples = int(times.size());
  row.median_ms = Percentile(times, 0.5);
  row.p99_ms = Percentile(times, 0.99);
  row.mean_abs_error = row.max_abs_error = std::numeric_limits<double>::quiet_NaN();
  rows.push_back(row);
  char line[200];
  std::snprintf(line, sizeof line, "growth %-7s %2d balls %dx%d r %.1f px: median %.1f ms, p99 %.1f ms",
                swept.c_str(), objects, row.width, row.height, row.radius_px, row.median_ms, row.p99_ms);
  say(line);
}

}  // namespace

std::vector<RenderRow> RunRenderBench(const RenderBenchOptions& options) {
  std::vector<RenderRow> rows;
  const Say say = [&](const std::string& s) { if (options.progress) options.progress(s); };
  auto context = render::GlContext::CreateOffscreen();
  say("GL: " + context->Describe());
  render::GlBlur gl;

  // 1. One blur of a whole frame: every method, radius and size, GPU and CPU, timed; accuracy on a crop.
  std::vector<cv::Size> sizes = {{1280, 720}, {1920, 1080}, {4592, 3056}};
  std::vector<double> radii = {1, 4, 8, 16};
  if (options.quick) sizes = {{640, 360}}, radii = {1, 8};
  if (options.frames_only) sizes.clear();
  for (const cv::Size& size : sizes) {
    const cv::Mat frame = TestFrame(size.width, size.height);
    AddBlurRows(gl, options, radii, frame, say, rows);
    AddReferenceRows(options, frame, say, rows);
  }

  // 2. The test-2 frame over a thesis scene at 1920 x 1080 (16:9 crop of the thesis sensor).
  synth::SceneOptions scene_options;
  const cv::Size frame_size = options.quick ? cv::Size(960, 540) : cv::Size(1920, 1080);
  scene_options.camera = ThesisCamera();
  scene_options.camera.sensor_height_mm = 23.4 * frame_size.height / frame_size.width;
  scene_options.camera.image_width_px = frame_size.width;
  scene_options.camera.image_height_px = frame_size.height;
  scene_options.supersample = 2;
  say("rendering the background scene " + std::to_string(frame_size.width) + "x" + std::to_string(frame_size.height));
  const synth::Scene scene = synth::RenderScene(scene_options);
  render::FrameCompositor compositor(scene.camera, scene.rvec, scene.tvec, scene.image);
  const scene::SurfaceTexture soccer(scene::SoccerTexture(1024));
  AddTestTwoFrameRows(options, scene, compositor, soccer, say, rows);

  // 3. How a frame's cost grows: balls per frame, frame size, blur radius - one swept at a time from the two-ball
  //    frame above, region by region.
  const int growth_frames = options.quick ? 5 : 120;  // a p99 needs more than a few dozen frames
  for (const int objects : {1, 2, 8, 32})
    AddGrowthRow("objects", growth_frames, scene, compositor, soccer, objects, 0, say, rows);
  for (const double r : {1.0, 4.0, 8.0, 16.0})
    AddGrowthRow("radius", growth_frames, scene, compositor, soccer, 2, r, say, rows);
  const std::vector<cv::Size> growth_sizes = options.quick ? std::vector<cv::Size>{{640, 360}, {960, 540}}
                                                           : std::vector<cv::Size>{{1280, 720}, {1920, 1080}, {3840, 2160}};
  for (const cv::Size& size : growth_sizes) {
    synth::SceneOptions o = scene_options;
    o.camera.image_width_px = size.width;
    o.camera.image_height_px = size.height;
    o.supersample = 1;  // the background's quality does not change what a frame costs
    say("rendering the background scene " + std::to_string(size.width) + "x" + std::to_string(size.height));
    const synth::Scene s = synth::RenderScene(o);
    render::FrameCompositor c(s.camera, s.rvec, s.tvec, s.image);
    AddGrowthRow("size", growth_frames, s, c, soccer, 2, 0, say, rows);
  }
  return rows;
}

void WriteRenderCsv(const std::vector<RenderRow>& rows, const std::filesystem::path& path, bool quick) {
  std::string text =
      "kind,method,backend,radius_px,width,height,samples,median_ms,p99_ms,mean_abs_error_levels,"
      "max_abs_error_levels,objects,quick\n";
  for (const auto& r : rows) {
    char line[300], mean[32] = "", max[32] = "";
    if (!std::isnan(r.mean_abs_error)) std::snprintf(mean, sizeof mean, "%.4f", r.mean_abs_error);
    if (!std::isnan(r.max_abs_error)) std::snprintf(max, sizeof max, "%.1f", r.max_abs_error);
    std::snprintf(line, sizeof line, "%s,%s,%s,%g,%d,%d,%d,%.3f,%.3f,%s,%s,%d,%d\n", r.kind.c_str(),
                  r.method.c_str(), r.backend.c_str(), r.radius_px, r.width, r.height, r.samples, r.median_ms, r.p99_ms,
                  mean, max, r.objects, int(quick));
    text += line;
  }
  WriteFileAtomically(path, text);
}

std::string SummarizeRender(const std::vector<RenderRow>& rows) {
  std::ostringstream out;
  const RenderRow* region = nullptr;
  const RenderRow* whole = nullptr;
  for (const auto& r : rows) {
    if (r.kind == "frame" && r.method == "region") region = &r;
    if (r.kind == "frame" && r.method == "whole_frame") whole = &r;
  }
  char line[400];
  if (region && whole) {
    const double speedup = whole->median_ms / region->median_ms;
    std::snprintf(line, sizeof line,
                  "two-ball frame %dx%d: region approach median %.1f ms (p99 %.1f ms), whole-frame approach median "
                  "%.1f ms (p99 %.1f ms): %.1fx faster (target >= 100x: %s); p99 within one 120 Hz refresh (8.3 ms): "
                  "%s; outputs differ by at most %.0f levels (mean %.3f)\n",
                  region->width, region->height, region->median_ms, region->p99_ms, whole->median_ms, whole->p99_ms,
                  speedup, speedup >= 100 ? "met" : "NOT met", region->p99_ms <= 1000.0 / 120 ? "yes" : "no",
                  whole->max_abs_error, whole->mean_abs_error);
    out << line;
  }
  for (const auto& r : rows)
    if (r.kind == "growth" && r.method == "objects" && r.objects == 8) {
      std::snprintf(line, sizeof line, "8 balls %dx%d: median %.1f ms, p99 %.1f ms; p99 within one 60 Hz refresh "
                    "(16.7 ms): %s\n", r.width, r.height, r.median_ms, r.p99_ms, r.p99_ms <= 1000.0 / 60 ? "yes" : "no");
      out << line;
    }
  for (const auto& ref : rows)
    for (const auto& r : rows)
      if (ref.kind == "reference" && r.kind == "blur" && r.method == "gaussian" && r.backend == "cpu" &&
          r.radius_px == 8 && r.width == ref.width && r.height == ref.height) {
        std::snprintf(line, sizeof line,
                      "CPU gaussian r=8 at %dx%d: %.0f ms; OpenCV's GaussianBlur on the same float image %.0f ms "
                      "(ratio %.2f, target <= 1: %s)\n", r.width, r.height, r.median_ms, ref.median_ms,
                      r.median_ms / ref.median_ms, r.median_ms <= ref.median_ms ? "met" : "NOT met");
        out << line;
      }
  for (const auto& r : rows)
    if (r.kind == "blur" && r.method == "butterworth" && r.width >= 4000) {
      std::snprintf(line, sizeof line, "butterworth %dx%d on the CPU: %.0f ms (target < 2000 ms: %s)\n", r.width,
                    r.height, r.median_ms, r.median_ms < 2000 ? "met" : "NOT met");
      out << line;
    }
  // GL against CPU for each method at the largest size and radius 8.
  for (const std::string method : {"gaussian", "disc"}) {
    const RenderRow *g = nullptr, *c = nullptr;
    for (const auto& r : rows)
      if (r.kind == "blur" && r.method == method && r.radius_px == 8 && (!g || r.width >= g->width)) {
        if (r.backend == "gl") g = &r;
      }
    for (const auto& r : rows)
      if (g && r.kind == "blur" && r.method == method && r.radius_px == 8 && r.width == g->width && r.backend == "cpu")
        c = &r;
    if (g && c) {
      std::snprintf(line, sizeof line,
                    "%s r=8 at %dx%d: GL %.1f ms, CPU %.1f ms (GL/CPU time %.2f); error vs exact: GL mean %.3f max "
                    "%.0f levels, CPU mean %.3f max %.0f levels\n",
                    method.c_str(), g->width, g->height, g->median_ms, c->median_ms, g->median_ms / c->median_ms,
                    g->mean_abs_error, g->max_abs_error, c->mean_abs_error, c->max_abs_error);
      out << line;
    }
  }
  return out.str();
}

}  // namespace blurcue::bench
