// blurcue init: a study folder that validates and runs at once - protocol, scene, calibration and next steps.
#include <sys/wait.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli/child.h"
#include "cli/commands.h"
#include "core/atomic_file.h"
#include "core/camera_exif.h"
#include "core/data_dir.h"
#include "core/error.h"
#include "core/image.h"
#include "core/output_guard.h"
#include "core/names.h"
#include "core/typed.h"

namespace blurcue::cli {
namespace {

namespace fs = std::filesystem;

struct InitArgs {
  std::string dir;
  std::string from = "test1-static-grids";
  std::string photo, camera, board_free;
  int seed = 7;
};

// The shipped examples: protocols/*.json beside the binary (installed) or in the source tree.
std::vector<std::string> Examples() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(DataDir().path / "protocols", ec))
    if (entry.path().extension() == ".json" && entry.path().stem() != "protocol.schema")
      names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "cannot open file");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs this blurcue with `args` in the folder being built (`cwd`: paths in `args` are relative to it, and so are
// those the step records, e.g. calib.json's "photo"); a failure stops init naming the step and says that `dir` was
// not made.
void Step(const std::string& what, std::vector<std::string> args, const fs::path& cwd, const fs::path& dir) {
  std::cout << "init: " << what << "\n";
  args.insert(args.begin(), ExecutablePath().string());
  const int status = RunChild(args, cwd.string());
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 10;
  // The step's own kind passes on (no board in your photo: 4), except that its command line is init's making, so
  // a usage error there is a problem of the files given (3); a crash or a kill stays internal.
  const ErrorKind kind = code == 2 || code == 3 ? ErrorKind::kInput
                         : code == 4            ? ErrorKind::kNotFound
                         : code == 5            ? ErrorKind::kDomain
                                                : ErrorKind::kInternal;
  throw Error(kind,
              "init: " + what + " failed (exit " + std::to_string(code) + "); " + dir.string() +
                  " was not made (or is left as it was)");
}

// The ground-truth take a video example's study folder gets (scripts/demo.sh makes the same one for the shipped
// protocol): the lens focused inside the board at 340 mm, the camera moving 40 mm closer and 30 mm sideways.
const std::vector<std::string> kExampleTake = {"--frames", "5", "--supersample", "2", "--noise", "0.004",
                                               "--from-u-mm", "320", "--to-u-mm", "280", "--focus-mm", "340",
                                               "--from-lateral-mm", "-15", "--to-lateral-mm", "15"};

std::string NextSteps(const std::string& example, const std::string& study, bool synthetic, bool video) {
  std::ostringstream s;
  s << "# " << study << "\n\n"
    << "A study folder made by `blurcue init` from the shipped example `" << example << "`.\n\n"
    << "| file | what it is |\n|---|---|\n"
    << "| `protocol.json` | the study: what each trial shows and asks (see `blurcue validate --help` and the protocol "
       "reference, `protocols/README.md` in blurcue's share folder) |\n"
    << "| `protocol.schema.json` | the protocol's JSON Schema, which its `$schema` names: an editor that reads it "
       "completes and checks the fields as you type |\n";
  if (video)
    s << "| `take/` | the video the trials are drawn on (`take.avi`, its frames and `camera.json`; a ground-truth take "
         "made by `blurcue synth-take`: replace it with your own video of the printed board) |\n"
      << "| `track/` | the take tracked by `blurcue track`: each frame's pose and blur (`calib-NNNN.json`, `track.csv`) "
         "|\n\n";
  else
    s << "| `scene/` | the scene photo and `camera.json`" << (synthetic ? " (a ground-truth scene made by `blurcue "
         "synth-scene`: replace it with your own photo of the printed board and `blurcue camera PHOTO` for its "
         "camera.json)" : "") << " |\n"
      << "| `calib.json` | the scene's blur, measured and modelled by `blurcue calibrate` |\n\n";
  s
    << "## Next steps\n\n```sh\n"
    << "blurcue validate protocol.json                  # every problem at once, or the trial count\n"
    << "blurcue preview protocol.json --out sheet.png   # every distinct stimulus, to look at\n"
    << "blurcue run protocol.json --participant S1 --observer sim --db record.sqlite   # a simulated observer, headless\n"
    << "blurcue run protocol.json --participant P1 --db record.sqlite                  # a person, in a window\n"
    << "blurcue export --db record.sqlite --out tables  # trials.csv, codebook.csv, ...\n"
    << "blurcue report --db record.sqlite --out report  # report/index.html\n"
    << "```\n\n"
    << (video ? "The take with virtual objects of your own, outside a study (the thesis's prototype, on video): "
                "`blurcue ar take/take.avi --track track --ball 87.5,125 --card 60,150,40 --out ar.avi` (each frame's "
                "objects in ar.csv).\n\n"
                "With your own video: write its camera.json by hand (focal length, f-number, the sensor area the video "
                "mode uses, the frame size, and `exposure_ms` if the camera states its shutter time: docs/running.md), "
                "then `blurcue track my.avi --camera camera.json --out track`, and point `scene.video` "
                "and `scene.track` in protocol.json at them.\n"
              : "With your own photo: `blurcue camera photo.jpg --out scene/camera.json`, then `blurcue calibrate "
                "photo.jpg --camera scene/camera.json --out calib.json`, and point `scene.background` in protocol.json "
                "at the photo.\n");
  return s.str();
}

// Makes the study in `root` (empty, the folder being built; `dir` is where it goes, for messages): the protocol
// `text` with its paths pointing into the folder, the scene or take, its calibration or track, and the README.
// Children run inside `root` with paths relative to it.
void Fill(const InitArgs& args, std::string text, bool video, const fs::path& root, const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(root / (video ? "take" : "scene"), ec);
  if (ec) throw InputError(dir.string(), "cannot make the folder: " + ec.message());
  // The protocol: the example's text with its demo paths pointing into this folder (relative to the protocol).
  const std::string demo = "../results/demo/";
  for (size_t at = text.find(demo); at != std::string::npos; at = text.find(demo, at)) text.erase(at, demo.size());
  const bool pictures = text.find("\"pictures/") != std::string::npos;
  // The shipped stimuli it names ("../stimuli/face.png") are copied in, so the folder stands on its own.
  const std::string shipped = "\"../stimuli/";
  for (size_t at = text.find(shipped); at != std::string::npos; at = text.find(shipped, at)) {
    const size_t end = text.find('"', at + shipped.size());
    const std::string name = text.substr(at + shipped.size(), end - at - shipped.size());
    fs::create_directories(root / "stimuli", ec);
    fs::copy_file(DataDir().path / "stimuli" / name, root / "stimuli" / name, fs::copy_options::skip_existing, ec);
    if (ec)
      throw InputError((DataDir().path / "stimuli" / name).string(),
                       "cannot copy into " + dir.string() + ": " + ec.message());
    text.replace(at, shipped.size(), "\"stimuli/");
  }

  fs::path photo = "scene/scene.png";
  const std::string seed = std::to_string(args.seed);
  if (video) {
    std::vector<std::string> synth = {"synth-take", "--out", "take", "--seed", seed, "--quiet"};
    synth.insert(synth.end(), kExampleTake.begin(), kExampleTake.end());
    Step("a ground-truth take (synth-take, seed " + seed + ")", synth, root, dir);
    Step("the take tracked (track)",
         {"track", "take/take.avi", "--camera", "take/camera.json", "--out", "track", "--quiet"}, root, dir);
  } else if (args.photo.empty()) {
    Step("a ground-truth scene (synth-scene, seed " + seed + ")",
         {"synth-scene", "--out", "scene", "--seed", seed, "--noise", "0.004"}, root, dir);
  } else {
    // Your photo under its own name; the board-free one (when given) as scene-no-board with its own extension.
    photo = fs::path("scene") / fs::path(args.photo).filename();
    fs::copy_file(args.photo, root / photo, ec);
    if (!ec && !args.camera.empty()) fs::copy_file(args.camera, root / "scene" / "camera.json", ec);
    if (ec) throw InputError(args.photo, "cannot copy into " + dir.string() + ": " + ec.message());
    auto replace_all = [&text](const std::string& from, const std::string& to) {
      for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
        text.replace(at, from.size(), to);
    };
    const std::string no_board = "\"scene/scene-no-board.png\"";
    if (!args.board_free.empty()) {
      const fs::path board_free = fs::path("scene") / ("scene-no-board" + fs::path(args.board_free).extension().string());
      fs::copy_file(args.board_free, root / board_free, fs::copy_options::overwrite_existing, ec);
      if (ec) throw InputError(args.board_free, "cannot copy into " + dir.string() + ": " + ec.message());
      replace_all(no_board, "\"" + board_free.string() + "\"");
    } else if (const size_t at = text.find("\"board_free\": " + no_board + ","); at != std::string::npos) {
      // No board-free photo of yours: the example names one it does not show, so the line goes.
      const size_t line = text.rfind('\n', at), next = text.find('\n', at);
      text.erase(line, next - line);
    }
    if (args.camera.empty())
      Step("camera.json from the photo's EXIF", {"camera", photo.string(), "--out", "scene/camera.json"}, root, dir);
    replace_all("\"scene/scene.png\"", "\"" + photo.string() + "\"");
  }
  if (!video)
    Step("calibration (calibrate)",
         {"calibrate", photo.string(), "--camera", "scene/camera.json", "--out", "calib.json"}, root, dir);
  WriteFileAtomically(root / "protocol.json", text);
  // The schema its "$schema" names, beside it: an editor that reads it completes and checks the fields as typed.
  fs::copy_file(DataDir().path / "protocols" / "protocol.schema.json", root / "protocol.schema.json", ec);
  if (ec) throw InputError(dir.string(), "cannot copy protocol.schema.json into it: " + ec.message());
  if (pictures)
    Step("the real pictures at each distance (synth-pictures)",
         {"synth-pictures", "--protocol", "protocol.json", "--out", "pictures"}, root, dir);
  WriteFileAtomically(root / "README.md", NextSteps(args.from, dir.filename().string(), args.photo.empty(), video));
  Step("validate", {"validate", "protocol.json"}, root, dir);
}

}  // namespace

