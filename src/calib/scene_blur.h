#pragma once
// A calibrated scene read back from calib.json, and the blur it calls for at any 3-D point: what the renderer asks
// when it places virtual content (thesis section 4.4: "the blur on any point in the camera scene could be
// calculated now").
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/model_undetermined.h"
#include "core/blur_source.h"
#include "core/board.h"
#include "core/camera.h"
#include "core/json_io.h"
#include "optics/fit.h"

namespace blurcue::calib {

struct SceneCalib {
  Camera camera;
  Board board;
  cv::Vec3d rvec, tvec;  // board frame -> camera, mm
  int reference_edge = 1;
  double reference_u_mm = 0, reference_r_px = 0;
  optics::FittedModel model;
  struct Section {
    int edge = 0, section = 0;
    cv::Vec3d midpoint_camera_mm;
    double r_px = 0;
    bool ok = false;
    // Flagged phase_limited yet joined to the lens fit at its reading (calib.json phase.joins_fit): unsure alone, its
    // edge's mean pools it (the blur source `measured`), `measured_section` does not take it.
    bool pooled = false;
    // Where it is in calib.json ("/edges/0/sections/3") and its flags there ("phase_limited"), for a message.
    std::string pointer, flags;
  };
  std::vector<Section> sections;
  // The calib.json it was read from (empty: built in code), for a message.
  std::string file;
  // Where calibrate found the lens model not determined within 5 % (calib.json model.undetermined); none named: hi 0.
  ModelUndetermined undetermined;

  // Board-frame point (mm) -> camera frame (mm).
  cv::Vec3d ToCamera(const cv::Vec3d& board_mm) const;
  // Throws Error(kInput) naming `photo_path` unless the photo has the calibrated camera's size.
  void RequireSameSize(const cv::Mat& photo, const std::string& photo_path) const;
};

// Reads calib.json as written by `blurcue calibrate`; errors name the file and the JSON pointer.
SceneCalib LoadSceneCalib(const std::filesystem::path& path);
SceneCalib SceneCalibFromJson(const Json& json, const std::string& where);

// The sources of blur: core's one vocabulary (core/blur_source.h), which protocols name too.
using ::blurcue::BlurSource;
using ::blurcue::ToString;
// A word of BlurSourceWords() ("none", "measured", ...) or a number (a fixed radius in px), as a command takes it.
// Throws Error(kUsage) otherwise, with a did-you-mean, its line starting "OPTION: " where the option is given.
BlurSource ParseBlurSource(const std::string& text, double* fixed_r_px, const std::string& option = "");

// Blur radius (px) the scene calls for at a camera-frame point:
//   measured  - the thesis's edge value (its Fig. 4.11): the mean r_px of the usable sections of the board edge
//               whose line (from the board and its pose) passes nearest the point; a card beside the board aligned
//               with edge k gets edge k's value whichever side it is on; Error(kInput) naming calib.json, the edge's
//               sections' "ok" and their flags when it has no usable section (never another edge's value);
//   measured_section - r_px of the nearest measured section alone (3-D distance between midpoints);
//               Error(kInput) naming calib.json, the section's "ok" and its flags when it is not usable (never
//               another section's value);
//   estimated - eq. 3.7 from the reference edge at the point's depth (Error(kDomain) nearer than focus);
//   fitted    - the fitted thin-lens model at the point's depth (ideal px), times StretchAt the point (photo px);
//   fixed     - fixed_r_px; none - 0.
double BlurAtPx(const SceneCalib& scene, BlurSource source, const cv::Vec3d& point_camera_mm, double fixed_r_px = 0);

// The board edge whose line passes nearest a point (camera frame, mm): the edge blur source `measured` reads there.
int NearestEdge(const SceneCalib& scene, const cv::Vec3d& point_camera_mm);

// Where `source` is `measured` and `edge` has no usable section, only readings flagged phase_limited and pooled into
// the lens fit (an edge near focus: the init example's edge 1 reads 0.30 px for a true 0): one sentence saying what
// that value is, for a command's note (render, validate, run), as UndeterminedNote says it of `fitted`; "" otherwise.
std::string PooledNote(const SceneCalib& scene, BlurSource source, int edge);

// Where a source's blur comes from in the calibration, for a message about a radius it gave: " (the lens model,
// calib.json /model)"; "" for none and a fixed radius (the command's own).
std::string BlurFrom(const SceneCalib& scene, BlurSource source);

// Where `source` is the fitted model and camera depth u_mm lies where calibrate found that model not determined
// within 5 %: one sentence saying so, with the depths and calib.json's field, for a command's note (render, validate,
// run); "" otherwise. The number drawn there is the model's estimate, not a result within 5 %.
std::string UndeterminedNote(const SceneCalib& scene, BlurSource source, double u_mm);

// How much camera.json's dist_coeffs stretch a round blur at a camera-frame point's place in the photo: sqrt(det J)
// of the distortion map there (core/distortion.h), 1 without distortion. Photo px per ideal (pinhole) px.
double StretchAt(const SceneCalib& scene, const cv::Vec3d& point_camera_mm);

// The lens floor (std, photo px) inside the blur `source` gives at a camera-frame point: for the scene's own blur
// (measured, measured_section, fitted) the fitted model's floor r0 as a std (r0 / 2, DESIGN.md's r = 2 std; 0 when
// the model kept none) times StretchAt the point (the model's floor is in ideal px), which a virtual object's defocus
// is drawn convolved with so that its PSF is the photo's; 0 for estimated, fixed and none.
double FloorSigmaPx(const SceneCalib& scene, BlurSource source, const cv::Vec3d& point_camera_mm);

// The shape (render::Psf::shape) the blur `source` gives a virtual object at a camera-frame point: for the scene's
// own blur the distortion's Jacobian J at the point's ideal image position over sqrt(det J), so that the object's
// PSF (defocus x floor) is stretched along and across as the photo's blur is there; the identity for estimated
// (eq. 3.7 as published), fixed and none, and without distortion.
cv::Matx22d ShapeAt(const SceneCalib& scene, BlurSource source, const cv::Vec3d& point_camera_mm);

// The source's radius on the line of sight through an object's centre (camera frame, mm) at camera depth z_mm: what
// a pixel of the object at that depth gets when it is blurred per pixel by depth. Where the source cannot be
// evaluated there (eq. 3.7 as published, in front of the focus plane) the centre's radius stands in.
double BlurAlongSightPx(const SceneCalib& scene, BlurSource source, const cv::Vec3d& centre_camera_mm, double z_mm,
                        double fixed_r_px = 0);

}  // namespace blurcue::calib
