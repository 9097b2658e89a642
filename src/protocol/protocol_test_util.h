#pragma once
// Helpers of the protocol parser's tests: a scene folder whose files exist, a small valid protocol, its problems.
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "protocol/protocol.h"

namespace blurcue::protocol::test {

namespace fs = std::filesystem;

// A folder with a protocol's scene files, so file checks pass unless a test removes one.
inline fs::path SceneFolder() {
  const fs::path dir = fs::temp_directory_path() / ("blurcue-protocol-test-" + std::to_string(::getpid()));
  fs::create_directories(dir / "scene");
  for (const char* name : {"scene/scene.png", "scene/scene-no-board.png", "calib.json"}) std::ofstream(dir / name) << "x";
  return dir;
}

// A small valid moving-ball protocol in the shape of test 2.
inline Json Valid() {
  return Json::parse(R"({
    "name": "small", "version": 1,
    "scene": {"background": "scene/scene.png", "board_free": "scene/scene-no-board.png", "calib": "calib.json"},
    "content": {"type": "ball", "texture": "soccer", "radius_mm": 10},
    "task": "forced_choice", "counterbalance": "swap_copies",
    "blocks": [
      {"name": "task1", "factors": {"pattern": [{"id": 1, "speed_cm_s": 3, "left": "measured", "right": "none"},
                                                {"id": 2, "speed_cm_s": 1.8, "left": "estimated", "right": "none"}]}},
      {"name": "task2", "factors": {"pattern": [{"id": 2, "speed_cm_s": 1.8, "left": "measured", "right": "none"}],
                                    "section": [1, 2, 3]}}
    ]
  })");
}

inline std::vector<std::string> Problems(const Json& json, bool check_files = true) {
  return Validate(json, SceneFolder() / "p.json", ValidateOptions{check_files});
}

// The one problem reported, or a failure listing all of them.
inline std::string OnlyProblem(const Json& json, bool check_files = true) {
  const auto problems = Problems(json, check_files);
  std::string all;
  for (const auto& p : problems) all += p + "\n";
  EXPECT_EQ(problems.size(), 1u) << all;
  return problems.empty() ? "" : problems.front();
}

inline bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// `json` has a problem containing `text` (among any others).
inline void ExpectProblem(const Json& json, const std::string& text) {
  bool found = false;
  std::string all;
  for (const auto& problem : Problems(json)) found = found || Contains(problem, text), all += problem + "\n";
  EXPECT_TRUE(found) << "expected '" << text << "' among:\n" << all;
}

}  // namespace blurcue::protocol::test
