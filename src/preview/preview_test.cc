// The contact sheet drawn straight from the library (no command line): which stimuli are distinct, their labels and
// the sheet's layout, on the thesis's view with stand-in images (GL: Mesa's software renderer through EGL).
#include "preview/preview.h"

#include <gtest/gtest.h>

#include <string>

#include "stimulus/test_scenes.h"

namespace blurcue::preview {
namespace {

// A grid-card protocol on the thesis's view: `edges` each shown `repetitions` times, left blurred by 2 px, right not.
procedure::PreparedSession GridStudy(const Json& edges, int repetitions) {
  const Json json = {{"name", "preview-test"},
                     {"version", 1},
                     {"scene", stimulus::fixtures::StandInScene()},
                     {"content", {{"type", "grid"}, {"cells", 5}}},
                     {"task", "forced_choice"},
                     {"factors", {{"edge", edges}}},
                     {"repetitions", repetitions},
                     {"sides", {{"left", 2.0}, {"right", "none"}}},
                     {"responses", {{"left", "Left"}, {"right", "Right"}, {"cant_tell", "Down"}}},
                     {"display", {{"width_px", 1280}, {"height_px", 720}}}};
  procedure::PreparedSession s;
  s.protocol_text = json.dump();
  s.protocol = protocol::ParseProtocol(json, "preview-test.json");
  s.scene = stimulus::fixtures::ThesisScene();
  s.images.photo = cv::Mat(764, 1148, CV_8UC3, cv::Scalar::all(128));
  s.images.texture = cv::Mat(64, 64, CV_8UC3, cv::Scalar::all(255));
  s.presentation = stimulus::Presentation::Of(s.protocol, s.images, s.display);
  return s;
}

TEST(ContactSheet, RepeatedTrialsAreDrawnOnceEachInLevelOrder) {
  procedure::PreparedSession study = GridStudy({3, 1, 2}, 2);
  SheetOptions options;
  options.columns = 2;
  size_t calls = 0;
  const Sheet sheet = DrawContactSheet(&study, options, [&](size_t done, size_t total, const std::string& tile) {
    ++calls;
    EXPECT_EQ(total, 3u);
    EXPECT_EQ(tile.rfind("#" + std::to_string(done) + " ", 0), 0u) << tile;
  });
  EXPECT_EQ(sheet.trial_count, 6u);  // 3 edges x 2 repetitions
  ASSERT_EQ(sheet.tiles.size(), 3u);
  EXPECT_EQ(calls, 3u);
  // Sorted by level whatever the file's order, each with the left side's 2 px and the right side's none.
  for (int edge = 1; edge <= 3; ++edge) {
    const std::string& tile = sheet.tiles[size_t(edge - 1)];
    EXPECT_EQ(tile.rfind("#" + std::to_string(edge) + " edge " + std::to_string(edge) + ": ", 0), 0u) << tile;
    EXPECT_NE(tile.find("L 2.0 2.00 px = 1.88 scr px"), std::string::npos) << tile;  // the 1280 x 720 window's scale
    EXPECT_NE(tile.find("R none 0.00 px = 0.00 scr px"), std::string::npos) << tile;
    EXPECT_NE(tile.find("L vs R: told apart"), std::string::npos) << tile;
  }
  // Two columns, two rows (the second half empty). A tile: the 1280 x 720 frame scaled to 320 x 180, two 180 px
  // insets beside it (4 px apart), 8 px between tiles; below it a strip of 5 label lines of 14 px and 8 px.
  EXPECT_EQ(sheet.image.type(), CV_8UC3);
  EXPECT_EQ(sheet.image.cols, 2 * (320 + 2 * (180 + 4) + 8));
  EXPECT_EQ(sheet.image.rows, 2 * (180 + 5 * 14 + 8));
}

}  // namespace
}  // namespace blurcue::preview
