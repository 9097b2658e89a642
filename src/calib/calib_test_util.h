// Test helpers shared by the calibration's test files: the thesis's synthetic scene (and one focused in front of the
// board), rendered and calibrated once per test binary.
#pragma once

#include <map>
#include <string>
#include <utility>

#include "calib/calibrate.h"
#include "calib/truth.h"
#include "synth/scene.h"

namespace blurcue::calib {

inline synth::SceneOptions Thesis(double noise = 0.004) {
  synth::SceneOptions o;
  o.noise_std = noise;
  o.seed = 11;
  return o;
}

// Focused in front of the board so every edge is blurred by 2-4 px at this resolution.
inline synth::SceneOptions Blurry() {
  synth::SceneOptions o = Thesis();
  o.focus_mm = 260;
  return o;
}

struct Calibration {
  synth::Scene scene;
  CalibResult result;
  TruthComparison cmp;
};

// Rendering a scene takes seconds: each distinct scene is rendered and calibrated once per test binary.
inline const Calibration& Calibrated(const synth::SceneOptions& o) {
  static std::map<std::string, Calibration> cache;
  const std::string key = std::to_string(o.focus_mm) + "/" + std::to_string(o.noise_std) + "/" +
                          std::to_string(o.floor_sigma_px) + "/" + std::to_string(o.vignetting) + "/" +
                          std::to_string(o.jpeg_quality) + "/" + std::to_string(int(o.psf)) + "/" +
                          Json(o.camera.dist_coeffs).dump() + "/" + std::to_string(o.yaw_deg) + "/" +
                          std::to_string(o.lateral_mm) + "/" + std::to_string(o.edge1_u_mm);
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  Calibration r;
  r.scene = synth::RenderScene(o);
  r.result = Calibrate(r.scene.image, r.scene.camera, r.scene.board);
  r.cmp = CompareToTruth(r.result, r.scene.truth, "truth");
  return cache.emplace(key, std::move(r)).first->second;
}

}  // namespace blurcue::calib
