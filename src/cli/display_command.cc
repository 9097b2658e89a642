// blurcue display check: a monitor's profile on its own screen - a ruler and a circle of known size to hold a
// ruler to, grey steps for a photometer, and the refresh interval measured over many flips.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "cli/commands.h"
#include "core/output_guard.h"
#include "core/own_output.h"
#include "core/error.h"
#include "core/stats.h"
#include "core/image.h"
#include "display/profile.h"
#include "render/frame_compositor.h"
#include "render/gl_context.h"

namespace blurcue::cli {
namespace {

// The test screen at the window's size, 8-bit sRGB BGR, in the profile's units.
cv::Mat TestScreen(const display::Profile& profile, int width, int height) {
  const double grey = 255 * display::DriveLevel(display::Transfer{}, 0.18);  // 18 % grey, as the studies use
  cv::Mat image(height, width, CV_8UC3, cv::Scalar::all(std::round(grey)));
  const cv::Scalar ink(20, 20, 20), white(255, 255, 255);
  auto text = [&](const std::string& line, int y, double scale = 0.7) {
    cv::putText(image, line, {40, y}, cv::FONT_HERSHEY_SIMPLEX, scale, ink, 2, cv::LINE_AA);
  };
  char line[200];
  text("blurcue display check: " + profile.name, 50, 0.9);
  std::snprintf(line, sizeof line, "%d x %d px, %.1f x %.1f mm, viewed from %.0f mm: %.2f px per degree, %.4f mm per px",
                profile.width_px, profile.height_px, profile.width_mm, profile.height_mm, profile.distance_mm,
                display::PxPerDeg(profile), display::MmPerPx(profile));
  text(line, 90, 0.6);
  // A 100 mm ruler with 10 mm ticks: it must measure 100 mm on the glass, or width_mm is wrong.
  const double mm = 1 / display::MmPerPx(profile);
  const int x0 = 40, y0 = 160, length = static_cast<int>(std::lround(100 * mm));
  cv::line(image, {x0, y0}, {x0 + length, y0}, white, 3);
  for (int t = 0; t <= 10; ++t) {
    const int x = x0 + static_cast<int>(std::lround(t * 10 * mm));
    cv::line(image, {x, y0 - (t % 5 ? 8 : 16)}, {x, y0 + (t % 5 ? 8 : 16)}, white, 2);
  }
  text("this bar must measure 100 mm with a ruler; if not, correct width_mm and height_mm", y0 + 45, 0.6);
  // A circle 5 degrees across at the viewing distance, centred.
  const double r5 = 2.5 * display::PxPerDeg(profile);
  cv::circle(image, {width / 2, height / 2}, static_cast<int>(std::lround(r5)), white, 2, cv::LINE_AA);
  text("the circle is 5 degrees across from the viewing distance", height / 2 + static_cast<int>(r5) + 30, 0.6);
  // Eight luminance steps (relative 0 .. 1) through the profile's transfer function, for a photometer.
  const int steps = 8, patch = std::max(20, std::min(width / (steps + 2), 120));
  for (int i = 0; i < steps; ++i) {
    const double level = 255 * display::DriveLevel(profile.transfer, i / double(steps - 1));
    const cv::Rect box(40 + i * patch, height - patch - 60, patch - 6, patch);
    if (box.br().x < width && box.y > 0) cv::rectangle(image, box, cv::Scalar::all(std::round(level)), cv::FILLED);
  }
  text("relative luminance 0 .. 1 in 8 steps through the " + display::ToString(profile.transfer.kind) +
           " transfer; a photometer should read a straight line", height - 25, 0.6);
  return image;
}

}  // namespace

void AddDisplayCommand(CLI::App& app) {
  CLI::App* display = app.add_subcommand("display", "A monitor's profile: check it on the screen it describes.");
  display->require_subcommand(1);
  struct Args {
    std::string profile, screenshot;
    int frames = 300, monitor = 0;
    bool fullscreen = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = display->add_subcommand(
      "check",
      "Shows a display profile's test screen and measures the real refresh interval.\n"
      "The screen has a 100 mm ruler and a circle 5 degrees across (in the profile's millimetres and viewing\n"
      "distance: hold a ruler to them), and 8 luminance steps through its transfer function (for a photometer).\n"
      "Then it flips the window --frames times with vsync and prints the interval between flips (median, 5th and\n"
      "95th percentile), the refresh rate it implies against the profile's refresh_hz, and how many flips came\n"
      "late (over 1.5 intervals). Without vsync (Xvfb, some compositors) swaps return at once: it says so, since no\n"
      "interval can be measured then. With --fullscreen it also checks the monitor's resolution against the profile.\n"
      "Without --profile the default profile (a 24-inch 16:9 monitor at 60 cm, 60 Hz, sRGB) is checked.\n"
      "Examples:\n"
      "  blurcue display check --profile monitors/lab1.json --fullscreen\n"
      "  blurcue display check --frames 600 --screenshot check.png");
  cmd->add_option("--profile", args->profile, "the display profile JSON (see docs/display.md: describing a monitor)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--frames", args->frames, "flips to time")->capture_default_str()->transform(IntRange(10, 100000));
  cmd->add_flag("--fullscreen", args->fullscreen, "fill the monitor (and check its resolution against the profile)");
  cmd->add_option("--monitor", args->monitor, "which monitor with --fullscreen")->capture_default_str()
      ->transform(IntRange(0, 16));
  cmd->add_option("--screenshot", args->screenshot, "also write the test screen as a PNG");
  cmd->callback([args] {
    if (!args->screenshot.empty()) {
      OutputGuard().OutputFile("--screenshot", args->screenshot).Check();
      RequireImageName("--screenshot", args->screenshot);
      // An image of another kind at its path (a protocol named .png, a JPEG named .png) is not replaced.
      RequireOwnFile("--screenshot", args->screenshot, "an image of the kind its name says",
                     ImageOfExtension(args->screenshot));
    }
    const display::Profile profile =
        args->profile.empty() ? display::DefaultProfile() : display::LoadProfile(args->profile);
    render::WindowOptions options;
    options.width_px = profile.width_px;
    options.height_px = profile.height_px;
    options.fullscreen = args->fullscreen;
    options.monitor = args->monitor;
    options.title = "blurcue - display check - " + profile.name;
    auto context = render::GlContext::CreateWindow(options);
    const int width = context->width_px(), height = context->height_px();
    if (args->fullscreen && (width != profile.width_px || height != profile.height_px))
      throw InputError(args->profile.empty() ? std::string("the default profile") : args->profile,
                       "the monitor shows " + std::to_string(width) + " x " + std::to_string(height) +
                           " px, the profile says " + std::to_string(profile.width_px) + " x " +
                           std::to_string(profile.height_px) + "; correct width_px/height_px or the monitor's mode");
    const cv::Mat screen = TestScreen(profile, width, height);
    if (!args->screenshot.empty()) WriteImage(args->screenshot, screen);
    const render::WindowImage shown(screen);
    std::vector<double> intervals_ms;
    double last = -1;
    for (int i = 0; i <= args->frames && !context->ShouldClose(); ++i) {
      shown.Present(width, height);
      context->SwapBuffers();
      const double now = context->Now();
      if (last >= 0) intervals_ms.push_back((now - last) * 1000);
      last = now;
    }
    if (intervals_ms.empty()) throw Error(ErrorKind::kInput, "the window was closed before any flip was timed");
    const double median = Percentile(intervals_ms, 0.5);
    const int late = static_cast<int>(std::count_if(intervals_ms.begin(), intervals_ms.end(),
                                                    [&](double ms) { return ms > 1.5 * median; }));
    std::printf("%s: %d x %d px window, %.2f px per degree at %.0f mm\n", profile.name.c_str(), width, height,
                display::PxPerDeg(profile), profile.distance_mm);
    std::printf("flip interval over %zu flips: median %.3f ms, 5th %.3f ms, 95th %.3f ms; %d late (> 1.5 intervals)\n",
                intervals_ms.size(), median, Percentile(intervals_ms, 0.05), Percentile(intervals_ms, 0.95), late);
    // With vsync every flip waits for the next refresh, so the intervals are all but equal. Without it (Xvfb, some
    // compositors) a swap returns when drawing is done and the intervals are the machine's, not the monitor's.
    const double spread = Percentile(intervals_ms, 0.95) - Percentile(intervals_ms, 0.05);
    const std::string system = context->RefreshHz() > 0 ? std::to_string(int(context->RefreshHz())) + " Hz" : "nothing";
    // A display that reports no refresh rate (Xvfb) has none to pace by, however steady the drawing happens to be.
    if (context->RefreshHz() <= 0 || median < 1.0 || spread > 0.2 * median) {
      std::printf("NOT MEASURED: the flips are not paced by a refresh (spread %.3f ms of a %.3f ms median; the system "
                  "reports %s: no vsync, as under Xvfb, or a loaded machine); the profile says %.2f Hz\n",
                  spread, median, system.c_str(), profile.refresh_hz);
      return;
    }
    const double hz = 1000 / median;
    const double off = std::abs(hz / profile.refresh_hz - 1);
    std::printf("measured %.2f Hz, the profile says %.2f Hz, the system reports %s: %s\n", hz, profile.refresh_hz,
                system.c_str(), off <= 0.02 ? "agree within 2 %" : "DIFFER: correct refresh_hz in the profile");
  });
}

}  // namespace blurcue::cli
