// blurcue estimate: the thesis's eq. 3.7 from one reference point to any depth, next to the signed thin-lens form.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "core/camera.h"
#include "core/error.h"
#include "core/json_io.h"
#include "optics/thin_lens.h"

namespace blurcue::cli {
namespace {

struct EstimateArgs {
  std::string camera;
  double ref_u_mm = 0;
  double ref_r_px = 0;
  std::vector<double> u_mm;
  bool ref_nearer = false;
  double pixel_pitch_mm = 0;  // 0: from the camera (sensor width / image width)
  bool json = false;
};

// One depth's answer; a model that does not hold there leaves its value empty and says why.
struct Row {
  double u_mm = 0;
  std::optional<double> eq37_px;
  std::string eq37_reason;
  std::optional<double> signed_px;
  std::string signed_reason;
};

std::string Px(double v) {
  char buf[32];
  // Two decimals, and no "-0.00" for a point on the focus plane.
  std::snprintf(buf, sizeof buf, "%.2f", std::abs(v) < 0.005 ? 0.0 : v);
  return buf;
}

std::string FocusText(double focus_mm) {
  if (std::isinf(focus_mm)) return "infinity";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f mm", focus_mm);
  return buf;
}

const char* Side(double signed_px) {
  // Below a hundredth of a pixel the sign is rounding, not a side.
  if (std::abs(signed_px) < 0.005) return "in focus";
  return signed_px > 0 ? "beyond" : "nearer";
}

Row Estimate(const optics::Lens& lens, const EstimateArgs& a, double r1_signed, double focus_mm, double u2) {
  Row row;
  row.u_mm = u2;
  // Each model is asked on its own: the signed form holds where the published one does not, and a u2 inside
  // the focal length is a note in its row, not the end of the whole table.
  try {
    row.signed_px = optics::Eq37SignedPx(lens, a.ref_u_mm, r1_signed, u2);
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::kDomain) throw;
    row.signed_reason = e.what();
  }
  if (a.ref_nearer) {
    row.eq37_reason = "eq. 3.7 as published assumes the reference beyond focus, but --ref-nearer-than-focus says "
                      "it is nearer: use the signed form";
  } else if (row.signed_px && *row.signed_px < 0) {
    row.eq37_reason = "u2 = " + Num(u2) + " mm is nearer than focus (" + FocusText(focus_mm) +
                      "); eq. 3.7 as published assumes both points beyond it: use the signed form";
  } else {
    try {
      row.eq37_px = optics::Eq37Px(lens, a.ref_u_mm, a.ref_r_px, u2);
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::kDomain) throw;
      row.eq37_reason = e.what();
    }
  }
  return row;
}

void PrintTable(const Camera& camera, const optics::Lens& lens, const EstimateArgs& a, double focus_mm,
                const std::vector<Row>& rows) {
  std::printf("camera %s: f = %g mm, N = %g (D = %.3f mm), pixel pitch %g mm%s\n", a.camera.c_str(),
              lens.focal_length_mm, camera.f_number, lens.aperture_mm, lens.pixel_pitch_mm,
              a.pixel_pitch_mm > 0 ? " (--pixel-pitch-mm)" : " (sensor width / image width)");
  std::printf("reference r1 = %.2f px at u1 = %.1f mm, %s focus: focus at u0 = %s\n", a.ref_r_px, a.ref_u_mm,
              a.ref_nearer ? "nearer than" : "beyond", FocusText(focus_mm).c_str());
  std::printf("%9s  %12s  %12s  %-8s  %s\n", "u2/mm", "eq3.7 r2/px", "signed r2/px", "side", "note");
  for (const Row& r : rows) {
    const std::string eq37 = r.eq37_px ? Px(*r.eq37_px) : "not valid";
    const std::string sgn = r.signed_px ? Px(*r.signed_px) : "not valid";
    const std::string note = !r.signed_px ? r.signed_reason : r.eq37_reason;
    std::printf("%9.1f  %12s  %12s  %-8s", r.u_mm, eq37.c_str(), sgn.c_str(), r.signed_px ? Side(*r.signed_px) : "-");
    if (note.empty())
      std::printf("\n");
    else
      std::printf("  %s\n", note.c_str());
  }
}

void PrintJson(const optics::Lens& lens, const EstimateArgs& a, double focus_mm, const std::vector<Row>& rows) {
  auto value = [](const std::optional<double>& v) { return v ? Json(*v) : Json(nullptr); };
  auto reason = [](const std::string& s) { return s.empty() ? Json(nullptr) : Json(s); };
  Json points = Json::array();
  for (const Row& r : rows)
    points.push_back({{"u_mm", r.u_mm},
                      {"eq37_px", value(r.eq37_px)},
                      {"eq37_reason", reason(r.eq37_reason)},
                      {"signed_px", value(r.signed_px)},
                      {"signed_reason", reason(r.signed_reason)},
                      {"r_px", r.signed_px ? Json(std::abs(*r.signed_px)) : Json(nullptr)},
                      {"side", r.signed_px ? Json(Side(*r.signed_px)) : Json(nullptr)}});
  const Json out = {{"camera", a.camera},
                    {"focal_length_mm", lens.focal_length_mm},
                    {"aperture_mm", lens.aperture_mm},
                    {"pixel_pitch_mm", lens.pixel_pitch_mm},
                    {"reference", {{"u_mm", a.ref_u_mm}, {"r_px", a.ref_r_px},
                                   {"side", a.ref_nearer ? "nearer" : "beyond"}}},
                    {"focus_mm", std::isinf(focus_mm) ? Json("infinity") : Json(focus_mm)},
                    {"points", points}};
  std::cout << out.dump(2) << "\n";
}

}  // namespace

