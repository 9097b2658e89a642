#include <chrono>
#include <cstdio>
#include <string>

#include "cli/commands.h"
#include "core/output_guard.h"
#include "core/own_output.h"
#include "core/error.h"
#include "core/image.h"
#include "render/blur.h"
#include "render/gl_context.h"

namespace blurcue::cli {

void AddBlurCommand(CLI::App& app) {
  struct Args {
    std::string in, out, method = "gaussian", backend = "gl";
    double radius_px = -1, cutoff = -1;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "blur",
      "Apply one blur to any image (to prepare your own stimuli). Works in linear light with premultiplied alpha,\n"
      "so bright areas keep their brightness and transparent borders blur without dark halos.\n"
      "  gaussian     separable Gaussian, s = r / 2 (the thesis's shader, appendix A), --radius-px r\n"
      "  disc         thin-lens pillbox of radius r, --radius-px r\n"
      "  butterworth  2nd-order low-pass (the thesis's pre-research), --cutoff in cycles per image width (CPU)\n"
      "Example: blurcue blur face.png --method disc --radius-px 6 --out face-r6.png");
  cmd->add_option("in", args->in, "input image (PNG/JPEG, sRGB, alpha kept)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "output image")->required();
  cmd->add_option("--method", args->method, "gaussian, disc or butterworth")
      ->check(CLI::IsMember({"gaussian", "disc", "butterworth"}))->capture_default_str();
  cmd->add_option("--radius-px", args->radius_px, "blur radius r in px (2 x std of the line-spread function)")
      ->check(FiniteRange(0, render::kMaxBlurRadiusPx, "px"));
  cmd->add_option("--cutoff", args->cutoff, "Butterworth cut-off, cycles per image width")
      ->check(FinitePositive(render::kMaxCutoffCyclesPerWidth, "cycles per image width"));
  cmd->add_option("--backend", args->backend, "gl (Mesa/GPU through EGL, no display needed) or cpu (OpenCV)")
      ->check(CLI::IsMember({"gl", "cpu"}))->capture_default_str();
  cmd->callback([args, cmd] {
    OutputGuard().Input("IN", args->in).OutputFile("--out", args->out).Check();
    RequireImageName("--out", args->out);
    // An image of another kind at its path (a protocol named .png, a JPEG named .png) is not replaced.
    RequireOwnFile("--out", args->out, "an image of the kind its name says", ImageOfExtension(args->out));
    const bool butterworth = args->method == "butterworth";
    // The other method's value is refused, not ignored (--radius-px 2 on a Butterworth blurred by the cut-off alone).
    if (butterworth && cmd->count("--radius-px") > 0)
      throw Error(ErrorKind::kUsage, "--radius-px: is for --method gaussian or disc; butterworth reads --cutoff");
    if (!butterworth && cmd->count("--cutoff") > 0)
      throw Error(ErrorKind::kUsage, "--cutoff: is for --method butterworth; " + args->method + " reads --radius-px");
    if (butterworth && args->cutoff <= 0)
      throw Error(ErrorKind::kUsage, "--method butterworth needs --cutoff (cycles per image width)");
    if (!butterworth && args->radius_px < 0)
      throw Error(ErrorKind::kUsage, "--method " + args->method + " needs --radius-px");
    const cv::Mat image = ReadImage(args->in);
    const bool alpha = image.channels() == 4;
    const cv::Mat linear = render::ToLinearPremultiplied(image);
    const auto t0 = std::chrono::steady_clock::now();
    cv::Mat blurred;
    std::string backend = args->backend;
    if (butterworth) {
      if (backend == "gl") std::fprintf(stderr, "note: butterworth runs on the CPU\n");
      backend = "cpu";
      blurred = render::ButterworthBlurCpu(linear, args->cutoff);
    } else if (backend == "cpu") {
      blurred = args->method == "disc" ? render::DiscBlurCpu(linear, args->radius_px)
                                       : render::GaussianBlurCpu(linear, args->radius_px);
    } else {
      auto context = render::GlContext::CreateOffscreen();
      render::GlBlur gl;
      blurred = args->method == "disc" ? gl.Disc(linear, args->radius_px) : gl.Gaussian(linear, args->radius_px);
    }
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    WriteImage(args->out, render::FromLinearPremultiplied(blurred, alpha));
    std::printf("%s (%s, %dx%d) -> %s in %.0f ms\n", args->method.c_str(), backend.c_str(), image.cols, image.rows,
                args->out.c_str(), ms);
  });
}

}  // namespace blurcue::cli
