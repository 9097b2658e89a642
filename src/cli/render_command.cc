#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>

#include <opencv2/imgproc.hpp>

#include "calib/scene_blur.h"
#include "cli/commands.h"
#include "core/output_guard.h"
#include "core/own_output.h"
#include "display/profile.h"
#include "core/error.h"
#include "core/names.h"
#include "core/typed.h"
#include "core/image.h"
#include "render/blur.h"
#include "render/gl_context.h"
#include "render/gl_objects.h"
#include "render/scene_render.h"
#include "scene/frame.h"
#include "scene/objects.h"
#include "scene/stimuli.h"

namespace blurcue::cli {
namespace {

struct RenderArgs {
  std::string calib, background, object = "ball", blur = "fitted", method = "gaussian", out, backend = "gl";
  int edge = 1, section = 4, display_width = 0, picture_height = 0;
  double gain = 1, brightness = 1, contrast = 1, cutoff = 0;
};

// --object KIND[:IMAGE], read whole: "balloon" is no ball and "ball:" names no texture (both were drawn as the
// default ball, silently).
struct ObjectSpec {
  std::string kind, image;  // kind: grid, ball or picture; image: the texture or picture given ("" = the default)
};
ObjectSpec ParseObject(const std::string& text) {
  const size_t colon = text.find(':');
  ObjectSpec o{text.substr(0, colon), colon == std::string::npos ? "" : text.substr(colon + 1)};
  const std::vector<std::string> kinds = {"grid", "ball", "picture"};
  const bool image = colon != std::string::npos;
  if (std::find(kinds.begin(), kinds.end(), o.kind) == kinds.end() || (o.kind == "grid" && image) ||
      (image && o.image.empty()))
    throw Error(ErrorKind::kUsage, "--object must be grid, ball[:TEXTURE] or picture[:IMAGE], got " + Echo(text) +
                                       DidYouMean(o.kind, kinds));
  return o;
}

// The options a kind of object does not read, given: refused, not ignored (a --cutoff on a ball, a --blur on the
// picture). `given` says whether an option was on the command line.
void RequireOptionsOf(const std::string& kind, const std::function<bool(const std::string&)>& given) {
  const std::vector<std::pair<std::string, std::string>> read_by = {
      {"--calib", "grid ball"},      {"--at-edge", "grid ball"},    {"--section", "ball"},
      {"--blur", "grid ball"},       {"--gain", "grid ball"},       {"--method", "grid ball"},
      {"--brightness", "grid ball"}, {"--contrast", "grid ball"},   {"--backend", "grid ball"},
      {"--cutoff", "picture"},       {"--picture-height-px", "picture"}};
  for (const auto& [option, kinds] : read_by)
    if (given(option) && (" " + kinds + " ").find(" " + kind + " ") == std::string::npos) {
      std::string those = kinds;
      if (const size_t space = those.find(' '); space != std::string::npos) those.replace(space, 1, " or a ");
      throw Error(ErrorKind::kUsage, option + ": is for a " + those + ", not --object " + kind + " (nothing reads it)");
    }
}

// The depth-matching study's frame: the picture low-passed on a grey upper half, the scene photo in the lower half.
void RenderPicture(const RenderArgs& args) {
  const ObjectSpec spec = ParseObject(args.object);
  const std::string name = spec.image.empty() ? "face" : spec.image;
  const cv::Mat picture = ReadImage(scene::ResolveStimulus(name));
  const cv::Mat photo = ReadImage(args.background, 1);
  const int w = args.display_width > 0 ? args.display_width : 960;
  const scene::DepthMatchingLayout l = scene::DepthMatchingLayout::Of(w, picture.size());
  const int h = l.frame.height, half = l.upper.height;
  const int picture_h = args.picture_height > 0 ? args.picture_height : l.picture.height;
  if (picture_h > half)
    throw Error(ErrorKind::kUsage, "--picture-height-px " + std::to_string(picture_h) +
                                       " is taller than the grey half of the frame (" + std::to_string(half) +
                                       " px)");
  cv::Mat frame;
  render::StackDepthMatchingFrame(render::PictureOnGrey(picture, l.upper.size(), picture_h, args.cutoff),
                                  l.LowerHalf(photo), &frame);
  WriteImage(args.out, frame);
  std::printf("picture %s, cut-off %g cycles per picture width, %d px high on a %dx%d frame -> %s\n", name.c_str(),
              args.cutoff, picture_h, w, h, args.out.c_str());
}

// A grid or a ball composited over the photo with the blur its depth calls for (one radius, or per pixel by depth
// where the object's depth span changes it by half a pixel or more).
void RenderObject(const RenderArgs& args, std::chrono::steady_clock::time_point t0) {
  if (args.calib.empty()) throw Error(ErrorKind::kUsage, "--calib is required for a grid or a ball");
  const calib::SceneCalib scene = calib::LoadSceneCalib(args.calib);
  const cv::Mat photo = ReadImage(args.background, 1 /* colour */);
  scene.RequireSameSize(photo, args.background);
  if (args.edge < 1 || args.edge > scene.board.EdgeCount())
    throw Error(ErrorKind::kUsage, "--at-edge must be 1.." + std::to_string(scene.board.EdgeCount()) + ", got " +
                                       std::to_string(args.edge));
  if (args.section < 1 || args.section > scene.board.SectionCount())
    throw Error(ErrorKind::kUsage, "--section must be 1.." + std::to_string(scene.board.SectionCount()) +
                                       ", got " + std::to_string(args.section));
  double fixed_r = 0;
  const calib::BlurSource source = calib::ParseBlurSource(args.blur, &fixed_r, "--blur");

  scene::VirtualObject object;
  const double y = (args.edge - 1) * scene.board.square_mm;
  std::string texture_name;
  const ObjectSpec spec = ParseObject(args.object);
  if (spec.kind == "grid") {
    object = scene::CardBesideBoard(scene.board, args.edge, /*left=*/false);
    texture_name = "grid";
  } else {
    object = scene::BallOnBoard(scene.board, args.section, y, 10, y);
    texture_name = spec.image.empty() ? "soccer" : spec.image;
  }
  object.texture = scene::SurfaceTexture(ReadImage(scene::ResolveStimulus(texture_name)));
  object.brightness = args.brightness;
  object.contrast = args.contrast;

  auto context = render::GlContext::CreateOffscreen();
  render::SceneRenderer renderer(scene.camera, scene.rvec, scene.tvec);
  const scene::Footprint f = renderer.Measure(object);
  // An object outside the photo would leave the photo as it was, written as if it were the stimulus.
  if ((f.bounds & cv::Rect(0, 0, photo.cols, photo.rows)).empty())
    throw Error(ErrorKind::kUsage, "the " + args.object + " at --at-edge " + std::to_string(args.edge) +
                                       " lies outside the " + std::to_string(photo.cols) + "x" +
                                       std::to_string(photo.rows) + " photo; nothing would be drawn");
  const cv::Vec3d centre = scene.ToCamera(object.center_board_mm);
  const double r = args.gain * calib::BlurAtPx(scene, source, centre, fixed_r);
  // One radius serves while the object's depth span changes r by less than half a pixel (a session's default
  // content.depth_blur_threshold; here the image is the photo, so photo px are screen px).
  auto at_depth = [&](double z) { return args.gain * calib::BlurAlongSightPx(scene, source, centre, z, fixed_r); };
  const double r_far = at_depth(f.z_max_mm), r_near = at_depth(f.z_min_mm);
  // Say which option made an impossible radius before the blur refuses it without knowing why.
  for (const double v : {r, r_far, r_near})
    if (!(v >= 0 && v <= render::kMaxBlurRadiusPx))
      throw Error(ErrorKind::kUsage, "--blur " + args.blur + " x --gain " + BoundText(args.gain) + " gives " +
                                         BoundText(v) + " px at the object" + calib::BlurFrom(scene, source) +
                                         "; the blur radius must be in [0, " + BoundText(render::kMaxBlurRadiusPx) +
                                         "] px");
  const double span = std::abs(r_far - r_near);
  // Model no more than the scene needs: one radius while the object's depth span changes r by < 0.5 px,
  // a per-pixel radius from depth where it does.
  const bool varying = span >= 0.5;
  render::Layer layer = renderer.Draw(object, render::KernelMarginPx(args.method, std::max({r, r_far, r_near})) + 1);
  std::unique_ptr<render::GlBlur> gl;
  if (args.backend == "gl") gl = std::make_unique<render::GlBlur>();
  if (varying)
    render::BlurLayerVarying(layer, args.method, at_depth, gl.get());
  else
    render::BlurLayer(layer, args.method, r, gl.get());
  cv::Mat background = DecodeSrgb8(photo);
  render::CompositeOver(background, layer);
  cv::Mat out = EncodeSrgb8(background);
  if (args.display_width > 0 && args.display_width != out.cols) {
    cv::Mat scaled;
    cv::resize(out, scaled, cv::Size(args.display_width, int(std::lround(double(out.rows) * args.display_width /
                                                                          out.cols))),
               0, 0, cv::INTER_AREA);
    out = scaled;
  }
  WriteImage(args.out, out);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%s at edge %d: depth %.1f mm, blur %s x %.2f = %.2f px (%s, %s); layer %dx%d of %dx%d -> %s in %.0f ms\n",
              args.object.c_str(), args.edge, f.z_center_mm, ToString(source).c_str(), args.gain, r,
              args.method.c_str(), args.backend.c_str(), layer.roi.width, layer.roi.height, photo.cols, photo.rows,
              args.out.c_str(), ms);
  if (varying)
    std::printf("its depth span changes r from %.2f to %.2f px: blurred per pixel by depth\n", r_near, r_far);
  if (const std::string note = calib::UndeterminedNote(scene, source, centre[2]); !note.empty())
    std::printf("note: %s\n", note.c_str());
  if (const std::string note = calib::PooledNote(scene, source, calib::NearestEdge(scene, centre)); !note.empty())
    std::printf("note: %s\n", note.c_str());
}

}  // namespace

