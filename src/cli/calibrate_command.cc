#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <vector>
#include <cstdio>
#include <iostream>
#include <string>

#include "calib/calib_checks.h"
#include "calib/calibrate.h"
#include "calib/truth.h"
#include "cli/commands.h"
#include "core/error.h"
#include "core/output_guard.h"
#include "core/own_output.h"
#include "core/image.h"
#include "optics/fit.h"

namespace blurcue::cli {

namespace {

// A pose that fits badly, or a lens model far from the camera's f-number: warnings on stderr (even with --quiet).
void WarnAboutCalibration(const calib::CalibResult& result, const Camera& camera, const std::string& camera_file,
                          const std::string& photo_file) {
  // A pose that fits its corners badly: the camera is not this photo's (distortion, sensor, focal length).
  if (result.pose.reprojection_error_px > calib::kPoseSuspectPx)
    std::fprintf(stderr,
                 "blurcue: warning: %s: the board's corners fit the pose only to %.2f px (a photo of this camera "
                 "fits to well under 1 px): check its dist_coeffs, sensor size and focal length; the depths and "
                 "blurs measured rest on that pose\n",
                 camera_file.c_str(), result.pose.reprojection_error_px);
  // A lens model whose aperture is far from the camera's f-number fits sections that may not measure the board's
  // edges (an edge covered or shaded reads sharp: a covered board gave focus 21 mm and an aperture of 0). Far: over
  // two thirds of a stop either way (kApertureWarnFactor; 0.6 x and 1.29 x passed unsaid under the old bound of 2 x).
  // Where the phase check found a filter after sampling, that is the first suspect: it adds one variance to every
  // section's blur (a sharpening takes it away); a family that does not quite match the camera's filter leaves the fit
  // to bend focus and aperture (a mask of amount 0.5 over 0.8 px, focus 300 mm: 1.42 x before the phase check read
  // turned and large sections with the family; amount 0.7 1.33 x until the sections it cancels to 0 px were taken as
  // bounds, 1.05 x since).
  const bool filtered = result.phase.chosen != 0 && result.phase.chosen < result.phase.families.size();
  if (calib::ApertureFarFromNominal(result, camera) && filtered)
    std::fprintf(stderr,
                 "blurcue: warning: %s: the fitted aperture %.3f mm is %.2f x the camera's (%.3f mm, f/%g), more "
                 "than two thirds of a stop off: the photo was processed after it was sampled (the phase check found "
                 "%s), which the lens model does not represent, so its focus and aperture are bent to fit; "
                 "photograph the board again with the camera's sharpening or smoothing off (or raw)\n",
                 photo_file.c_str(), result.model.aperture_mm, calib::ApertureRatio(result, camera), camera.ApertureMm(),
                 camera.f_number, result.phase.families[result.phase.chosen].Name().c_str());
  else if (calib::ApertureFarFromNominal(result, camera))
    std::fprintf(stderr,
                 "blurcue: warning: %s: the fitted aperture %.3f mm is %.2f x the camera's (%.3f mm, f/%g), more "
                 "than two thirds of a stop off: the sections may not measure the board's edges (covered, shaded, "
                 "reflections; see the table's flags) or camera.json's f_number is not the photo's\n",
                 photo_file.c_str(), result.model.aperture_mm, calib::ApertureRatio(result, camera), camera.ApertureMm(),
                 camera.f_number);
}

// The board, the reference edge, the fitted model and the sections it was fitted to.
void PrintCalibrationSummary(const calib::CalibResult& result, const Board& board, const Camera& camera) {
  const auto& m = result.model;
  std::printf("board %s found; pose reprojection error %.3f px; board origin %.1f mm from the lens\n",
              board.Name().c_str(), result.pose.reprojection_error_px, cv::norm(result.pose.tvec));
  // calibrate.cc's SetReference takes a reference edge's phase_limited readings where none of its sections is usable.
  const calib::EdgeResult& ref = result.edges[result.reference_edge - 1];
  if (ref.usable > 0)
    std::printf("reference edge %d: u = %.1f mm, r = %.2f px (median of its usable sections)\n",
                result.reference_edge, result.reference_u_mm, result.reference_r_px);
  else
    std::printf("reference edge %d: u = %.1f mm, r = %.2f px (median of its phase_limited sections' readings: none "
                "of them is usable, so eq. 3.7's estimates below are as unsure as they are; --reference-edge N takes "
                "another edge)\n",
                result.reference_edge, result.reference_u_mm, result.reference_r_px);
  const std::string far = calib::ApertureFarFromNominal(result, camera)
                              ? ", " + Num(std::round(calib::ApertureRatio(result, camera) * 100) / 100) +
                                    " x: more than two thirds of a stop off"
                              : "";
  // Its samples: the sections it is fitted to, and the middles of the phase_limited ranges that held it.
  const std::string held = result.phase.held > 0 ? " (" + std::to_string(m.samples_used - result.phase.held) +
                                                       " sections and " + std::to_string(result.phase.held) +
                                                       " held ranges' middles)"
                                                 : "";
  std::printf("fitted %s model: focus %.1f mm, aperture %.3f mm (nominal %.3f%s), %s, rms %.3f px,"
              " leave-one-out %.3f px, %d outliers of its %d samples%s%s\n",
              m.kind.c_str(), m.focus_mm, m.aperture_mm, camera.ApertureMm(), far.c_str(),
              optics::FloorText(m).c_str(), m.rms_px, m.loo_rms_px, m.outliers, m.samples_used, held.c_str(),
              result.phase.variance_px2 < 0 ? " (fitted to the optics' readings under the sharpening: rms in their px)"
                                            : "");
  // How many sections the model was fitted to, and why the others were left out.
  {
    int sections = 0;
    for (const auto& e : result.edges) sections += static_cast<int>(e.sections.size());
    std::string left;
    int n_left = 0;
    for (const auto& [why, n] : calib::SectionsLeftOut(result))
      left += (left.empty() ? "" : ", ") + std::to_string(n) + " " + why, n_left += n;
    std::printf("the model is fitted to %d of %d sections%s\n", sections - n_left, sections,
                left.empty() ? "" : ("; left out at their readings (it predicts them): " + left).c_str());
    // What each flag means, once (phase_limited has its own lines below), and the informational ones.
    for (const auto& [why, n] : calib::SectionsLeftOut(result))
      if (why != "phase_limited") std::printf("  %s: %s\n", why.c_str(), calib::SectionFlagMeaning(why).c_str());
    for (const std::string& flag : calib::InformationalFlags()) {
      int n = 0;
      for (const auto& e : result.edges)
        for (const auto& sec : e.sections)
          n += std::find(sec.fit.flags.begin(), sec.fit.flags.end(), flag) != sec.fit.flags.end();
      if (n > 0 && flag != "short")  // short: its own line below
        std::printf("%d sections flagged %s: %s\n", n, flag.c_str(), calib::SectionFlagMeaning(flag).c_str());
    }
    // phase_limited sections flagged only by a sharpening's amplification, the valley or their noise join the fit.
    int n_joined = 0;
    for (const auto& e : result.edges)
      for (const auto& sec : e.sections) n_joined += sec.phase.joins_fit;
    if (n_joined > 0)
      std::printf("%d of them phase_limited but joined at their readings (a sharpening that cancels most of the "
                  "optics' blur there, masks along the chosen one's valley that read them apart, or an edge near a "
                  "pixel centre): each reading unsure alone, pooled by the fit\n",
                  n_joined);
    // Sections used but read on a shorter central part (a neighbouring X-junction within the blur's reach): said,
    // as the flag in calib.json says it, since such a reading can run a few per cent high.
    int n_short = 0;
    for (const auto& e : result.edges)
      for (const auto& sec : e.sections)
        n_short += sec.fit.ok && std::find(sec.fit.flags.begin(), sec.fit.flags.end(), "short") != sec.fit.flags.end();
    if (n_short > 0)
      std::printf("%d of them read on a shorter central part (flag short: an X-junction within the blur's reach of "
                  "the usual half)\n", n_short);
  }
}

// The phase check's summary, and each edge with phase_limited sections.
void PrintPhaseCheck(const calib::CalibResult& result) {
  std::printf("phase check: %s\n", result.phase.summary.c_str());
  // Each edge with phase_limited sections, once, with its first section's reason (every one's is in calib.json).
  for (const auto& e : result.edges) {
    int n = 0;
    const std::string* why = nullptr;
    for (const auto& sec : e.sections)
      if (!sec.fit.phase_why.empty()) ++n, why = why ? why : &sec.fit.phase_why;
    if (n > 0) std::printf("  edge %d: %d of %zu sections phase_limited: %s\n", e.index, n, e.sections.size(),
                           why->c_str());
  }
  if (result.phase.held > 0)
    std::printf("phase check: the model predicted %d phase_limited sections outside the range their families "
                "leave open; their ranges' middles joined its fit\n", result.phase.held);
  // What to do about them: a filter after sampling is in every section (a turned board is read with it at any angle
  // to the pixel axes, but it still cancels or blurs what the lens did); without one, turning the board gives every
  // edge all phases.
  if (result.phase.flagged > 0) {
    if (result.phase.chosen != 0)
      std::printf("what to do: this photo was filtered after it was sampled (the camera's sharpening or smoothing); "
                  "for measured blur on the flagged edges turn that processing off (or take raw) and photograph "
                  "again; until then the blur source `fitted` gives those places the model's value%s\n",
                  !result.undetermined.Named()
                      ? ""
                      : (" (an estimate at " + Num(std::round(result.undetermined.lo_mm)) + "-" +
                         Num(std::round(result.undetermined.hi_mm)) +
                         " mm, where it is not determined within 5 %)").c_str());
    else
      std::printf("what to do: for measured blur on the flagged edges turn the board a few degrees on the table so "
                  "its edges cross the pixel rows (every phase is then sampled); until then `measured` averages an "
                  "edge's readings, those flagged as unsure alone included, and `fitted` gives every place the "
                  "model's value\n");
  }
}

// Why this model (calib.json's model.choice): both candidates' held-out errors, and eq. 3.7 as published.
void PrintModelChoice(const calib::CalibResult& result, const Json& choice) {
  const auto& m = result.model;
  if (std::isfinite(m.floor_loo_rms_px))
    std::printf("model choice, held-out error: thin lens %.3f px, thin lens + floor %.3f px (%s)\n",
                m.thin_loo_rms_px, m.floor_loo_rms_px, optics::kModelChoiceRule);
  else
    std::printf("model: the thin lens alone (the floor model needs at least 10 sections; %d usable)\n",
                m.samples_used);
  if (choice["eq37"]["rms_px"].is_number())
    std::printf("eq. 3.7 (the thesis's estimate from reference edge %d, no parameters fitted): rms %.3f px against "
                "the measured sections%s\n",
                result.reference_edge, choice["eq37"]["rms_px"].get<double>(),
                m.kind == "thin_lens+floor" ? " (it takes the reference's whole blur for defocus, floor included)"
                                            : "");
  if (result.undetermined.Named()) std::printf("model: %s\n", result.undetermined.why.c_str());
}

// --truth: the pose and every method's blur against the ground truth; the true radius of each edge, for the table.
std::vector<double> PrintAgainstTruth(const calib::CalibResult& result, const std::string& truth_file) {
  const calib::TruthComparison cmp =
      calib::CompareToTruth(result, ReadJsonFile(truth_file), truth_file + ": ");
  std::printf("against truth: pose %.3f mm / %.3f deg, section depths within %.3f mm\n",
              cmp.translation_error_mm, cmp.rotation_error_deg, cmp.max_depth_error_mm);
  auto summary = [&](const char* name, calib::MethodError calib::SectionComparison::*method) {
    const calib::MethodSummary m = calib::SummarizeMethod(cmp, method);
    std::printf("  %-22s answered %2d/%d, mean |error| %.3f px, worst %.3f px, within max(0.25 px, 5%%): %d\n",
                name, m.answered, m.sections, m.mean_abs_error_px, m.max_abs_error_px, m.within_target);
  };
  summary("model fit (r_px)", &calib::SectionComparison::model);
  summary("thesis (r_thesis_px)", &calib::SectionComparison::thesis);
  summary("eq. 3.7 (r_estimated)", &calib::SectionComparison::estimated);
  summary("fitted (r_fitted_px)", &calib::SectionComparison::fitted);
  return cmp.true_r_per_edge;
}

// --truth of another scene was read as this one's (a truth's pose 221 mm / 89 deg from the one found, printed as the
// calibration's error): its board and camera must be the ones given, before anything is measured.
void CheckTruthScene(const Json& truth, const std::string& file, const Board& board, const Camera& camera,
                     const std::string& camera_file) {
  const std::string other = ": the truth of another scene";
  if (truth.contains("board") && truth["board"].is_object()) {
    const Json& b = truth["board"];
    const bool same = b.value("cols", board.cols) == board.cols && b.value("rows", board.rows) == board.rows &&
                      std::abs(b.value("square_mm", board.square_mm) - board.square_mm) <= 1e-9 * board.square_mm;
    if (!same)
      throw Error(ErrorKind::kInput, "--truth " + file + ": /board is " + std::to_string(b.value("cols", 0)) + "x" +
                                         std::to_string(b.value("rows", 0)) + " of " +
                                         Num(b.value("square_mm", 0.0)) + " mm, not the --board " + board.Name() +
                                         " of " + Num(board.square_mm) + " mm given" + other);
  }
  if (!truth.contains("camera") || !truth["camera"].is_object()) return;
  const std::pair<const char*, double> fields[] = {
      {"focal_length_mm", camera.focal_length_mm},       {"f_number", camera.f_number},
      {"sensor_width_mm", camera.sensor_width_mm},       {"sensor_height_mm", camera.sensor_height_mm},
      {"image_width_px", double(camera.image_width_px)}, {"image_height_px", double(camera.image_height_px)}};
  for (const auto& [key, given] : fields) {
    const Json v = truth["camera"].value(key, Json());
    if (v.is_number() && std::abs(v.get<double>() - given) > 1e-6 * std::abs(given))
      throw Error(ErrorKind::kInput, "--truth " + file + ": /camera/" + key + " is " + Num(v.get<double>()) + ", " +
                                         camera_file + "'s " + Num(given) + other);
  }
}

// After detection: the truth's pose must put the board where the photo shows it. Each corner found is matched to the
// nearest of the truth's projected corners (so a board read half a turn round still matches: that is the
// calibration's error, which --truth is there to print); the median distance is a small fraction of a pixel for the
// truth of this photo (its pose 0.03 mm / 0.004 deg from the one found), 19 px for the same scene turned 25 deg.
void CheckTruthPose(const Json& truth, const std::string& file, const calib::CalibResult& result, const Board& board,
                    const Camera& camera, const std::string& photo_file) {
  if (!truth.contains("pose") || !truth["pose"].is_object()) return;  // CompareToTruth names what is missing
  auto vec3 = [](const Json& j, cv::Vec3d& out) {
    if (!j.is_array() || j.size() != 3) return false;
    for (size_t i = 0; i < 3; ++i) {
      if (!j[i].is_number()) return false;
      out[int(i)] = j[i].get<double>();
    }
    return true;
  };
  calib::BoardPose pose;
  if (!vec3(truth["pose"].value("rvec", Json()), pose.rvec) || !vec3(truth["pose"].value("tvec", Json()), pose.tvec))
    return;
  std::vector<std::array<double, 3>> points;
  for (int iy = 1; iy <= board.InnerCornersY(); ++iy)
    for (int ix = 1; ix <= board.InnerCornersX(); ++ix)
      points.push_back({ix * board.square_mm, iy * board.square_mm, 0});
  const std::vector<cv::Point2d> projected = calib::Project(pose, camera, points);
  std::vector<double> nearest;
  for (const cv::Point2f& c : result.pose.corners) {
    double best = INFINITY;
    for (const cv::Point2d& q : projected) best = std::min(best, std::hypot(c.x - q.x, c.y - q.y));
    nearest.push_back(best);
  }
  if (nearest.empty()) return;
  std::nth_element(nearest.begin(), nearest.begin() + long(nearest.size() / 2), nearest.end());
  const double median = nearest[nearest.size() / 2];
  if (!(median <= 2))
    throw Error(ErrorKind::kInput, "--truth " + file + ": its pose puts the board's corners " + Num(median) +
                                       " px (median) from those found in " + photo_file +
                                       ": the truth of another scene (nothing written)");
}

}  // namespace

void AddCalibrateCommand(CLI::App& app) {
  struct Args {
    std::string photo, camera, out = "calib.json", board = "7x10", truth;
    double square_mm = 25;
    int reference_edge = 1;
    bool quiet = false, no_phase_check = false, board_turned = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Measure the defocus blur of a photographed checkerboard and predict it for the whole scene.\n"
      "Finds the board, solves the camera pose, measures every edge section (edge 1 = nearest line of the board,\n"
      "11 edges x 7 sections on a 7x10 board) twice - the thesis's threshold count (r_thesis_px) and a robust\n"
      "model fit in linear light (r_px) - then estimates every section from the reference edge by eq. 3.7\n"
      "(r_estimated_px) and from a thin-lens model fitted to all usable sections (r_fitted_px).\n"
      "Blur radius r is in pixels: 2 x the standard deviation of the edge's line-spread function.\n"
      "Example: blurcue calibrate scene.png --camera camera.json --out calib.json");
  cmd->add_option("photo", args->photo, "photo of the scene with the board (PNG/JPEG, sRGB)")
      ->required()->check(CLI::ExistingFile);
  cmd->add_option("--camera", args->camera,
                  "camera.json: focal_length_mm, f_number, sensor_width_mm, sensor_height_mm, image_width_px,\n"
                  "image_height_px [, camera_matrix, dist_coeffs]")
      ->required()->check(CLI::ExistingFile);
  cmd->add_option("--board", args->board, "board size in squares, COLSxROWS")->capture_default_str();
  cmd->add_option("--square-mm", args->square_mm, "side of one square in mm")->capture_default_str()
      ->check(FiniteRange(1, 1000, "mm"));
  cmd->add_option("--reference-edge", args->reference_edge, "edge whose measured blur feeds eq. 3.7")
      ->capture_default_str()->transform(IntRange(1, 1000));
  cmd->add_option("--out", args->out, "where to write calib.json")->capture_default_str();
  cmd->add_option("--truth", args->truth,
                  "truth.json of a ground-truth scene (blurcue synth-scene): adds the true radius to the table\n"
                  "and prints the pose and blur errors of every method")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--no-phase-check", args->no_phase_check,
                "take every section's blur fit as it reads, also where the edge runs along the pixel rows with blur\n"
                "near or below a pixel (none flagged phase_limited; to compare: docs/definitions.md)");
  cmd->add_flag("--board-turned", args->board_turned,
                "take a board found with its edges within 10 deg of running straight away from the camera (refused\n"
                "without it: every edge then lies at one depth, and a 10x7 board so found is likelier a 7x10 one)");
  cmd->add_flag("--quiet", args->quiet, "print only errors");
  cmd->callback([args] {
    const auto t0 = std::chrono::steady_clock::now();
    OutputGuard guard;
    guard.Input("PHOTO", args->photo).Input("--camera", args->camera);
    if (!args->truth.empty()) guard.Input("--truth", args->truth);
    guard.OutputFile("--out", args->out).Check();
    // What the guard lets pass may still be someone's: a protocol, a camera.json that is not --camera's.
    RequireOwnFile("--out", args->out, "a calib.json calibrate wrote", Holds("\"format\": \"blurcue-calib\""));
    const Board board = Board::Parse(args->board, args->square_mm);
    const Camera camera = LoadCamera(args->camera);
    Json truth;
    if (!args->truth.empty()) {
      truth = ReadJsonFile(args->truth);
      CheckTruthScene(truth, args->truth, board, camera, args->camera);
    }
    const cv::Mat photo = ReadImage(args->photo, 1 /* cv::IMREAD_COLOR */);
    const double read_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    calib::CalibrateOptions options;
    options.reference_edge = args->reference_edge;
    options.phase_check = !args->no_phase_check;
    options.detect.refuse_edges_into_depth_deg = args->board_turned ? 0 : 10;
    calib::CalibResult result;
    try {
      result = calib::Calibrate(photo, camera, board, options);
    } catch (const Error& e) {
      // Name the files the error is about: the photo for a missing board, the camera for a size mismatch.
      throw Error(e.kind(), (e.kind() == ErrorKind::kInput ? args->camera : args->photo) + ": " + e.what());
    }
    if (!args->truth.empty()) CheckTruthPose(truth, args->truth, result, board, camera, args->photo);
    // A calibration absurd for its photo (a blur no section could show, edges no blurred edge explains) is refused
    // before anything is written.
    calib::RefuseAbsurdCalibration(result, args->camera, args->photo);
    Json json = calib::CalibToJson(result);
    json["photo"] = args->photo;
    WriteJsonFile(args->out, json);
    WarnAboutCalibration(result, camera, args->camera, args->photo);
    if (args->quiet) return;
    PrintCalibrationSummary(result, board, camera);
    if (options.phase_check) PrintPhaseCheck(result);
    PrintModelChoice(result, json["model"]["choice"]);
    const std::vector<double> true_r =
        args->truth.empty() ? std::vector<double>() : PrintAgainstTruth(result, args->truth);
    std::printf("\n%s", calib::FormatEdgeTable(result, true_r).c_str());
    std::printf("measured: the mean r_px of the edge's usable sections and of those pooled into the lens fit, the "
                "value blur source `measured` draws there ([in brackets] where only pooled readings give it; '-': "
                "refused); thesis: the thesis's pixel count (r_thesis_px, "
                "section 4.3), kept for comparison with it only: it counts the edge's whole grey ramp and runs "
                "several px over the optical blur; eq3.7: the thesis's estimate from reference edge %d; fitted: the "
                "lens model's prediction (blur source `fitted`)%s%s\n\n",
                result.reference_edge,
                !result.undetermined.Named() ? "" : ", in parentheses where it is not determined within 5 %",
                true_r.empty() ? "" : "; true: the scene's truth");
    std::printf("time: read %.0f ms, detect+pose %.0f ms, measure %.0f ms, estimate %.1f ms\n", read_ms,
                result.detect_ms, result.measure_ms, result.estimate_ms);
    std::printf("wrote %s\n", args->out.c_str());
  });
}

}  // namespace blurcue::cli
