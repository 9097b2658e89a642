#pragma once
// Test fixtures (tests only): the thesis's view built by hand, stand-ins for the files a protocol names, a ball
// protocol, a pair trial.
#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <utility>

#include <opencv2/calib3d.hpp>

#include "calib/scene_blur.h"
#include "core/camera.h"
#include "core/json_io.h"
#include "protocol/protocol.h"
#include "protocol/trials.h"

namespace blurcue::stimulus::fixtures {

// The thesis's view built by hand (camera pitched down 38 deg, 440 mm from the board's centre), a lens focused
// at 342.3 mm with the nominal aperture, and one measured section at edge 1 reading 0.3 px.
inline calib::SceneCalib ThesisScene() {
  calib::SceneCalib s;
  s.camera = ThesisCamera().Resized(1148, 764);
  const double a = 38 * M_PI / 180, sn = std::sin(a), c = std::cos(a);
  const cv::Matx33d r(1, 0, 0, 0, -sn, -c, 0, c, -sn);
  const cv::Vec3d forward(0, c, -sn), target(87.5, 125, 0);
  const cv::Vec3d centre = target - 440.0 * forward;
  cv::Rodrigues(r, s.rvec);
  s.tvec = -(r * centre);
  s.reference_edge = 1;
  s.reference_u_mm = s.ToCamera({87.5, 0, 0})[2];
  s.reference_r_px = 0.0;
  s.model.focus_mm = s.reference_u_mm;
  s.model.aperture_mm = 21 / 5.6;
  s.model.kind = "thin_lens";
  calib::SceneCalib::Section section;
  section.edge = 1;
  section.section = 4;
  section.midpoint_camera_mm = s.ToCamera({87.5, 0, 0});
  section.r_px = 0.3;
  section.ok = true;
  s.sections.push_back(section);
  return s;
}

// Files a protocol names must exist: stand-ins, never read (the calibration and the photo are given by hand).
inline Json StandInScene() {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path d = std::filesystem::temp_directory_path() / ("blurcue-stand-in-scene-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    for (const char* name : {"scene.png", "calib.json"}) std::ofstream(d / name) << "";
    return d;
  }();
  return {{"background", (dir / "scene.png").string()}, {"calib", (dir / "calib.json").string()}};
}

inline protocol::Protocol BallProtocol() {
  protocol::Protocol p;
  p.file = "balls.json";
  p.content.type = protocol::ContentType::kBall;
  p.content.radius_mm = 10;
  return p;
}

inline protocol::Trial PairTrial(Json levels, Json left, Json right) {
  protocol::Trial t;
  t.block = "task2";
  t.levels = protocol::LevelsOf(levels);
  if (!left.is_null()) t.left = protocol::BlurSpecOf(left);
  if (!right.is_null()) t.right = protocol::BlurSpecOf(right);
  return t;
}

}  // namespace blurcue::stimulus::fixtures
