// blurcue synth-scene: a ground-truth scene (src/synth) rendered and written to a folder.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "cli/commands.h"
#include "cli/scene_option_error.h"
#include "core/atomic_file.h"
#include "core/output_guard.h"
#include "core/camera.h"
#include "core/error.h"
#include "core/typed.h"
#include "optics/thin_lens.h"
#include "synth/scene.h"

namespace blurcue::cli {
namespace {

Error UsageError(const std::string& option, const std::string& what) {
  return Error(ErrorKind::kUsage, option + ": " + what);
}

// "inf" / "infinity" or a number of mm. A "nan" would stand for the default (focus on edge 1) without saying so.
double ParseFocus(const std::string& text) {
  if (text == "inf" || text == "infinity") return std::numeric_limits<double>::infinity();
  if (const std::optional<double> v = ParseDecimal(text); v && *v > 0 && *v <= 1e6) return *v;
  throw UsageError("--focus-mm", "must be a distance in (0, 1000000] mm or 'inf', got " + Echo(text));
}

}  // namespace

// RenderScene names SceneOptions fields; say them as the options a user typed (`renamed` adds or overrides names:
// synth-take's).
Error AsSceneOptionError(const Error& e, const std::map<std::string, std::string>& renamed) {
  std::map<std::string, std::string> options = {
      {"tilt_deg", "--tilt-deg"},       {"edge1_u_mm", "--edge1-u-mm"}, {"lateral_mm", "--lateral-mm"},
      {"yaw_deg", "--yaw-deg"},         {"focus_mm", "--focus-mm"},     {"fixed_r_px", "--fixed-r-px"},
      {"blur_gain", "--blur-gain"},     {"white", "--white"},           {"black", "--black"},
      {"table", "--table"},             {"noise_std", "--noise"},       {"jpeg_quality", "--jpeg-quality"},
      {"flaws", "--flaws"},             {"supersample", "--supersample"}, {"board", "--board"},
      {"floor_sigma_px", "--floor-sigma-px"}, {"vignetting", "--vignetting"},
      {"post_sigma_px", "--post-sigma-px"}, {"post_amount", "--post-amount"},
  };
  for (const auto& [field, option] : renamed) options[field] = option;
  const std::string message = e.what();
  const size_t colon = message.find(':');
  if (e.kind() == ErrorKind::kInput && colon != std::string::npos) {
    auto it = options.find(message.substr(0, colon));
    if (it != options.end()) return Error(ErrorKind::kUsage, it->second + message.substr(colon));
  }
  return e;
}


namespace {

struct SynthSceneArgs {
  std::string out, preset = "quarter", camera, focus, psf = "disc", board = "7x10", post_filter = "none";
  uint64_t seed = 1;
  int width = 0, height = 0, jpeg_quality = 0, flaws = 0;
  std::optional<int> supersample;
  double square_mm = 25;
  std::optional<double> fixed_r_px;
  bool quiet = false;
  synth::SceneOptions o;
  CLI::Option* post_sigma = nullptr;   // given or not: a filter's option without its filter is refused
  CLI::Option* post_amount = nullptr;
};

constexpr const char* kSynthSceneHelp =
      "Render a ground-truth scene: a printed checkerboard lying on a wooden table, photographed through a thin\n"
      "lens, so every blur radius in it is known. Use it to test and benchmark calibration (blurcue calibrate\n"
      "--truth DIR/truth.json) where a real photo gives no ground truth.\n"
      "\n"
      "The defaults are the thesis set-up (Tables 4.1-4.3) at a quarter of its resolution: 7x10 board of 25 mm\n"
      "squares, camera pitched down 38 deg, f = 21 mm at f/5.6 on a 23.4 x 15.6 mm sensor, 1148 x 764 px, edge 1\n"
      "(the board's nearest line) 342.3 mm deep and in focus, so blur grows with distance to ~3.4 px at the top.\n"
      "--preset thesis renders the full 4592 x 3056 px instead.\n"
      "\n"
      "Blur radius r (px) = 2 x the standard deviation of the line-spread function: a disc PSF of radius r, or a\n"
      "Gaussian of std r/2. The scene is shaded per sub-pixel in linear light, blurred per sub-pixel with the\n"
      "thin-lens radius of the depth seen there, averaged to camera pixels, then noise, sRGB and optional JPEG.\n"
      "\n"
      "Writes to --out DIR:\n"
      "  scene.png           the photo (8-bit sRGB)\n"
      "  scene-no-board.png  the same view with only the table (for the thesis's test 3)\n"
      "  camera.json         the camera, ready for blurcue calibrate --camera\n"
      "  truth.json          options, camera, board, pose (board frame -> camera: rvec, tvec mm, rotation),\n"
      "                      focus, aperture, pixel pitch, and per edge section its true depth u_mm, blur r_px\n"
      "                      (optical: the pixel's own area excluded) and whether a printing flaw touches it\n"
      "Same options + seed give the same bytes.\n"
      "Example: blurcue synth-scene --out scenes/a --seed 7 --noise 0.004 --focus-mm 260";

// The files synth-scene writes: the folder it replaces holds these and nothing else.
bool OurSceneFile(const std::string& name) {
  return name == "scene.png" || name == "scene-no-board.png" || name == "camera.json" || name == "truth.json";
}

void AddSceneOptions(CLI::App* cmd, SynthSceneArgs* a) {
  cmd->add_option("--out", a->out, "folder to write the four files to (created)")->required();
  cmd->add_option("--seed", a->seed, "seed of the texture, flaws and noise")->capture_default_str()
      ->transform(SeedValidator());
  cmd->add_option("--preset", a->preset,
                  "quarter: thesis set-up at 1148 x 764 (default); thesis: full 4592 x 3056 (supersample 2)")
      ->check(OneOf({"quarter", "thesis"}))->capture_default_str();
  cmd->add_option("--camera", a->camera, "camera.json to shoot with instead of the preset's camera")
      ->check(CLI::ExistingFile);
  cmd->add_option("--width", a->width, "image width in px (the sensor is resampled; height follows the aspect)")
      ->transform(IntRange(32, kMaxImageSidePx, "px"));
  cmd->add_option("--height", a->height, "image height in px (with --width: both exactly)")
      ->transform(IntRange(32, kMaxImageSidePx, "px"));
  cmd->add_option("--board", a->board, "board size in squares, COLSxROWS")->capture_default_str();
  cmd->add_option("--square-mm", a->square_mm, "side of one square in mm")->capture_default_str()
      ->check(FiniteRange(1, 1000, "mm"));
  cmd->add_option("--tilt-deg", a->o.tilt_deg, "camera pitched down from the horizontal, degrees")->capture_default_str()
      ->check(FinitePositive(90, "degrees"));
  cmd->add_option("--edge1-u-mm", a->o.edge1_u_mm, "depth (camera z) of the midpoint of edge 1, mm")
      ->capture_default_str()->check(FinitePositive(1e6, "mm"));
  cmd->add_option("--lateral-mm", a->o.lateral_mm, "board shifted sideways from the optical axis, mm")
      ->capture_default_str()->check(FiniteRange(-1e4, 1e4, "mm"));
  cmd->add_option("--yaw-deg", a->o.yaw_deg, "board turned about the table normal, degrees (0: edges are image rows)")
      ->capture_default_str()->check(FiniteRange(-89.9, 89.9, "degrees"));
  cmd->add_option("--focus-mm", a->focus, "focus distance in mm, or 'inf' (default: edge 1's midpoint)");
  cmd->add_option("--psf", a->psf, "point-spread function: disc (thin lens) or gaussian")
      ->check(OneOf({"disc", "gaussian"}))->capture_default_str();
  cmd->add_option("--fixed-r-px", a->fixed_r_px, "one blur radius everywhere instead of the thin lens's, px")
      ->check(FiniteRange(0, optics::kMaxBlurRadiusPx, "px"));
  cmd->add_option("--blur-gain", a->o.blur_gain, "multiplies every thin-lens radius (a lens blurrier than ideal)")
      ->capture_default_str()->check(FiniteRange(0, 100, ""));
  cmd->add_option("--floor-sigma-px", a->o.floor_sigma_px,
                  "lens floor: every PSF convolved with a Gaussian of this std, px (truth adds its second moment)")
      ->capture_default_str()->check(FiniteRange(0, 20, "px"));
  cmd->add_option("--post-filter", a->post_filter,
                  "a filter on the sampled image, after the noise, as demosaicing or sharpening do: none, gaussian\n"
                  "(taps of a Gaussian of std --post-sigma-px at whole pixels) or sharpen (unsharp mask: 1 + amount\n"
                  "times the image less amount times that Gaussian); truth adds the taps' second moment")
      ->check(OneOf({"none", "gaussian", "sharpen"}))->capture_default_str();
  a->post_sigma = cmd->add_option("--post-sigma-px", a->o.post_filter.sigma_px,
                                  "std of the post filter's Gaussian, px (0, 5]")
      ->check(FiniteRange(0, 5, "px"));
  a->post_amount = cmd->add_option("--post-amount", a->o.post_filter.amount,
                                   "sharpen: how much of the blurred copy is taken away (0, 5]")
      ->check(FiniteRange(0, 5, ""));
  cmd->add_option("--vignetting", a->o.vignetting, "light fall-off at the image corner, 0..0.9 (0.35: corners at 65 %)")
      ->capture_default_str()->check(FiniteRange(0, 0.9, ""));
  cmd->add_option("--noise", a->o.noise_std,
                  "sensor noise std in linear units (plus shot noise of the same size at white), e.g. 0.004")
      ->capture_default_str()->check(FiniteRange(0, 1, "linear units"));
  cmd->add_option("--jpeg-quality", a->jpeg_quality, "JPEG round trip at this quality (1-100); 0: none")
      ->capture_default_str()->transform(IntRange(0, 100));
  cmd->add_option("--flaws", a->flaws, "dark printing spots on white squares near edges (recorded in truth.json)")
      ->capture_default_str()->transform(IntRange(0, 10000));
  cmd->add_option("--white", a->o.white, "linear reflectance x exposure of the white squares")->capture_default_str()
      ->check(FiniteRange(0, 1, "linear reflectance"));
  cmd->add_option("--black", a->o.black, "... of the black squares")->capture_default_str()
      ->check(FiniteRange(0, 1, "linear reflectance"));
  cmd->add_option("--table", a->o.table, "... mean of the wooden table")->capture_default_str()
      ->check(FiniteRange(0, 1, "linear reflectance"));
  cmd->add_option("--supersample", a->supersample,
                  "sub-pixels per pixel side for shading and blur (default 4; 2 for --preset thesis). 1\n"
                  "point-samples each pixel: no pixel aperture and aliased edges, so blur measured on the image\n"
                  "reads off its truth near focus; 2 or more for a ground truth")
      ->transform(IntRange(1, 16));
  cmd->add_flag("--quiet", a->quiet, "print only errors");

}

// The options as synth::SceneOptions, checked in the order the command always checked them.
synth::SceneOptions SceneOptionsFrom(const SynthSceneArgs& a) {
  synth::SceneOptions o = a.o;
  o.seed = a.seed;
  o.jpeg_quality = a.jpeg_quality;
  o.flaws = a.flaws;
  o.fixed_r_px = a.fixed_r_px;
  o.psf = a.psf == "gaussian" ? synth::Psf::kGaussian : synth::Psf::kDisc;
  o.post_filter.kind = synth::ParsePostFilter(a.post_filter);
  // A filter's option without that filter would be ignored: refused, naming what it needs.
  if (o.post_filter.kind == synth::PostFilter::kNone && a.post_sigma->count() > 0)
    throw UsageError("--post-sigma-px", "needs --post-filter gaussian or sharpen (the filter is none)");
  if (o.post_filter.kind == synth::PostFilter::kNone && a.post_amount->count() > 0)
    throw UsageError("--post-amount", "needs --post-filter sharpen (the filter is none)");
  if (o.post_filter.kind == synth::PostFilter::kGaussian && a.post_amount->count() > 0)
    throw UsageError("--post-amount", "is for --post-filter sharpen, not gaussian");
  // A filter without its values: named as missing (the message used to quote the unset default, "got 0").
  if (o.post_filter.kind != synth::PostFilter::kNone && a.post_sigma->count() == 0)
    throw UsageError("--post-filter " + a.post_filter, "needs --post-sigma-px S, the std of its Gaussian in (0, 5] px");
  if (o.post_filter.kind == synth::PostFilter::kSharpen && a.post_amount->count() == 0)
    throw UsageError("--post-filter sharpen", "needs --post-amount A, how much of the blurred copy it takes away, in (0, 5]");
  if (!a.focus.empty()) o.focus_mm = ParseFocus(a.focus);
  o.board = Board::Parse(a.board, a.square_mm);
  if (!(a.square_mm > 0)) throw UsageError("--square-mm", "must be > 0, got " + std::to_string(a.square_mm));

  Camera camera = ThesisCamera();
  int supersample = 4;
  if (a.preset == "thesis") supersample = 2;
  else camera = camera.Resized(1148, 764);
  if (!a.camera.empty()) camera = LoadCamera(a.camera);
  if (a.width != 0 || a.height != 0) {
    if (a.width < 0 || (a.width == 0 && a.height <= 0))
      throw UsageError(a.width != 0 ? "--width" : "--height", "must be a positive number of pixels");
    int w = a.width, h = a.height;
    const double aspect = double(camera.image_height_px) / camera.image_width_px;
    if (h == 0) h = std::max(1, static_cast<int>(std::lround(w * aspect)));
    if (w == 0) w = std::max(1, static_cast<int>(std::lround(h / aspect)));
    if (w < 32 || h < 32 || w > kMaxImageSidePx || h > kMaxImageSidePx)
      throw UsageError("--width/--height", "must be 32.." + std::to_string(kMaxImageSidePx) + " px, got " +
                                               std::to_string(w) + " x " + std::to_string(h));
    camera = camera.Resized(w, h);
  }
  o.camera = camera;
  o.supersample = a.supersample.value_or(supersample);
  return o;
}

void PrintScene(const synth::Scene& scene, const synth::SceneOptions& o, const std::string& out, double total_s,
                double render_s) {
  const Camera& camera = o.camera;
  const auto& s = scene.sections;
  const int n = scene.board.SectionCount(), edges = scene.board.EdgeCount();
  auto edge_mean = [&](int e, double synth::SectionTruth::*field) {
    double sum = 0;
    for (int k = 0; k < n; ++k) sum += s[(e - 1) * n + k].*field;
    return sum / n;
  };
  auto edge_r = [&](int e) { return edge_mean(e, &synth::SectionTruth::r_px); };
  auto edge_u = [&](int e) { return edge_mean(e, &synth::SectionTruth::u_mm); };
  int flawed = 0;
  for (const auto& t : s) flawed += t.flawed;
  std::printf("rendered %d x %d px (supersample %d), %s board %s, tilt %.1f deg, focus %s\n",
              camera.image_width_px, camera.image_height_px, o.supersample,
              o.psf == synth::Psf::kDisc ? "disc PSF," : "gaussian PSF,", scene.board.Name().c_str(), o.tilt_deg,
              std::isinf(scene.focus_mm) ? "at infinity" : (std::to_string(scene.focus_mm).substr(0, 6) + " mm").c_str());
  std::printf("mean of edge 1: u = %.1f mm, r = %.2f px;  edge %d: u = %.1f mm, r = %.2f px;  whole view r %.2f - "
              "%.2f px (lens floor included)\n",
              edge_u(1), edge_r(1), edges, edge_u(edges), edge_r(edges),
              scene.truth["r_range_px"][0].get<double>(), scene.truth["r_range_px"][1].get<double>());
  if (o.post_filter.kind != synth::PostFilter::kNone)
    std::printf("filtered after sampling: %s, std %.2f px%s (its taps' second moment is in every r above)\n",
                synth::Name(o.post_filter.kind), o.post_filter.sigma_px,
                o.post_filter.kind == synth::PostFilter::kSharpen
                    ? (", amount " + std::to_string(o.post_filter.amount).substr(0, 4)).c_str() : "");
  if (o.flaws > 0) std::printf("%d printing flaws touching %d edge sections\n", o.flaws, flawed);
  std::printf("wrote %s/{scene.png, scene-no-board.png, camera.json, truth.json} in %.2f s (render %.2f s)\n",
              out.c_str(), total_s, render_s);
}

void RunSynthScene(const SynthSceneArgs& a) {
  const auto t0 = std::chrono::steady_clock::now();
  {
    OutputGuard guard;
    if (!a.camera.empty()) guard.Input("--camera", a.camera);
    guard.OutputFolder("--out", a.out).Check();
  }
  // The four files are written beside --out and swapped in whole; a folder of anything else (a photo of one's own
  // named scene.png among other files) is refused before the render, not overwritten.
  RequireReplaceableFolder(a.out, OurSceneFile);
  // A folder of one's own camera.json or photo named scene.png alone passed the check above and was replaced.
  RequireMarkedFolder("--out", a.out, "truth.json", "a scene synth-scene wrote", "one's own camera.json or scene.png?");
  const synth::SceneOptions o = SceneOptionsFrom(a);
  synth::Scene scene;
  try {
    scene = synth::RenderScene(o);
  } catch (const Error& e) {
    throw AsSceneOptionError(e);
  }
  const double render_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  WriteFolderAtomically(
      a.out, [&](const std::filesystem::path& partial) { synth::WriteScene(scene, partial); }, OurSceneFile);
  const double total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (a.quiet) return;
  PrintScene(scene, o, a.out, total_s, render_s);
}

}  // namespace

void AddSynthSceneCommand(CLI::App& app) {
  auto args = std::make_shared<SynthSceneArgs>();
  CLI::App* cmd = app.add_subcommand("synth-scene", kSynthSceneHelp);
  AddSceneOptions(cmd, args.get());
  cmd->callback([args] { RunSynthScene(*args); });
}

}  // namespace blurcue::cli
