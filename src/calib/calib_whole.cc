#include "calib/calib_whole.h"

#include <cmath>

#include "core/distortion.h"
#include "core/error.h"

namespace blurcue::calib {
namespace {

// Depths as the reader takes them elsewhere (scene_blur.cc): at most 1000 m.
constexpr double kMaxDepthMm = 1e6;

// A depth: positive, finite, at most kMaxDepthMm.
double Depth(const Json& obj, const std::string& where) {
  if (!obj.contains("u_mm") || !obj["u_mm"].is_number())
    throw InputError(where + "/u_mm", "must be a depth in mm, got " + (obj.contains("u_mm") ? obj["u_mm"].dump()
                                                                                             : std::string("nothing")));
  const double u = obj["u_mm"].get<double>();
  if (!(u > 0 && u <= kMaxDepthMm))
    throw InputError(where + "/u_mm", "must be a depth in (0, " + Num(kMaxDepthMm) +
                                          "] mm (distance in front of the lens), got " + Num(u));
  return u;
}

void RequireUnits(const Json& j, const SceneCalib& s, const std::string& where) {
  if (!j.contains("r_units")) return;  // calibrations written before the field was (blurcue < 2026-11-28)
  const Json& units = j["r_units"];
  const bool distorted = !LensDistortion(s.camera).Identity();
  // What calibrate writes (calibrate.cc CalibToJson): one sentence without dist_coeffs, two with.
  const bool as_written =
      distorted ? units.is_object() && units.size() == 2 && units.contains("sections") && units.contains("model") &&
                      units["sections"].is_string() && units["model"].is_string() &&
                      units["sections"].get<std::string>().rfind("r_px", 0) == 0 &&
                      units["model"].get<std::string>().find("ideal") != std::string::npos
                : units.is_string() && units.get<std::string>().rfind("px of the photo", 0) == 0;
  if (!as_written)
    throw InputError(where + "/r_units",
                     std::string("must be what blurcue calibrate writes for ") +
                         (distorted ? "a camera with dist_coeffs (an object saying the sections' radii are photo px and "
                                      "the model's ideal px)"
                                    : "a camera without dist_coeffs (\"px of the photo ...\"): every radius is in px") +
                         ", got " + units.dump().substr(0, 120));
}

}  // namespace

void RequireWholeCalib(const Json& j, const SceneCalib& s, const std::string& where) {
  RequireUnits(j, s, where);
  const Json& edges = j["edges"];
  const int E = s.board.EdgeCount(), S = s.board.SectionCount();
  if (int(edges.size()) != E)
    throw InputError(where + "/edges", "lists " + std::to_string(edges.size()) + " edges but the board of " +
                                           std::to_string(s.board.rows) + " rows has " + std::to_string(E) +
                                           " (calibrate writes every edge; was /board edited?)");
  const double w = s.camera.image_width_px, h = s.camera.image_height_px;
  for (size_t e = 0; e < edges.size(); ++e) {
    const std::string ew = where + "/edges/" + std::to_string(e);
    const Json& sections = edges[e]["sections"];
    if (int(sections.size()) != S)
      throw InputError(ew + "/sections", std::to_string(sections.size()) + " sections but the board has " +
                                             std::to_string(S) + " columns (calibrate writes one section per "
                                             "column; was /board/cols edited?)");
    Depth(edges[e], ew);
    for (size_t k = 0; k < sections.size(); ++k) {
      const Json& sec = sections[k];
      const std::string sw = ew + "/sections/" + std::to_string(k);
      const double u = Depth(sec, sw);
      // calibrate writes a section's depth as its midpoint's camera z; a different one was edited.
      const double z = sec["midpoint_camera_mm"][2].get<double>();
      if (!(std::abs(u - z) <= 1e-6 * std::max(1.0, std::abs(z))))
        throw InputError(sw + "/u_mm", "must be the depth of the section's midpoint_camera_mm (" + Num(z) +
                                           " mm), got " + Num(u));
      const Json& px = sec.contains("image_px") ? sec["image_px"] : Json();
      const bool shaped = px.is_array() && px.size() == 2 && px[0].is_array() && px[0].size() == 2 &&
                          px[1].is_array() && px[1].size() == 2 && px[0][0].is_number() && px[0][1].is_number() &&
                          px[1][0].is_number() && px[1][1].is_number();
      if (!shaped)
        throw InputError(sw + "/image_px", "must be the section's two ends in the photo, [[x, y], [x, y]] px, got " +
                                               px.dump().substr(0, 120));
      const bool usable = sec.contains("ok") && sec["ok"] == true;
      for (int p = 0; p < 2; ++p) {
        const double x = px[p][0].get<double>(), y = px[p][1].get<double>();
        // A usable section was measured in the photo: both its ends are in it. One that was not may lie beyond the
        // photo's border (a board partly out of view), but not beyond one photo's size past it.
        const bool inside = usable ? x >= 0 && x <= w && y >= 0 && y <= h
                                   : x >= -w && x <= 2 * w && y >= -h && y <= 2 * h;
        if (!inside)
          throw InputError(sw + "/image_px/" + std::to_string(p),
                           "must be inside the " + Num(w) + " x " + Num(h) + " px image" +
                               (usable ? " (the section is usable: it was measured there)"
                                       : " or less than one image's size beyond it") +
                               ", got [" + Num(x) + ", " + Num(y) + "]");
      }
    }
  }
}

}  // namespace blurcue::calib