void AddInitCommand(CLI::App& app) {
  auto args = std::make_shared<InitArgs>();
  std::string examples;
  for (const std::string& name : Examples()) examples += "\n  " + name;
  CLI::App* cmd = app.add_subcommand(
      "init",
      "Make a study folder that validates and runs at once: a protocol from a shipped example, a scene, its\n"
      "calibration, and a README of next steps.\n"
      "Without --photo the scene is a ground-truth one made by synth-scene (the thesis's set-up; --seed), so a lab\n"
      "with no photo yet can preview and run the study; with --photo (and --camera, or the photo's EXIF) it is\n"
      "yours. A study on a video (video-ball-depth) gets a ground-truth take instead (synth-take, tracked by\n"
      "track: take/ and track/). DIR must not exist or be empty: init never overwrites. The folder is built\n"
      "beside DIR and moved into place when every step has passed: a failed or killed init leaves no DIR (the\n"
      "next init removes what a killed one left). Example:\n"
      "  blurcue init my-study --from yes-no-ball && cd my-study && blurcue validate protocol.json\n"
      "Examples shipped (--from):" + examples);
  cmd->add_option("dir", args->dir, "the study folder to make")->required();
  cmd->add_option("--from", args->from, "the shipped example to start from")->capture_default_str();
  cmd->add_option("--photo", args->photo, "your scene photo with the printed board (default: a synthetic scene)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--camera", args->camera, "the photo's camera.json (default: from its EXIF, blurcue camera)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--board-free", args->board_free,
                  "with --photo: the same view without the board, for an example that shows it (test3-no-board);\n"
                  "without it such an example is refused, and the others get no scene.board_free")
      ->check(CLI::ExistingFile);
  cmd->add_option("--seed", args->seed, "the synthetic scene's seed (recorded in scene/truth.json)")
      ->capture_default_str()->check(IntRange(0, 2147483647));
  cmd->callback([args] {
    const std::vector<std::string> examples = Examples();
    if (std::find(examples.begin(), examples.end(), args->from) == examples.end())
      throw Error(ErrorKind::kUsage, "--from: no shipped example " + Echo(args->from) +
                                         DidYouMean(args->from, examples) + "; 'blurcue init --help' lists them");
    if (!args->camera.empty() && args->photo.empty())
      throw Error(ErrorKind::kUsage, "--camera: goes with --photo (a synthetic scene has its own camera)");
    const fs::path dir = args->dir;
    const fs::path example = DataDir().path / "protocols" / (args->from + ".json");
    std::string text = ReadText(example);
    // A study on a video: its scene is a take and the track folder, made here by synth-take and track.
    const bool video = text.find("\"video\":") != std::string::npos;
    if (video && !args->photo.empty())
      throw Error(ErrorKind::kUsage, "--photo: " + args->from + " is a study on a video; init makes a ground-truth "
                                     "take for it (for your own, track it and point scene.video and scene.track at it)");
    if (!args->board_free.empty() && args->photo.empty())
      throw Error(ErrorKind::kUsage, "--board-free: goes with --photo (a synthetic scene has its own)");
    const bool shows_board_free = text.find("\"show\": \"board_free\"") != std::string::npos;
    if (shows_board_free && !args->photo.empty() && args->board_free.empty())
      throw Error(ErrorKind::kUsage, "--photo: " + args->from + " shows the scene without the board: give that "
                                     "photo too (--board-free), or start from another example");
    // Everything init needs is checked before anything is written: the folder's place, and your files (an image
    // that decodes, not a FIFO or /etc/passwd).
    {
      OutputGuard guard;
      if (!args->photo.empty()) guard.Input("--photo", args->photo);
      if (!args->camera.empty()) guard.Input("--camera", args->camera);
      if (!args->board_free.empty()) guard.Input("--board-free", args->board_free);
      guard.OutputFolder("DIR", dir).Check();
      for (const auto& [option, image] : {std::pair<std::string, std::string>{"--photo", args->photo},
                                          {"--board-free", args->board_free}}) {
        if (image.empty()) continue;
        try {
          ReadImage(image);
        } catch (const Error& e) {
          throw Error(ErrorKind::kInput, option + " " + OneLine(image) + ": not a readable image (" + e.what() + ")");
        }
      }
      // Without --camera, its camera.json comes from the photo's EXIF (blurcue camera): where that lacks a number,
      // say so now, and point to what init takes - the numbers' own options are camera's, not init's.
      if (!args->photo.empty() && args->camera.empty()) {
        try {
          CameraFromExif(args->photo);
        } catch (const Error& e) {
          const std::string what = e.what();
          throw Error(e.kind(), "--photo " + what.substr(0, what.find("; give ")) + "; give init --camera FILE, a "
                                "camera.json made by 'blurcue camera " + OneLine(args->photo) + " --focal-length-mm "
                                "F --f-number N --sensor-mm W H --out FILE' (those options are camera's)");
        }
      }
    }
    std::error_code ec;
    if (fs::exists(dir, ec) && !(fs::is_directory(dir, ec) && fs::is_empty(dir, ec)))
      throw InputError(dir.string(), "exists and is not an empty folder; init never overwrites: name a new folder");
    RemoveLeftoversBeside("init", dir);
    WriteFolderAtomically(dir, [&](const fs::path& partial) { Fill(*args, text, video, partial, dir); },
                          [](const std::string&) { return false; });
    std::cout << "init: " << dir.string() << " is ready; its README.md lists the next steps\n";
  });
}

}  // namespace blurcue::cli