void AddEstimateCommand(CLI::App& app) {
  auto args = std::make_shared<EstimateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "estimate",
      "Predict the defocus blur radius at other depths from one measured reference, by the thesis's eq. 3.7.\n"
      "Eq. 3.7 (thin lens, similar triangles): a point at depth u1 blurred to radius r1 fixes where the lens is\n"
      "focused, and with it the radius r2 at any depth u2:\n"
      "  r2 = [ u1 (u2 - f) / (u2 (u1 - f)) * (2 r1 sigma + D) - D ] / (2 sigma)\n"
      "with f the focal length, D = f / N the aperture diameter and sigma the pixel pitch (mm per pixel).\n"
      "As published it assumes both points lie beyond the focus plane; the signed form (negative = nearer than\n"
      "focus) holds on both sides, and the table shows both, plus the focus distance u0 the reference implies.\n"
      "Units: depths u in mm along the optical axis from the lens (camera z), radii r in pixels.\n"
      "Example (the thesis: f = 21 mm, f/5.6, sigma = 5.1e-3 mm; 8 px at edge 1 gives 16.61 px at edge 11):\n"
      "  blurcue estimate --camera thesis-camera.json --pixel-pitch-mm 0.0051 --ref-u-mm 342.3 --ref-r-px 8 \\\n"
      "      --u-mm 527.3 400 230");
  cmd->add_option("--camera", args->camera,
                  "camera.json: focal_length_mm, f_number, sensor_width_mm, sensor_height_mm, image_width_px,\n"
                  "image_height_px")
      ->required();
  // No CLI11 validators on the camera and u1: a missing file and a u1 inside the focal length are errors of the
  // input (exit 3) and of the model (exit 5), each one line naming what is wrong, like every other command's.
  // Their ranges are what a number can mean at all (finite, a depth of at most 1000 m); whether u1 lies beyond
  // f is the model's to say.
  cmd->add_option("--ref-u-mm", args->ref_u_mm, "u1: depth of the reference point in mm (must exceed f)")
      ->required()->check(FiniteRange(0, 1e6, "mm"));
  cmd->add_option("--ref-r-px", args->ref_r_px, "r1: measured blur radius at u1 in px (>= 0)")->required()
      ->check(FiniteRange(0, optics::kMaxBlurRadiusPx, "px", "for a reference in front of focus add "
                                                              "--ref-nearer-than-focus"));
  cmd->add_option("--u-mm", args->u_mm, "u2: one or more depths in mm to predict the blur at")
      ->required()->check(FinitePositive(1e6, "mm"));
  cmd->add_flag("--ref-nearer-than-focus", args->ref_nearer,
                "the reference lies in front of the focus plane (its signed radius is -r1)");
  cmd->add_option("--pixel-pitch-mm", args->pixel_pitch_mm,
                  "sigma in mm per pixel instead of sensor_width_mm / image_width_px (the thesis rounded it to\n"
                  "5.1e-3; its camera's 23.4 mm / 4592 px is 5.096e-3)")
      ->check(FinitePositive(1, "mm"));
  cmd->add_flag("--json", args->json, "print JSON instead of a table; a model that does not hold gives null and a "
                                      "reason");
  cmd->callback([args] {
    const EstimateArgs& a = *args;
    const Camera camera = LoadCamera(a.camera);
    optics::Lens lens = optics::Lens::FromCamera(camera);
    if (a.pixel_pitch_mm > 0) lens.pixel_pitch_mm = a.pixel_pitch_mm;
    const double r1_signed = a.ref_nearer ? -a.ref_r_px : a.ref_r_px;
    double focus_mm;
    try {
      // Also the check that the reference is possible at all: u1 beyond f, and not more near-side blur than
      // this lens makes.
      focus_mm = optics::FocusFromReferenceMm(lens, a.ref_u_mm, r1_signed);
    } catch (const Error& e) {
      throw Error(e.kind(), "reference (--ref-u-mm " + Num(a.ref_u_mm) + ", --ref-r-px " + Num(a.ref_r_px) +
                                "): " + e.what());
    }
    std::vector<Row> rows;
    for (double u2 : a.u_mm) rows.push_back(Estimate(lens, a, r1_signed, focus_mm, u2));
    if (a.json)
      PrintJson(lens, a, focus_mm, rows);
    else
      PrintTable(camera, lens, a, focus_mm, rows);
  });
}

}  // namespace blurcue::cli
