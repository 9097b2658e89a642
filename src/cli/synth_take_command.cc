// blurcue synth-take: a ground-truth moving-camera take (src/synth/take.h) rendered and written to a folder.
#include <chrono>
#include <regex>
#include <cstdio>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/scene_option_error.h"
#include "core/atomic_file.h"
#include "core/output_guard.h"
#include "core/error.h"
#include "synth/take.h"

namespace blurcue::cli {
void AddSynthTakeCommand(CLI::App& app) {
  struct Args {
    std::string out;
    uint64_t seed = 1;
    bool quiet = false;
    synth::TakeOptions o;
  };
  auto args = std::make_shared<Args>();
  synth::TakeOptions& o = args->o;
  CLI::App* cmd = app.add_subcommand(
      "synth-take",
      "Render a ground-truth moving-camera take: a fixed-focus lens on a camera moving closer to the board and\n"
      "sideways, so every frame's pose and blur are known. Use it to test and benchmark `blurcue track`.\n"
      "\n"
      "Each frame is a synth-scene still (the thesis set-up at 1148 x 764 px, 7x10 board of 25 mm squares, camera\n"
      "pitched down 38 deg, f = 21 mm at f/5.6) at its point of a straight path: edge 1's depth goes from\n"
      "--from-u-mm to --to-u-mm and the board's sideways offset from --from-lateral-mm to --to-lateral-mm, linear in\n"
      "the frame index. The lens stays focused at --focus-mm (inside the board by default, so blur grows both ways)\n"
      "and has a floor (--floor-sigma-px). The table's texture is the same in every frame; sensor noise is new.\n"
      "\n"
      "Writes to --out DIR:\n"
      "  frame-0000.png ...  the frames (8-bit sRGB): `blurcue track DIR/frame-%04d.png`\n"
      "  take.avi            the same frames as a video (FFV1 lossless where OpenCV's videoio has it, else MJPEG)\n"
      "  truth-0000.json ... each frame's truth in synth-scene's truth.json format (pose; per section u_mm and r_px,\n"
      "                      the applied kernels' second moments): `blurcue calibrate --truth` reads it\n"
      "  camera.json         the camera;  take.json: the options, fps, and every frame's time and pose\n"
      "Example: blurcue synth-take --out take --frames 12");
  cmd->add_option("--out", args->out, "folder to write the take to (created)")->required();
  cmd->add_option("--frames", o.frames, "number of frames")->capture_default_str()->transform(IntRange(1, 10000));
  cmd->add_option("--fps", o.fps, "frame rate, frames per second")->capture_default_str()
      ->check(FinitePositive(1000, "frames per second"));
  cmd->add_option("--from-u-mm", o.edge1_u_start_mm, "depth of edge 1's midpoint in the first frame, mm")
      ->capture_default_str()->check(FinitePositive(1e6, "mm"));
  cmd->add_option("--to-u-mm", o.edge1_u_end_mm, "... in the last frame, mm")->capture_default_str()
      ->check(FinitePositive(1e6, "mm"));
  cmd->add_option("--from-lateral-mm", o.lateral_start_mm, "board's sideways offset in the first frame, mm")
      ->capture_default_str()->check(FiniteRange(-1e4, 1e4, "mm"));
  cmd->add_option("--to-lateral-mm", o.lateral_end_mm, "... in the last frame, mm")->capture_default_str()
      ->check(FiniteRange(-1e4, 1e4, "mm"));
  cmd->add_option("--focus-mm", o.scene.focus_mm, "the lens's fixed focus distance, mm")->capture_default_str()
      ->check(FinitePositive(1e6, "mm"));
  cmd->add_option("--floor-sigma-px", o.scene.floor_sigma_px, "lens floor: every PSF convolved with a Gaussian of this std, px")
      ->capture_default_str()->check(FiniteRange(0, 20, "px"));
  cmd->add_option("--tilt-deg", o.scene.tilt_deg, "camera pitched down from the horizontal, degrees")
      ->capture_default_str()->check(FinitePositive(90, "degrees"));
  cmd->add_option("--noise", o.scene.noise_std, "sensor noise std in linear units, e.g. 0.004")->capture_default_str()
      ->check(FiniteRange(0, 1, "linear units"));
  cmd->add_option("--supersample", o.scene.supersample,
                  "sub-pixels per pixel side for shading and blur. 1 point-samples each pixel: no pixel aperture\n"
                  "and aliased edges, so blur measured on the frames reads off their truth near focus; 2 or more\n"
                  "for a ground truth")
      ->capture_default_str()->transform(IntRange(1, 16));
  cmd->add_option("--seed", args->seed, "seed of the texture and noise")->capture_default_str()
      ->transform(SeedValidator());
  cmd->add_flag("--quiet", args->quiet, "print only errors");
  cmd->callback([args] {
    const auto t0 = std::chrono::steady_clock::now();
    OutputGuard().OutputFolder("--out", args->out).Check();
    // A folder of one's own camera.json or frame-NNNN.png images alone passed as a take's files and was replaced.
    RequireMarkedFolder("--out", args->out, "take.json", "a take synth-take wrote", "one's own camera.json or frames?");
    synth::TakeOptions o = args->o;
    o.scene.seed = args->seed;
    auto progress = [&](const std::string& line) {
      if (!args->quiet) std::fprintf(stderr, "%s\n", line.c_str());
    };
    synth::TakeFiles files;
    // The take is built beside --out and swapped in whole: a shorter take over a longer one left its old frames
    // behind it (a 5-frame folder read back as a mix). A folder of anything but a take's files is refused.
    auto ours = [](const std::string& name) {
      static const std::regex kTakeFile(R"((frame-\d{4}\.png|truth-\d{4}\.json|take\.(avi|json)|camera\.json))");
      return std::regex_match(name, kTakeFile);
    };
    try {
      WriteFolderAtomically(
          args->out, [&](const std::filesystem::path& partial) { files = synth::WriteTake(o, partial, progress); },
          ours);
    } catch (const Error& e) {
      // The take's own fields, and the still's path fields as the take's path options.
      throw AsSceneOptionError(e, {{"frames", "--frames"}, {"fps", "--fps"},
                                   {"edge1_u_mm", "--from-u-mm/--to-u-mm"},
                                   {"lateral_mm", "--from-lateral-mm/--to-lateral-mm"},
                                   {"edge1_u_start_mm", "--from-u-mm"}, {"edge1_u_end_mm", "--to-u-mm"},
                                   {"lateral_start_mm", "--from-lateral-mm"}, {"lateral_end_mm", "--to-lateral-mm"}});
    }
    if (args->quiet) return;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("wrote %d frames (%s) to %s in %.1f s%s\n", files.frames, synth::kTakeFramePattern, args->out.c_str(), s,
                files.video.empty() ? "; no video: OpenCV's videoio could not open a writer"
                                    : (" and " + std::filesystem::path(files.video).filename().string() + " (" +
                                       files.video_codec + ")").c_str());
  });
}

}  // namespace blurcue::cli