void AddRenderCommand(CLI::App& app) {
  using Args = RenderArgs;
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "render",
      "Composite one virtual object over the scene photo with the blur the scene calls for at its depth.\n"
      "  --object grid          a 50 mm card with a 5x5 grid lying on the table right of the board (test 1)\n"
      "  --object ball[:TEX]    a 10 mm-radius ball resting on the board (tests 2 and 3); TEX = soccer (default),\n"
      "                         wood, or an image file (equirectangular)\n"
      "  --object picture[:IMG] the depth-matching study's frame (thesis 3.2): the picture (default: the face) low-\n"
      "                         passed by a 2nd-order Butterworth at --cutoff (cycles per picture width) on a grey\n"
      "                         upper half, the scene photo in the lower half; 960 x 720 unless --display-width\n"
      "  --blur none|measured|measured_section|estimated|fitted|R\n"
      "      measured: the edge's value, the mean r of its usable sections and of those calibrate pools into the\n"
      "      lens fit (phase.joins_fit; thesis Fig. 4.11), for the edge whose line passes nearest the object (refused\n"
      "      when that edge has neither: calibrate's table shows '-' there); measured_section: r of the\n"
      "      nearest section alone (refused when it is not usable); fitted (the default): the model calibrate\n"
      "      chose from all sections (thin lens, or thin lens + the lens's floor of blur), the blur the photo shows at\n"
      "      the object's depth;\n"
      "      estimated: eq. 3.7 from the reference edge, as the thesis published it (it takes the reference's whole\n"
      "      blur for defocus: with a lens floor there it draws too much blur elsewhere; calibrate prints its error);\n"
      "      R: a fixed radius in px. --gain scales it.\n"
      "Only the object's pixels plus the kernel's margin are blurred; everything happens in linear light.\n"
      "Example: blurcue render --calib calib.json --background scene.png --object ball --at-edge 9 --blur fitted\n"
      "         --out ball-e9.png");
  cmd->add_option("--calib", args->calib, "calib.json from blurcue calibrate (not needed for a picture)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--background", args->background, "the scene photo (same camera)")->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--object", args->object, "grid, ball[:TEXTURE] or picture[:IMAGE]")->capture_default_str();
  cmd->add_option("--at-edge", args->edge, "edge the object is aligned with (1 = nearest)")->capture_default_str()
      ->transform(IntRange(1, 1000));
  cmd->add_option("--section", args->section, "section along the edge for a ball (1..7)")->capture_default_str()
      ->transform(IntRange(1, 1000));
  cmd->add_option("--blur", args->blur, "blur source")->capture_default_str();
  cmd->add_option("--gain", args->gain, "multiplies the radius")->capture_default_str()->check(FiniteRange(0, 100, ""));
  cmd->add_option("--method", args->method, "gaussian or disc")->capture_default_str()
      ->check(OneOf({"gaussian", "disc"}));
  cmd->add_option("--brightness", args->brightness, "multiplies the object's linear colour")->capture_default_str()
      ->check(FiniteRange(0, 100, ""));
  cmd->add_option("--contrast", args->contrast, "scales the object's texture around mid grey")->capture_default_str()
      ->check(FiniteRange(0, 100, ""));
  cmd->add_option("--backend", args->backend, "blur on gl or cpu")->capture_default_str()
      ->check(OneOf({"gl", "cpu"}));
  cmd->add_option("--display-width", args->display_width,
                  "scale the output to this width (0 = full resolution; else a display's width, " +
                      std::to_string(display::kMinWidthPx) + " to " + std::to_string(display::kMaxWidthPx) + " px)")
      ->transform(IntRange(0, display::kMaxWidthPx, "px"))
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            const int w = std::atoi(text.c_str());
            if (w == 0 || w >= display::kMinWidthPx) return "";
            return "must be 0 (the photo's own width) or a display's width, " + std::to_string(display::kMinWidthPx) +
                   " to " + std::to_string(display::kMaxWidthPx) + " px (a display profile's width_px range), got " +
                   text;
          },
          ""));
  cmd->add_option("--cutoff", args->cutoff, "picture: Butterworth cut-off, cycles per picture width (0 = sharp)")
      ->check(FiniteRange(0, render::kMaxCutoffCyclesPerWidth, "cycles per picture width"));
  cmd->add_option("--picture-height-px", args->picture_height, "picture: its height on screen (default 60 % of the "
                                                                "grey half)")
      ->transform(IntRange(0, 7680, "px"));
  cmd->add_option("--out", args->out, "output PNG")->required();
  cmd->callback([args, cmd] {
    const auto t0 = std::chrono::steady_clock::now();
    RequireOptionsOf(ParseObject(args->object).kind, [cmd](const std::string& o) { return cmd->count(o) > 0; });
    {
      OutputGuard guard;
      guard.Input("--background", args->background);
      if (!args->calib.empty()) guard.Input("--calib", args->calib);
      // A texture named by --object (ball:FILE, picture:FILE) is an input too.
      const size_t colon = args->object.find(':');
      if (colon != std::string::npos) {
        const std::filesystem::path texture = scene::ResolveStimulus(args->object.substr(colon + 1));
        if (std::filesystem::exists(texture)) guard.Input("--object", texture);
      }
      guard.OutputFile("--out", args->out).Check();
      RequireImageName("--out", args->out);
      // An image of another kind at its path (a protocol named .png, a JPEG named .png) is not replaced.
      RequireOwnFile("--out", args->out, "an image of the kind its name says", ImageOfExtension(args->out));
    }
    if (ParseObject(args->object).kind == "picture") return RenderPicture(*args);
    RenderObject(*args, t0);
  });
}

}  // namespace blurcue::cli
