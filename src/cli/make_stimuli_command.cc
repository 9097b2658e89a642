#include <cstdio>
#include <memory>
#include <string>

#include <filesystem>
#include <map>
#include <set>
#include <vector>

#include "cli/commands.h"
#include "core/atomic_file.h"
#include "core/output_guard.h"
#include "core/own_output.h"
#include "core/camera.h"
#include "core/error.h"
#include "core/image.h"
#include "protocol/protocol.h"
#include "render/real_picture.h"
#include "scene/stimuli.h"

namespace blurcue::cli {
namespace {

// A scratch folder removed however the command ends.
struct RemovedWhenDone {
  std::filesystem::path path;
  ~RemovedWhenDone() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

}  // namespace

void AddMakeStimuliCommand(CLI::App& app) {
  auto out = std::make_shared<std::string>("stimuli");
  CLI::App* cmd = app.add_subcommand(
      "make-stimuli",
      "Draw the study's stimulus textures (procedural, deterministic, 8-bit sRGB PNG). Into --out:\n"
      "  soccer.png  2048 x 1024 equirectangular soccer ball (truncated icosahedron) for the balls of tests 2-3\n"
      "  wood.png    2048 x 1024 equirectangular wood grain (seed 1), the alternative ball texture\n"
      "  grid.png    1024 x 1024 white card with a 5 x 5 black grid, the virtual content of test 1\n"
      "  face.png    800 x 1200 face picture with alpha, the pre-research's depth-matching content\n"
      "Example: blurcue make-stimuli --out stimuli");
  cmd->add_option("--out", *out, "folder to write into (created if needed); a file of the same name there is\n"
                                  "replaced only when make-stimuli wrote it (OUT/make-stimuli.txt lists it)")
      ->capture_default_str();
  cmd->callback([out] {
    OutputGuard().OutputFolder("--out", *out).Check();
    RemoveLeftoversBeside("make-stimuli", *out);
    // Drawn into a folder of its own beside OUT, then moved in: OUT may hold one's own pictures under the same
    // names (face.png), which are refused before any file is replaced.
    const std::filesystem::path partial = TemporaryBeside(*out, "partial");
    std::error_code ignored;
    std::filesystem::remove_all(partial, ignored);
    std::filesystem::create_directories(partial, ignored);
    const RemovedWhenDone remove_partial{partial};
    scene::WriteStandardStimuli(partial);
    for (const auto& file : PlaceOwnFiles("--out", *out, partial, "make-stimuli.txt", "make-stimuli"))
      std::printf("wrote %s\n", file.string().c_str());
  });
}

void AddSynthPicturesCommand(CLI::App& app) {
  struct Args {
    std::string camera, protocol, out, picture = "face";
    std::vector<double> distances_m;
    double focus_m = 1.0, height_mm = 120, grey = 0.18;
    int width_px = 960;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "synth-pictures",
      "Make photos of the depth-matching study's real picture at each distance with the thin lens, to try the study\n"
      "without a photo session. The picture (8 x 12 cm by default) faces the camera at distance d,\n"
      "imaged at magnification f / (d - f), blurred by the thin-lens disc for the lens focused at --focus-m, on a\n"
      "grey wall. Writes OUT/PICTURE-{d}m.png (d as %g) at --width-px wide with the camera's aspect, the names a\n"
      "protocol's content.real_photos pattern (e.g. \"pictures/face-{distance_m}m.png\") finds. With --protocol, the\n"
      "camera and focus default to its content.real_camera (the ones its trials record the real blur from).\n"
      "Example: blurcue synth-pictures --camera results/demo/scene/camera.json\n"
      "         --protocol protocols/pre-research-depth-matching.json --out results/demo/pictures");
  cmd->add_option("--camera", args->camera, "camera.json (f, f-number, sensor); default: the protocol's real_camera")
      ->check(CLI::ExistingFile);
  cmd->add_option("--protocol", args->protocol, "take the distances from this protocol's distance_m levels")
      ->check(CLI::ExistingFile);
  cmd->add_option("--distances-m", args->distances_m, "distances (m), instead of --protocol")
      ->check(FinitePositive(1000, "m"));
  CLI::Option* focus = cmd->add_option("--focus-m", args->focus_m, "focus distance (m); default: the protocol's "
                                                                    "real_camera focus_m, else 1")
                           ->check(FinitePositive(1000, "m"));
  cmd->add_option("--picture", args->picture, "face or an image with alpha")->capture_default_str();
  cmd->add_option("--height-mm", args->height_mm, "the real picture's height")->capture_default_str()
      ->check(FinitePositive(10000, "mm"));
  cmd->add_option("--width-px", args->width_px, "photo width (the camera's sensor scaled to it)")
      ->capture_default_str()->transform(IntRange(16, 16384, "px"));
  cmd->add_option("--out", args->out, "folder (created); a photo of the same name there is replaced only\n"
                                      "when synth-pictures wrote it (OUT/synth-pictures.txt lists it): real photos are\n"
                                      "refused")
      ->required();
  cmd->callback([args, focus] {
    {
      OutputGuard guard;
      if (!args->camera.empty()) guard.Input("--camera", args->camera);
      if (!args->protocol.empty()) guard.Input("--protocol", args->protocol);
      guard.OutputFolder("--out", args->out).Check();
    }
    std::set<double> distances;
    for (double d : args->distances_m)
      if (!distances.insert(d).second)
        throw Error(ErrorKind::kUsage, "--distances-m " + BoundText(d) + " is given twice; each distance is one photo");
    bool focus_from_protocol = false;
    if (!args->protocol.empty()) {
      protocol::ValidateOptions no_files;
      no_files.check_files = false;  // its real_photos may be what we are about to write
      const protocol::Protocol p = protocol::LoadProtocol(args->protocol, no_files);
      distances.merge(protocol::NumericLevels(p, "distance_m"));
      if (args->camera.empty()) args->camera = p.content.real_camera_file.string();
      if (!focus->count() && p.content.real_focus_m > 0) args->focus_m = p.content.real_focus_m, focus_from_protocol = true;
    }
    if (distances.empty()) throw Error(ErrorKind::kUsage, "give --distances-m or a --protocol with distance_m levels");
    if (args->camera.empty())
      throw Error(ErrorKind::kUsage, "give --camera, or a --protocol whose content.real_camera names one");
    const Camera camera = LoadCamera(args->camera);
    const Camera scaled = camera.Resized(args->width_px, int(std::lround(double(args->width_px) *
                                                                          camera.image_height_px /
                                                                          camera.image_width_px)));
    const cv::Mat picture = ReadImage(scene::ResolveStimulus(args->picture), -1);
    const std::string stem = std::filesystem::path(args->picture).stem().string();
    // Each distance's file name, told apart: %g keeps 6 digits, so 1 and 1.0000001 would write one file.
    std::map<std::string, double> named;
    for (double d : distances) {
      char name[64];
      std::snprintf(name, sizeof name, "%s-%gm.png", stem.c_str(), d);
      if (const auto [at, fresh] = named.emplace(name, d); !fresh)
        throw Error(ErrorKind::kUsage, "distances " + BoundText(at->second) + " and " + BoundText(d) + " m both "
                                       "name " + name + " (its name keeps 6 digits); give distances apart");
    }
    RemoveLeftoversBeside("synth-pictures", args->out);
    // Made in a folder of its own beside OUT, then moved in: OUT may hold real photos of the same names (a
    // protocol's real_photos), which are refused before any file is replaced.
    const std::filesystem::path partial = TemporaryBeside(args->out, "partial");
    std::error_code ignored;
    std::filesystem::remove_all(partial, ignored);
    std::filesystem::create_directories(partial, ignored);
    const RemovedWhenDone remove_partial{partial};
    for (const auto& [name, d] : named) {
      const auto path = partial / name;
      cv::Mat photo;
      try {
        photo = render::RealPicturePhoto(picture, scaled, args->focus_m * 1000, d * 1000, args->height_mm, args->grey);
      } catch (const Error& e) {
        // A focus, distance or size the thin lens cannot image: the field or option that chose it.
        if (e.kind() != ErrorKind::kDomain) throw;
        if (focus_from_protocol) throw InputError(args->protocol + ": /content/real_camera", e.what());
        throw Error(ErrorKind::kDomain, "--focus-m, --distances-m or --height-mm: " + std::string(e.what()));
      }
      WriteImage(path, photo);
    }
    PlaceOwnFiles("--out", args->out, partial, "synth-pictures.txt", "synth-pictures");
    std::printf("wrote %zu photo%s (%s, %dx%d, focus %g m) to %s\n", named.size(), named.size() == 1 ? "" : "s",
                stem.c_str(), scaled.image_width_px, scaled.image_height_px, args->focus_m, args->out.c_str());
  });
}

}  // namespace blurcue::cli
