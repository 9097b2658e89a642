#pragma once
// What the stimulus module's sources share and nothing outside it uses: where a protocol problem is, an outline's
// extent, a run's two ends. Not part of the module's interface.
#include <algorithm>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "stimulus/stimulus.h"

namespace blurcue::stimulus {


// "FILE: /pointer": where a problem of a trial comes from in the protocol.
inline std::string At(const protocol::Protocol& p, const std::string& pointer) {
  return p.file.string() + ": " + (pointer.empty() ? "/" : pointer);
}

// The largest distance between two points of an outline (px).
inline double ExtentPx(const std::vector<cv::Point2d>& outline) {
  double extent = 0;
  for (const cv::Point2d& p : outline)
    for (const cv::Point2d& q : outline) extent = std::max(extent, cv::norm(p - q));
  return extent;
}

// What a pair trial shows at the start and at the end of its run (the same twice for a still one; the end taken just
// before a section run's wipe): where a check of its whole extent looks.
inline std::array<std::array<std::optional<scene::BlurredObject>, 2>, 2> RunEnds(const protocol::Protocol& protocol,
                                                                         const calib::SceneCalib& scene,
                                                                         const TrialScene& trial) {
  return {ObjectsAt(protocol, scene, trial, 0),
          ObjectsAt(protocol, scene, trial, std::max(0.0, trial.MotionS() - 1e-6))};
}


}  // namespace blurcue::stimulus
