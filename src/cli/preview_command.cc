// blurcue preview: a contact sheet of every distinct stimulus of a protocol, to check it by eye before any
// participant sits down.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <set>
#include <string>

#include <opencv2/imgproc.hpp>

#include "cli/commands.h"
#include "cli/groups.h"
#include "core/output_guard.h"
#include "core/error.h"
#include "core/image.h"
#include "protocol/protocol.h"
#include "protocol/trials.h"
#include "render/gl_context.h"
#include "procedure/adaptive.h"
#include "procedure/answer.h"
#include "procedure/observer.h"
#include "procedure/prepare.h"
#include "session/stimulus_renderer.h"
#include "stimulus/stimulus.h"
#include "procedure/visibility.h"

namespace blurcue::cli {
namespace {

const double kFontScale = 0.36;  // labels: about 6 px a character
const int kLineHeight = 14;

// `lines` broken at spaces so that none is wider than `width_px` in the labels' font (a word wider than that
// alone on its line).
std::vector<std::string> WrapToWidth(const std::vector<std::string>& lines, int width_px) {
  std::vector<std::string> out;
  auto width = [](const std::string& text) {
    int baseline = 0;
    return cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, kFontScale, 1, &baseline).width;
  };
  for (const std::string& line : lines) {
    std::string current;
    size_t at = 0;
    while (at < line.size()) {
      const size_t space = line.find(' ', at);
      const std::string word = line.substr(at, space == std::string::npos ? space : space - at);
      at = space == std::string::npos ? line.size() : space + 1;
      const std::string joined = current.empty() ? word : current + " " + word;
      if (!current.empty() && width(joined) > width_px) {
        out.push_back(current);
        current = "  " + word;  // a continued line is indented
      } else {
        current = joined;
      }
    }
    out.push_back(current);
  }
  return out;
}

// Each object of a composed frame (`described`: stimulus::DescribeFrame) at 1:1 screen scale: a `box_px` square of
// the sheet centred on it, holding box_px / zoom screen px each way, every screen px a zoom x zoom square (nearest
// neighbour: nothing resampled). A depth-matching frame's two pictures likewise, centred on each.
std::vector<std::pair<std::string, cv::Mat>> ObjectInsets(const cv::Mat& frame, const Json& described, int box_px,
                                                          int zoom) {
  std::vector<std::pair<std::string, cv::Point2d>> centres;
  for (const Json& o : described["objects"]) {
    cv::Point2d lo(1e18, 1e18), hi(-1e18, -1e18);
    for (const Json& p : o["outline_px"]) {
      lo = {std::min(lo.x, p[0].get<double>()), std::min(lo.y, p[1].get<double>())};
      hi = {std::max(hi.x, p[0].get<double>()), std::max(hi.y, p[1].get<double>())};
    }
    if (hi.x >= lo.x) centres.push_back({o["side"].get<std::string>(), (lo + hi) * 0.5});
  }
  for (const char* part : {"picture", "real_picture"}) {
    if (!described.contains(part)) continue;
    const Json& r = described[part]["rect_px"];
    centres.push_back({part == std::string("picture") ? "virtual" : "real",
                       {r[0].get<double>() + r[2].get<double>() / 2, r[1].get<double>() + r[3].get<double>() / 2}});
  }
  std::vector<std::pair<std::string, cv::Mat>> insets;
  const int side = std::max(1, box_px / zoom);
  for (const auto& [name, centre] : centres) {
    // The crop, moved inside the frame where the object is near its border.
    const int w = std::min(side, frame.cols), h = std::min(side, frame.rows);
    const int x = std::clamp(int(std::lround(centre.x)) - w / 2, 0, frame.cols - w);
    const int y = std::clamp(int(std::lround(centre.y)) - h / 2, 0, frame.rows - h);
    cv::Mat zoomed;
    cv::resize(frame(cv::Rect(x, y, w, h)), zoomed, cv::Size(), zoom, zoom, cv::INTER_NEAREST);
    insets.push_back({name + (zoom == 1 ? " 1:1" : " 1:1 x" + std::to_string(zoom)), zoomed});
  }
  return insets;
}

}  // namespace

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
      "Draw a contact sheet of every distinct stimulus a protocol shows (each at its onset, as the window shows it),\n"
      "labelled with its levels, the blur radius on each side in photo px, screen px and arcmin, and its blur plan\n"
      "(one radius, or per pixel by depth where the object's depth span changes r by the protocol's\n"
      "content.depth_blur_threshold) with what a frame of it costs to compose here, so a protocol can be checked by\n"
      "eye before a session.\n"
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
    }
    // The pre-flight of blurcue run: the same checks, and every trial's scene already worked out.
    const procedure::ObserverParams observer = procedure::ParseObserver(args->observer);
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
    }
    const std::vector<std::string> groups = GroupsToCheck(prepared.protocol, args->group);
    const protocol::Protocol& p = prepared.protocol;
    const auto& scene = prepared.scene;
    struct Tile {
      stimulus::TrialScene scene;
      double level;
      std::string label, label2;  // levels; the sides and their radii
      Json key;                    // sorts the sheet by level
      std::string seen = {};       // pairs: the predicted share correct, and invisible below --visible
    };
    std::vector<Tile> tiles;
    std::vector<std::string> visibility;  // what an observer can see, per group
    size_t trial_count = 0;
    for (size_t g = 0; g < groups.size(); ++g) {
      // Each group's own trials: its blocks, checked and drawn (a group's tiles together, labelled with its name).
      procedure::PrepareParticipant(&prepared, args->participant, args->seed, groups[g]);
      const auto& trials = prepared.trials;
      trial_count += trials.size();
      const size_t group_start = tiles.size();
      std::set<std::string> seen;  // labels or level keys already on the sheet
      procedure::AdaptiveState adaptive(p);  // no answers yet: each procedure's first level
      for (const auto& t : trials) {
        const stimulus::TrialScene& s_planned = prepared.scenes[size_t(t.index)];
        if (protocol::TraitsOf(t.task).answer == protocol::TaskAnswer::kLevel) {
          const stimulus::TrialScene& s = s_planned;
          // Every level once (at the first distance shown), and every distance once (at the middle level): the
          // two halves of the frame vary apart, so together these show every distinct half.
          const std::string parameter = p.blocks.front().adjust ? p.blocks.front().adjust->parameter : "level";
          std::vector<double> sorted = t.adjust_levels;
          std::sort(sorted.begin(), sorted.end());
          for (double level : t.adjust_levels) {
            char label[96];
            std::snprintf(label, sizeof label, "%s %g", parameter.c_str(), level);
            if (seen.insert(label).second)
              tiles.push_back({s, level, label, "distance " + Json(s.distance_m).dump() + " m",
                               Json::array({0, level})});
          }
          if (!sorted.empty() && s.distance_m > 0) {
            char label[96];
            std::snprintf(label, sizeof label, "distance %g m", s.distance_m);
            const double middle = sorted[sorted.size() / 2];
            if (seen.insert(label).second)
              tiles.push_back({s, middle, label, parameter + " " + Json(middle).dump(),
                               Json::array({1, s.distance_m})});
          }
          continue;
        }
        Json key = protocol::ToJson(t.levels);
        key[protocol::ToString(protocol::Side::kLeft)] = protocol::ToJson(t.left);
        key[protocol::ToString(protocol::Side::kRight)] = protocol::ToJson(t.right);
        if (!seen.insert(key.dump()).second) continue;
        // A procedure's crossing is shown at its first trial's level, on that trial's test side.
        stimulus::TrialScene s = s_planned;
        std::string first;
        if (t.cell >= 0) {
          const double level = adaptive.Level(t);
          const protocol::Procedure& procedure = *protocol::BlockOf(p, t)->procedure;  // t.cell >= 0: it has one
          stimulus::ApplyLevel(procedure, t, level, prepared.presentation, &s);
          first = " (" + protocol::ToString(procedure.kind) + ": " + protocol::ToString(procedure.variable) + " " + Json(level).dump() +
                  " on the " + t.test_side + " at first)";
          procedure::PlanLeveled(prepared, t, &s);
        }
        const std::string levels = procedure::LevelsLabel(t);
        // Each side's radius as the camera made it (photo px) and as the screen shows it (screen px, arcmin): the
        // numbers the record keeps for these trials.
        const stimulus::Presentation& at = prepared.presentation;
        auto side = [&](const char* name, const std::optional<protocol::BlurSpec>& v, double r) {
          char text[160];
          std::snprintf(text, sizeof text, "%s %s %.2f px = %.2f scr px %.2f'", name, protocol::SideText(v).c_str(), r,
                        at.ScreenPx(r), at.Arcmin(r));
          return std::string(text);
        };
        // What an observer makes of the pair on this display: the object against the scene's blur for one object.
        procedure::PairView view = procedure::ViewOf(s, at);
        if (s.left_only) view.r_px[protocol::Index(protocol::Side::kRight)] = view.r_scene_px;
        const double p_correct = procedure::ProbabilityCorrect2afc(observer, view);
        char seen[96];
        std::snprintf(seen, sizeof seen, "%s told apart %.0f %% (2AFC)%s", s.left_only ? "vs scene:" : "L vs R:",
                      100 * p_correct,
                      p_correct >= args->visible ? "" : s.left_only ? " - as blurred as the scene" : " - INVISIBLE");
        const size_t first_tile = tiles.size();
        if (s.left_only) {  // layout single: its one object
          tiles.push_back({s, 0, levels + first, side("object", t.left, s.side(protocol::Side::kLeft).r_px), key});
        } else if (s.intervals > 0) {
          // Intervals show one object at a time, at the left object's place: a tile for each kind of interval.
          const bool odd = s.intervals > 2;
          Json first_key = key;
          first_key["interval"] = 1;
          tiles.push_back({stimulus::IntervalScene(s, false), 0, levels + first,
                           side(odd ? "the others: L" : "1st interval: L", t.left, s.side(protocol::Side::kLeft).r_px),
                           first_key});
          Json second = key;
          second["interval"] = 2;
          tiles.push_back(
              {stimulus::IntervalScene(s, true), 0, levels + first,
               side(odd ? "the odd one: R" : "2nd interval: R", t.right, s.side(protocol::Side::kRight).r_px), second});
        } else {
          tiles.push_back({s, 0, levels + first,
                           side("L", t.left, s.side(protocol::Side::kLeft).r_px) + " | " +
                               side("R", t.right, s.side(protocol::Side::kRight).r_px),
                           key});
        }
        for (size_t k = first_tile; k < tiles.size(); ++k) tiles[k].seen = seen;
      }
      const std::string prefix = groups[g].empty() ? "" : "group " + groups[g] + ": ";
      for (size_t k = group_start; k < tiles.size(); ++k)
        tiles[k].label = prefix + tiles[k].label, tiles[k].key = Json::array({int(g), tiles[k].key});
      for (const std::string& text : procedure::VisibilityLines(prepared, observer, args->visible, true))
        visibility.push_back(prefix + text);
    }
    std::stable_sort(tiles.begin(), tiles.end(), [](const Tile& a, const Tile& b) { return a.key < b.key; });
    if (tiles.empty()) throw InputError(args->protocol, "the protocol makes no trials to preview");

    auto context = render::GlContext::CreateOffscreen();
    session::StimulusRenderer renderer(p, scene, prepared.images, prepared.presentation);
    const cv::Size frame = renderer.FrameSize();
    // Each tile: the whole frame (1:1 when it fits --tile-width), then an inset per object at 1:1 (x --zoom).
    const bool whole_at_1to1 = frame.width <= args->tile_width;
    const int tw = whole_at_1to1 ? frame.width : args->tile_width, th = tw * frame.height / frame.width;
    const int inset = whole_at_1to1 ? 0 : std::max(th, 160), insets = whole_at_1to1 ? 0 : 2;
    const int tile_w = tw + insets * (inset + 4);
    const int cols = std::min<int>(args->columns, int(tiles.size()));
    const int rows = (int(tiles.size()) + cols - 1) / cols;
    const bool tty = isatty(2);  // a terminal gets a progress line; a log only the summary
    struct Drawn {
      cv::Mat whole;
      std::vector<std::pair<std::string, cv::Mat>> insets;  // label, 1:1 crop (zoomed)
      std::vector<std::string> lines;
    };
    std::vector<Drawn> drawn(tiles.size());
    for (size_t i = 0; i < tiles.size(); ++i) {
      // Composed twice: the second time is what a frame of it costs in a session (textures already uploaded).
      renderer.Compose(tiles[i].scene, 0, tiles[i].level);
      renderer.Finish();
      const auto t0 = std::chrono::steady_clock::now();
      renderer.Compose(tiles[i].scene, 0, tiles[i].level);
      renderer.Finish();
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      std::string plan;
      if (tiles[i].scene.content != protocol::ContentType::kPicture) {
        char text[128];
        std::snprintf(text, sizeof text, "plan: %s, span %.2f scr px, %.1f ms/frame",
                      tiles[i].scene.per_pixel ? "per pixel" : "one radius", tiles[i].scene.r_span_screen_px, ms);
        plan = text;
      }
      const cv::Mat full = renderer.Read();
      Drawn& d = drawn[i];
      d.whole = whole_at_1to1 ? full.clone() : ResampleSrgb8(full, cv::Size(tw, th));
      const Json described = stimulus::DescribeFrame(scene ? &*scene : nullptr, tiles[i].scene,
                                                     prepared.presentation, renderer.View(), renderer.Shown(),
                                                     tiles[i].level);
      if (insets > 0) d.insets = ObjectInsets(full, described, inset, args->zoom);
      d.lines = {"#" + std::to_string(i + 1) + " " + tiles[i].label};
      for (size_t at = 0, bar; at != std::string::npos; at = bar == std::string::npos ? bar : bar + 3) {
        bar = tiles[i].label2.find(" | ", at);
        d.lines.push_back(tiles[i].label2.substr(at, bar == std::string::npos ? bar : bar - at));
      }
      if (described.contains("picture")) {  // depth matching: each picture's blur on this screen
        char text[160];
        const Json& virt = described["picture"];
        const Json& real = described["real_picture"];
        std::snprintf(text, sizeof text, "virtual r %.2f scr px %.2f'", virt["r_screen_px"].get<double>(),
                      virt["r_arcmin"].get<double>());
        std::string radii = text;
        if (real.contains("r_screen_px")) {
          std::snprintf(text, sizeof text, ", real r %.2f scr px %.2f'", real["r_screen_px"].get<double>(),
                        real["r_arcmin"].get<double>());
          radii += text;
        }
        d.lines.push_back(radii);
      }
      if (!plan.empty()) d.lines.push_back(plan.substr(6));  // without "plan: "
      if (!tiles[i].seen.empty()) d.lines.push_back(tiles[i].seen);
      d.lines = WrapToWidth(d.lines, tile_w - 8);
      if (args->list)
        std::printf("#%zu %s: %s%s%s%s%s\n", i + 1, tiles[i].label.c_str(), tiles[i].label2.c_str(),
                    plan.empty() ? "" : " | ", plan.c_str(), tiles[i].seen.empty() ? "" : " | ",
                    tiles[i].seen.c_str());
      if (tty) std::fprintf(stderr, "\rpreview: %zu of %zu", i + 1, tiles.size());
    }
    if (tty) std::fprintf(stderr, "\n");
    // The label strip is as tall as the longest label needs, so no label runs into the next row's tiles.
    size_t most_lines = 0;
    for (const Drawn& d : drawn) most_lines = std::max(most_lines, d.lines.size());
    const int tile_h = std::max(th, inset), strip = kLineHeight * int(most_lines) + 8;
    cv::Mat sheet(rows * (tile_h + strip), cols * (tile_w + 8), CV_8UC3, cv::Scalar(40, 40, 40));
    for (size_t i = 0; i < drawn.size(); ++i) {
      const Drawn& d = drawn[i];
      const int x = int(i % size_t(cols)) * (tile_w + 8), y = int(i / size_t(cols)) * (tile_h + strip);
      d.whole.copyTo(sheet(cv::Rect(x, y, d.whole.cols, d.whole.rows)));
      for (size_t k = 0; k < d.insets.size(); ++k) {
        const cv::Mat& crop = d.insets[k].second;
        const int ix = x + tw + 4 + int(k) * (inset + 4);
        crop.copyTo(sheet(cv::Rect(ix, y, crop.cols, crop.rows)));
        cv::putText(sheet, d.insets[k].first, {ix + 3, y + 12}, cv::FONT_HERSHEY_SIMPLEX, kFontScale,
                    cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
        cv::putText(sheet, d.insets[k].first, {ix + 3, y + 12}, cv::FONT_HERSHEY_SIMPLEX, kFontScale,
                    cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
      }
      for (size_t k = 0; k < d.lines.size(); ++k) {
        const bool flagged = d.lines[k].find("INVISIBLE") != std::string::npos;
        cv::putText(sheet, d.lines[k], {x + 4, y + tile_h + kLineHeight * int(k + 1)}, cv::FONT_HERSHEY_SIMPLEX,
                    kFontScale, flagged ? cv::Scalar(90, 90, 255) : cv::Scalar(235, 235, 235), 1, cv::LINE_AA);
      }
    }
    WriteImage(args->out, sheet);
    std::string in_groups;
    for (const std::string& group : groups)
      if (!group.empty()) in_groups += (in_groups.empty() ? " (groups " : ", ") + group;
    std::printf("%s: %zu distinct stimuli of %zu trials%s -> %s\n", args->protocol.c_str(), tiles.size(), trial_count,
                in_groups.empty() ? "" : (in_groups + ")").c_str(), args->out.c_str());
    // What a participant can see of it (as blurcue validate --plan): the invisible pairs, each depth-matching distance.
    for (const std::string& text : visibility) std::printf("%s\n", text.c_str());
  });
}

}  // namespace blurcue::cli
