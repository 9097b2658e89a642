// blurcue preview: a contact sheet of every distinct stimulus of a protocol, to check it by eye before any
// participant sits down.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "cli/commands.h"
#include "cli/groups.h"
#include "core/image.h"
#include "core/output_guard.h"
#include "core/own_output.h"
#include "preview/preview.h"
#include "procedure/observer.h"
#include "procedure/prepare.h"

namespace blurcue::cli {

void AddPreviewCommand(CLI::App& app) {
  struct Args {
    std::string protocol, out, participant = "P1", display, observer = "sim", group;
    std::optional<uint64_t> seed;
    int columns = 6, tile_width = 320, zoom = 1;
    double visible = 0.75;
    bool list = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "preview",
      "Draw a contact sheet of every distinct stimulus a protocol shows, to check the protocol by eye before a session.\n"
      "Each is drawn at its onset, as the window shows it, labelled with its levels, the blur radius on each side in\n"
      "photo px, screen px and arcmin, and its blur plan (one radius, or per pixel by depth where the object's depth\n"
      "span changes r by the protocol's content.depth_blur_threshold) with what a frame of it costs to compose here.\n"
      "Distinct: the same levels and sides drawn once (practice copies and repetitions are not repeated); for\n"
      "depth matching, one tile per adjustment level and one per distance.\n"
      "Each pair's tile says the probability that an observer (--observer's model, no lapses or bias) tells its two\n"
      "sides apart on the display (--display) in a 2AFC; below --visible it is flagged invisible, and every distinct\n"
      "pair is listed so (as blurcue validate --plan).\n"
      "A protocol with between-subject groups gets each group's tiles (labelled with the group), or only --group's.\n"
      "Each tile shows the whole frame (scaled to --tile-width) and, beside it, every object at 1:1 screen scale\n"
      "(each screen px one sheet px, or --zoom sheet px, never resampled), so a blur of 1-2 screen px is seen as a\n"
      "participant sees it; a frame no wider than --tile-width is shown whole at 1:1. Labels are wrapped to the tile.\n"
      "Example: blurcue preview protocols/test1-static-grids.json --out results/preview-test1.png");
  cmd->add_option("protocol", args->protocol, "the protocol JSON file")->required();  // missing: exit 3, as validate
  cmd->add_option("--out", args->out, "the contact sheet PNG")->required();
  cmd->add_option("--participant", args->participant, "whose trial list (by_participant sides)")
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "seed (default: as blurcue run)")->transform(SeedValidator());
  cmd->add_option("--group", args->group, "a protocol with groups: only this group's tiles (default: every group's)");
  cmd->add_flag("--list", args->list, "also print each tile's label (its levels, each side's source and radius in "
                                      "photo px, screen px and arcmin), one line per tile");
  cmd->add_option("--display", args->display, "the monitor's display profile, as blurcue run --display")
      ->check(CLI::ExistingFile);
  cmd->add_option("--observer", args->observer, "the observer model that predicts what is visible, as blurcue run "
                                                "--observer")->capture_default_str();
  cmd->add_option("--visible", args->visible, "the predicted share correct (2AFC) below which a pair is flagged "
                                              "invisible")
      ->capture_default_str()->check(FiniteRange(0.5, 1, "share correct"));
  cmd->add_option("--columns", args->columns, "tiles per row")->capture_default_str()->transform(IntRange(1, 20));
  cmd->add_option("--tile-width", args->tile_width, "width of each tile's whole frame in px (a frame this wide or "
                                                    "narrower is shown at 1:1)")->capture_default_str()
      ->transform(IntRange(80, 2000, "px"));
  cmd->add_option("--zoom", args->zoom, "sheet px per screen px in the 1:1 insets (nearest neighbour: each screen px "
                                        "becomes a square of this many)")->capture_default_str()
      ->transform(IntRange(1, 8));
  cmd->callback([args] {
    {
      OutputGuard guard;
      guard.Input("PROTOCOL", args->protocol);
      if (!args->display.empty()) guard.Input("--display", args->display);
      guard.OutputFile("--out", args->out).Check();
      RequireImageName("--out", args->out);
      // An image of another kind at its path (a protocol named .png, a JPEG named .png) is not replaced.
      RequireOwnFile("--out", args->out, "an image of the kind its name says", ImageOfExtension(args->out));
    }
    // The pre-flight of blurcue run: the same checks, and every trial's scene already worked out.
    preview::SheetOptions options;
    options.observer = procedure::ParseObserver(args->observer);
    procedure::PreparedSession prepared = procedure::PrepareStudy(args->protocol, args->display);
    {
      // The files the protocol names are inputs too (its photo overwritten by the sheet was exit 0): checked once the
      // protocol is read, still before any drawing.
      const protocol::Scene& files = prepared.protocol.scene;
      OutputGuard guard;
      for (const auto& [name, path] : {std::pair{"scene.background", files.background},
                                        {"scene.board_free", files.board_free}, {"scene.calib", files.calib},
                                        {"scene.video", files.video}, {"scene.track", files.track},
                                        {"content.image", prepared.protocol.content.image}})
        if (!path.empty() && std::filesystem::exists(path)) guard.Input(std::string("the protocol's ") + name, path);
      guard.OutputFile("--out", args->out).Check();
      RequireImageName("--out", args->out);
    }
    options.groups = GroupsToCheck(prepared.protocol, args->group);
    options.participant = args->participant;
    options.seed = args->seed;
    options.visible = args->visible;
    options.columns = args->columns;
    options.tile_width_px = args->tile_width;
    options.zoom = args->zoom;
    const bool tty = isatty(2);  // a terminal gets a progress line; a log only the summary
    const preview::Sheet sheet =
        preview::DrawContactSheet(&prepared, options, [&](size_t done, size_t total, const std::string& tile) {
          if (args->list) std::printf("%s\n", tile.c_str());
          if (tty) std::fprintf(stderr, "\rpreview: %zu of %zu", done, total);
        });
    if (tty) std::fprintf(stderr, "\n");
    WriteImage(args->out, sheet.image);
    std::string in_groups;
    for (const std::string& group : options.groups)
      if (!group.empty()) in_groups += (in_groups.empty() ? " (groups " : ", ") + group;
    std::printf("%s: %zu distinct stimuli of %zu trials%s -> %s\n", args->protocol.c_str(), sheet.tiles.size(),
                sheet.trial_count, in_groups.empty() ? "" : (in_groups + ")").c_str(), args->out.c_str());
    // What a participant can see of it (as blurcue validate --plan): the invisible pairs, each depth-matching distance.
    for (const std::string& text : sheet.visibility) std::printf("%s\n", text.c_str());
    for (const std::string& text : sheet.notes) std::printf("note: %s\n", text.c_str());
  });
}

}  // namespace blurcue::cli
