// The contact sheet of a protocol (preview.h): which stimuli are distinct, each drawn as a session draws it, labelled
// and laid out.
#include "preview/preview.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <set>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/image.h"
#include "procedure/adaptive.h"
#include "procedure/visibility.h"
#include "protocol/protocol.h"
#include "protocol/trials.h"
#include "render/gl_context.h"
#include "session/stimulus_renderer.h"
#include "stimulus/stimulus.h"

namespace blurcue::preview {
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

struct Tile {
  stimulus::TrialScene scene;
  double level;
  std::string label, label2;  // levels; the sides and their radii
  Json key;                    // sorts the sheet by level
  std::string seen = {};       // pairs: the predicted share correct, and invisible below --visible
};

// A depth-matching trial's tiles: every level once (at the first distance shown), and every distance once (at the
// middle level): the two halves of the frame vary apart, so together these show every distinct half.
void AddAdjustTiles(const protocol::Protocol& p, const protocol::Trial& t, const stimulus::TrialScene& s,
                    std::set<std::string>* seen, std::vector<Tile>* tiles) {
  const std::string parameter = p.blocks.front().adjust ? p.blocks.front().adjust->parameter : "level";
  std::vector<double> sorted = t.adjust_levels;
  std::sort(sorted.begin(), sorted.end());
  for (double level : t.adjust_levels) {
    char label[96];
    std::snprintf(label, sizeof label, "%s %g", parameter.c_str(), level);
    if (seen->insert(label).second)
      tiles->push_back({s, level, label, "distance " + Json(s.distance_m).dump() + " m", Json::array({0, level})});
  }
  if (!sorted.empty() && s.distance_m > 0) {
    char label[96];
    std::snprintf(label, sizeof label, "distance %g m", s.distance_m);
    const double middle = sorted[sorted.size() / 2];
    if (seen->insert(label).second)
      tiles->push_back({s, middle, label, parameter + " " + Json(middle).dump(), Json::array({1, s.distance_m})});
  }
}

// A pair trial's tiles, when its levels and sides are not on the sheet yet: one, or one per kind of interval.
void AddPairTiles(const procedure::PreparedSession& prepared, const SheetOptions& options,
                  procedure::AdaptiveState* adaptive, const protocol::Trial& t, std::set<std::string>* seen_keys,
                  std::vector<Tile>* tiles) {
  const protocol::Protocol& p = prepared.protocol;
  Json key = protocol::ToJson(t.levels);
  key[protocol::ToString(protocol::Side::kLeft)] = protocol::ToJson(t.left);
  key[protocol::ToString(protocol::Side::kRight)] = protocol::ToJson(t.right);
  if (!seen_keys->insert(key.dump()).second) return;
  // A procedure's crossing is shown at its first trial's level, on that trial's test side.
  stimulus::TrialScene s = prepared.scenes[size_t(t.index)];
  std::string first;
  if (t.cell >= 0) {
    const double level = adaptive->Level(t);
    const protocol::Procedure& procedure = *protocol::BlockOf(p, t)->procedure;  // t.cell >= 0: it has one
    stimulus::ApplyLevel(procedure, t, level, prepared.presentation, &s);
    first = " (" + protocol::ToString(procedure.kind) + ": " + protocol::ToString(procedure.variable) + " " +
            Json(level).dump() + " on the " + t.test_side + " at first)";
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
  const double p_correct = procedure::ProbabilityCorrect2afc(options.observer, view);
  char seen[96];
  std::snprintf(seen, sizeof seen, "%s told apart %.0f %% (2AFC)%s", s.left_only ? "vs scene:" : "L vs R:",
                100 * p_correct,
                p_correct >= options.visible ? "" : s.left_only ? " - as blurred as the scene" : " - INVISIBLE");
  const size_t first_tile = tiles->size();
  const double r_left = s.side(protocol::Side::kLeft).r_px, r_right = s.side(protocol::Side::kRight).r_px;
  if (s.left_only) {  // layout single: its one object
    tiles->push_back({s, 0, levels + first, side("object", t.left, r_left), key});
  } else if (s.intervals > 0) {
    // Intervals show one object at a time, at the left object's place: a tile for each kind of interval.
    const bool odd = s.intervals > 2;
    Json first_key = key;
    first_key["interval"] = 1;
    tiles->push_back({stimulus::IntervalScene(s, false), 0, levels + first,
                      side(odd ? "the others: L" : "1st interval: L", t.left, r_left), first_key});
    Json second = key;
    second["interval"] = 2;
    tiles->push_back({stimulus::IntervalScene(s, true), 0, levels + first,
                      side(odd ? "the odd one: R" : "2nd interval: R", t.right, r_right), second});
  } else {
    tiles->push_back({s, 0, levels + first, side("L", t.left, r_left) + " | " + side("R", t.right, r_right), key});
  }
  for (size_t k = first_tile; k < tiles->size(); ++k) (*tiles)[k].seen = seen;
}

// Every group's distinct tiles, sorted by group and level; counts the trials and gathers each group's visibility.
std::vector<Tile> ChooseTiles(procedure::PreparedSession* prepared, const SheetOptions& options, Sheet* sheet) {
  const protocol::Protocol& p = prepared->protocol;
  std::vector<Tile> tiles;
  for (size_t g = 0; g < options.groups.size(); ++g) {
    // Each group's own trials: its blocks, checked and drawn (a group's tiles together, labelled with its name).
    procedure::PrepareParticipant(prepared, options.participant, options.seed, options.groups[g]);
    const auto& trials = prepared->trials;
    sheet->trial_count += trials.size();
    const size_t group_start = tiles.size();
    std::set<std::string> seen;  // labels or level keys already on the sheet
    procedure::AdaptiveState adaptive(p);  // no answers yet: each procedure's first level
    for (const auto& t : trials) {
      if (protocol::TraitsOf(t.task).answer == protocol::TaskAnswer::kLevel)
        AddAdjustTiles(p, t, prepared->scenes[size_t(t.index)], &seen, &tiles);
      else
        AddPairTiles(*prepared, options, &adaptive, t, &seen, &tiles);
    }
    const std::string prefix = options.groups[g].empty() ? "" : "group " + options.groups[g] + ": ";
    for (size_t k = group_start; k < tiles.size(); ++k)
      tiles[k].label = prefix + tiles[k].label, tiles[k].key = Json::array({int(g), tiles[k].key});
    for (const std::string& text : procedure::VisibilityLines(*prepared, options.observer, options.visible, true))
      sheet->visibility.push_back(prefix + text);
    if (const std::string note = procedure::UndeterminedBlurNote(*prepared); !note.empty())
      sheet->notes.push_back(prefix + note);
  }
  std::stable_sort(tiles.begin(), tiles.end(), [](const Tile& a, const Tile& b) { return a.key < b.key; });
  return tiles;
}

// Where a tile's parts go: the whole frame (1:1 when it fits the tile width), then an inset per object at 1:1.
struct Layout {
  int tw = 0, th = 0;       // the whole frame as shown
  int inset = 0, insets = 0;  // an inset's side, and how many a tile has room for
  int tile_w = 0;
  bool whole_at_1to1 = false;
};

Layout LayoutFor(cv::Size frame, const SheetOptions& options) {
  Layout l;
  l.whole_at_1to1 = frame.width <= options.tile_width_px;
  l.tw = l.whole_at_1to1 ? frame.width : options.tile_width_px;
  l.th = l.tw * frame.height / frame.width;
  l.inset = l.whole_at_1to1 ? 0 : std::max(l.th, 160);
  l.insets = l.whole_at_1to1 ? 0 : 2;
  l.tile_w = l.tw + l.insets * (l.inset + 4);
  return l;
}

struct Drawn {
  cv::Mat whole;
  std::vector<std::pair<std::string, cv::Mat>> insets;  // label, 1:1 crop (zoomed)
  std::vector<std::string> lines;
  std::string listed;  // its line of Sheet::tiles
  double ms = 0;       // what composing a frame of it cost here
};

// Tile `i` composed as a session composes it, with its label lines (wrapped to the tile) and its line for the list.
Drawn DrawTile(session::StimulusRenderer& renderer, const procedure::PreparedSession& prepared, const Tile& tile,
               size_t i, const Layout& layout, int zoom) {
  // Composed twice: the second time is what a frame of it costs in a session (textures already uploaded).
  renderer.Compose(tile.scene, 0, tile.level);
  renderer.Finish();
  const auto t0 = std::chrono::steady_clock::now();
  renderer.Compose(tile.scene, 0, tile.level);
  renderer.Finish();
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::string plan;
  if (tile.scene.content != protocol::ContentType::kPicture) {
    char text[128];
    std::snprintf(text, sizeof text, "plan: %s, span %.2f scr px, %.1f ms/frame",
                  tile.scene.per_pixel ? "per pixel" : "one radius", tile.scene.r_span_screen_px, ms);
    plan = text;
  }
  const cv::Mat full = renderer.Read();
  Drawn d;
  d.ms = ms;
  d.whole = layout.whole_at_1to1 ? full.clone() : ResampleSrgb8(full, cv::Size(layout.tw, layout.th));
  const auto& scene = prepared.scene;
  const Json described = stimulus::DescribeFrame(scene ? &*scene : nullptr, tile.scene, prepared.presentation,
                                                 renderer.View(), renderer.Shown(), tile.level);
  if (layout.insets > 0) d.insets = ObjectInsets(full, described, layout.inset, zoom);
  d.lines = {"#" + std::to_string(i + 1) + " " + tile.label};
  for (size_t at = 0, bar; at != std::string::npos; at = bar == std::string::npos ? bar : bar + 3) {
    bar = tile.label2.find(" | ", at);
    d.lines.push_back(tile.label2.substr(at, bar == std::string::npos ? bar : bar - at));
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
  if (!tile.seen.empty()) d.lines.push_back(tile.seen);
  d.lines = WrapToWidth(d.lines, layout.tile_w - 8);
  d.listed = "#" + std::to_string(i + 1) + " " + tile.label + ": " + tile.label2 + (plan.empty() ? "" : " | ") + plan +
             (tile.seen.empty() ? "" : " | ") + tile.seen;
  return d;
}

// The drawn tiles in rows of `columns`, each with its label strip below.
cv::Mat AssembleSheet(const std::vector<Drawn>& drawn, const Layout& layout, int columns) {
  const int cols = std::min<int>(columns, int(drawn.size()));
  const int rows = (int(drawn.size()) + cols - 1) / cols;
  // The label strip is as tall as the longest label needs, so no label runs into the next row's tiles.
  size_t most_lines = 0;
  for (const Drawn& d : drawn) most_lines = std::max(most_lines, d.lines.size());
  const int tile_w = layout.tile_w, inset = layout.inset;
  const int tile_h = std::max(layout.th, inset), strip = kLineHeight * int(most_lines) + 8;
  cv::Mat sheet(rows * (tile_h + strip), cols * (tile_w + 8), CV_8UC3, cv::Scalar(40, 40, 40));
  for (size_t i = 0; i < drawn.size(); ++i) {
    const Drawn& d = drawn[i];
    const int x = int(i % size_t(cols)) * (tile_w + 8), y = int(i / size_t(cols)) * (tile_h + strip);
    d.whole.copyTo(sheet(cv::Rect(x, y, d.whole.cols, d.whole.rows)));
    for (size_t k = 0; k < d.insets.size(); ++k) {
      const cv::Mat& crop = d.insets[k].second;
      const int ix = x + layout.tw + 4 + int(k) * (inset + 4);
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
  return sheet;
}

}  // namespace

Sheet DrawContactSheet(procedure::PreparedSession* prepared, const SheetOptions& options,
                       const SheetProgress& progress) {
  Sheet sheet;
  const std::vector<Tile> tiles = ChooseTiles(prepared, options, &sheet);
  if (tiles.empty()) throw InputError(prepared->protocol.file.string(), "the protocol makes no trials to preview");

  auto context = render::GlContext::CreateOffscreen();
  session::StimulusRenderer renderer(prepared->protocol, prepared->scene, prepared->images, prepared->presentation);
  const Layout layout = LayoutFor(renderer.FrameSize(), options);
  std::vector<Drawn> drawn;
  for (size_t i = 0; i < tiles.size(); ++i) {
    drawn.push_back(DrawTile(renderer, *prepared, tiles[i], i, layout, options.zoom));
    sheet.tiles.push_back(drawn.back().listed);
    if (progress) progress(i + 1, tiles.size(), sheet.tiles.back());
  }
  sheet.image = AssembleSheet(drawn, layout, options.columns);
  // A frame's cost against the display's frame interval: a tile slower than it would drop frames in a session on
  // this machine's renderer (a session's frame log says what each shown frame took).
  const auto slowest = std::max_element(drawn.begin(), drawn.end(),
                                        [](const Drawn& a, const Drawn& b) { return a.ms < b.ms; });
  const double budget = 1000 / prepared->presentation.profile.refresh_hz;
  const size_t over = std::count_if(drawn.begin(), drawn.end(), [&](const Drawn& d) { return d.ms > budget; });
  char line[400];
  if (over > 0)
    std::snprintf(line, sizeof line,
                  "%zu of %zu tiles took longer to compose here than the display's frame (%.1f ms at %g Hz; the "
                  "slowest, #%zu, %.1f ms): on this machine's renderer their trials would drop frames; run them on "
                  "the lab's GPU and check their dropped frames (export's frames.csv)",
                  over, drawn.size(), budget, prepared->presentation.profile.refresh_hz,
                  size_t(slowest - drawn.begin()) + 1, slowest->ms);
  else
    std::snprintf(line, sizeof line, "every tile composed within the display's frame here (the slowest, #%zu, %.1f ms "
                  "of %.1f ms at %g Hz)", size_t(slowest - drawn.begin()) + 1, slowest->ms, budget,
                  prepared->presentation.profile.refresh_hz);
  sheet.notes.push_back(line);
  return sheet;
}

}  // namespace blurcue::preview
