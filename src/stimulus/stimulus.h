#pragma once
// What a trial shows, worked out from the protocol, the trial and the calibrated scene before anything is drawn:
// TrialScene, its objects per frame, the blur plan, and how a frame maps to the screen and the eye (Presentation).
// Pure, no GL: session's StimulusRenderer draws exactly these, and the runner records them.
//   grid    - two 5x5 grid cards lying on the table beside the board, left and right of it, aligned with an edge
//             (test 1), each blurred by its side's source at its own depth;
//   ball    - two balls rolling side by side along sections 3 and 5 of the board (tests 2 and 3): edge 1 -> 11 at
//             the pattern's speed, or with a `section` s only from edge s to s + 1 and then wiped;
//   picture - the depth-matching frame (thesis 3.2): the picture low-passed at the adjusted cut-off on grey above,
//             below the photo of the real picture at the trial's distance (content.real_photos), or the scene
//             photo when the protocol names no real photos.
#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/scene_blur.h"
#include "display/profile.h"
#include "protocol/protocol.h"
#include "protocol/trials.h"
#include "scene/frame.h"

namespace blurcue::stimulus {

class VideoTake;

// What one side of a pair (grid, ball) shows, from the protocol's source to the record: each quantity spelled once,
// the record's column names made from it and the side's word (store::SideColumn).
struct SideShown {
  // The source as shown (swaps applied), and a fixed source's radius (photo px).
  calib::BlurSource source = calib::BlurSource::kNone;
  double fixed_px = 0;
  // Across the board (x, 0 at its left edge): NaN for the default place - a card beside the board, a ball on section 3
  // (left) or 5 (right). From the level left_x_mm / right_x_mm.
  double x_mm = std::numeric_limits<double>::quiet_NaN();
  // A procedure's level on the test side (ApplyLevel): the radius is gain x its source's + add_px.
  double gain = 1, add_px = 0;
  // The radius rendered (photo px), averaged over the run for balls.
  double r_px = 0;
  // The lens floor inside the radius (std, photo px; calib::FloorSigmaPx of the source at the object's place, averaged
  // over the run for balls): a scene source's defocus is drawn convolved with the scene's floor.
  double floor_sigma_px = 0;
  // A ball's streak over the exposure (photo px, image x right, y down), averaged over the run like the radius.
  cv::Vec2d motion_px{0, 0};
  // The object's largest extent on screen at onset (visual angle, deg; PlanOnScreen).
  double size_deg = 0;
  // Where the object is in depth and in the picture (the right one at the left's place in an intervals trial),
  // averaged over a ball's run like the radius: its centre's depth u (camera z, mm: DESIGN.md's u) and its centre's
  // image below the photo's principal point (photo px, down positive; the calibrated camera's distortion included).
  double u_mm = 0, below_axis_px = 0;
};

struct TrialScene {
  protocol::ContentType content = protocol::ContentType::kGrid;
  // Pairs (grid, ball): what each side shows, indexed by protocol::Index(side) (side() below).
  std::array<SideShown, 2> sides;
  int edge = 1;                       // grid: the edge the cards are aligned with (0: placed by y_mm)
  double from_y_mm = 0, to_y_mm = 0;  // along the board's y (0 at edge 1): a ball's run, a card's place
  // Grid: the card's width and height (mm; 0: two board squares, square), upright or flat, turned about the
  // vertical; grid and ball: raised above the table (content defaults, or the levels height_mm / rotation_deg).
  double card_width_mm = 0, card_height_mm = 0, rotation_deg = 0, height_mm = 0;
  bool standing = false;
  double speed_mm_s = 0;              // ball: 0 = at rest at from_y_mm
  bool wipe_at_end = false;           // ball: disappear on arrival (a section run)
  double distance_m = 0;              // picture: the real picture's distance
  protocol::Kernel kernel = protocol::Kernel::kGaussian;  // pairs: the blur kernel, and the object's matching
  double brightness = 1, contrast = 1;
  std::array<double, 3> white_balance{1, 1, 1};  // red, green, blue gains
  double level = std::numeric_limits<double>::quiet_NaN();  // the procedure's level shown; NaN: none (yet)
  // Only the left object: the layout single's one object, or one interval of an intervals trial (IntervalScene).
  bool left_only = false;
  int intervals = 0;       // the intervals a pair trial shows one after the other (protocol::IntervalCount), else 0
  // The scene's own blur (the fitted model) at the objects' places (a picture: the real picture's), averaged like
  // the sides' radii.
  double r_scene_px = 0;
  // Motion blur: the exposure (content.exposure_ms; 0: none) each ball's streak (SideShown::motion_px) lasts.
  double exposure_ms = 0;
  // A study on video: the take plays while the trial is shown (VideoTake), so every frame is composed again.
  bool video = false;

  // The blur plan (PlanOnScreen): per pixel by depth when an object's depth span changes its radius on screen by at least
  // the protocol's depth_blur_threshold, else one radius at its centre.
  bool per_pixel = false;
  double r_span_screen_px = 0;  // the largest change of r across an object's depth, both sides, start and end of a run

  // The side `side` of the pair.
  SideShown& side(protocol::Side side) { return sides[protocol::Index(side)]; }
  const SideShown& side(protocol::Side side) const { return sides[protocol::Index(side)]; }
  // Seconds of motion (0 for a static stimulus).
  double MotionS() const;
  // The balls' y (board frame, mm) at t_s after onset; negative infinity when wiped.
  double BallYMm(double t_s) const;
};

// Works out a trial's scene. `scene` may be null for a picture. Throws Error naming the protocol file and the
// trial when a level needed is missing or a source cannot be evaluated (e.g. eq. 3.7 nearer than focus).
// A side's fixed radius given on the screen ({"screen_px": r} or {"arcmin": r}) is turned into photo px by
// `presentation` (and its profile): without one it is an input error.
struct Presentation;
TrialScene DescribeTrial(const protocol::Protocol& protocol, const protocol::Trial& trial,
                         const calib::SceneCalib* scene, const Presentation* presentation = nullptr);

// What a pair trial (grid or ball) shows t_s after onset: each side's object where it is at that moment and the blur
// radius (photo px) it gets there, the lens floor inside it (a scene source's) and, for a rolling ball with an exposure,
// its motion streak; [0] left, [1] right, empty for a ball wiped at the end of its section. No GL:
// StimulusRenderer::Compose draws exactly these, and the runner records each frame's radii from them.
std::array<std::optional<scene::BlurredObject>, 2> ObjectsAt(const protocol::Protocol& protocol,
                                                              const calib::SceneCalib& scene, const TrialScene& trial,
                                                              double t_s);

struct Presentation;

// A procedure block's trial at `level` (protocol::Procedure): its test side's radius becomes (1 + level) x the
// reference's (relative_difference), or the reference's plus level arcmin on the screen (difference_arcmin; the
// arcmin turned into photo px by the presentation). Updates the side's gain or add_px and the recorded radii; run
// PlanOnScreen after it.
void ApplyLevel(const protocol::Procedure& procedure, const protocol::Trial& trial, double level,
                const Presentation& presentation, TrialScene* scene);

// One interval of an intervals trial (two_intervals, odd_one_out): the left side's object, or with `right` the right
// side's, alone at the left object's place.
TrialScene IntervalScene(const TrialScene& scene, bool right);

// Whether interval `i` (0-based) of `trial` shows the right side's object: the second of two intervals; in an
// odd-one-out trial the odd one (test_side "1".."n").
bool IntervalShowsRight(const protocol::Trial& trial, const TrialScene& scene, int i);

// Works out what the screen `presentation` shows of a pair trial: each object's size in degrees at onset
// (each side's size_deg) and the blur plan - each object's radius at its nearest and farthest depth (along
// its line of sight), at the start and the end of its run, against the protocol's depth_blur_threshold (arcmin
// converted by the display profile), setting per_pixel and r_span_screen_px.
void PlanOnScreen(const protocol::Protocol& protocol, const calib::SceneCalib& scene, const Presentation& presentation,
              TrialScene* trial);

// Throws Error(kInput) naming the protocol field that asked for it when what `trial` shows (`scene`, its sides'
// gains and additions as ApplyLevel left them) cannot be drawn on the screen `presentation` describes: a radius (at any
// depth of the object, as the per-pixel plan draws it) or a rolling ball's motion streak longer than the largest blur
// the renderer draws (optics::kMaxBlurRadiusPx screen px). The field is the side's source, or `level_pointer` with
// `level_text` (a procedure's largest level: "/blocks/0/procedure/max", "its largest level, 3") when a level set it;
// a streak names /content/exposure_ms. What validate checks so that run does not stop at that trial.
void CheckBlurOnScreen(const protocol::Protocol& protocol, const protocol::Trial& trial, const calib::SceneCalib& s,
                       const Presentation& presentation, const TrialScene& scene, const std::string& level_pointer = "",
                       const std::string& level_text = "");

// The protocol's calibration (none for a picture without one). Throws Error(kInput) naming the protocol file and
// /scene/calib when the file is not a calibration written by `blurcue calibrate` (kNotACalibration, the reader's
// reason after it).
inline constexpr const char* kNotACalibration = "not a calibration from blurcue calibrate: ";
std::optional<calib::SceneCalib> LoadProtocolScene(const protocol::Protocol& protocol);

// The images a protocol's trials show, decoded (8-bit) and checked against what shows them.
struct StimulusImages {
  cv::Mat photo;    // the scene photo shown (BGR; for a grid or ball the calibrated camera's size)
  cv::Mat picture;  // picture: the picture (alpha kept)
  cv::Mat texture;  // grid or ball: the card's or the ball's texture
  // A study on video: the tracked take, its frames decoded (photo is its first frame with a pose); null for a photo.
  std::shared_ptr<const VideoTake> take;
};

// How a frame reaches the screen and the eye. A grid or ball trial is composed at the window's size: the photo
// resampled (linear light, area filter) by `scale` screen px per photo px, as the protocol's display.scale or
// width_deg says, and the objects drawn and blurred at screen resolution; a photo larger than the window is cropped
// around what the trial shows (ViewFor). A picture's frame is fitted 4:3 into the window at one screen px per frame
// px. The display profile turns screen px into visual angle; a radius is recorded in all three units.
struct Presentation {
  int frame_width_px = 0, frame_height_px = 0;  // the photo, or the picture's frame
  int window_width_px = 0, window_height_px = 0;
  double scale = 1;         // screen px per frame (photo) px
  std::string scaling;      // "fit" | "native" | "scale" | "degrees"
  // A band this high at the bottom of the window holds the response prompt (responses.prompt; 0: none): the
  // stimulus is fitted, centred and cropped in the window above it.
  int prompt_band_px = 0;
  scene::FrameView view;   // the photo's place before a trial moves it (centred, or letterboxed when it fits)
  display::Profile profile;

  // picture: the frame's parts (frame px; the virtual picture's outline among them), and the frame px per px of the
  // real photos' camera (content.real_camera, the lower half's scale; 0 without one).
  scene::DepthMatchingLayout layout;
  double real_frame_px_per_px = 0;

  double ScreenPx(double frame_px) const { return frame_px * scale; }
  double Arcmin(double frame_px) const { return display::ArcminOfScreenPx(profile, ScreenPx(frame_px)); }
  // picture: the blur as shown (blurcue's r, arcmin) of the virtual picture low-passed at `cutoff` cycles per picture
  // width (its equivalent Gaussian, scene::ButterworthEquivalentSigma; 0 = sharp), and of the real picture blurred
  // by r_camera_px (px of the real camera's full image).
  double LevelArcmin(double cutoff) const { return display::ArcminOfScreenPx(profile, LevelScreenPx(cutoff)); }
  double LevelScreenPx(double cutoff) const;
  double RealArcmin(double r_camera_px) const { return Arcmin(r_camera_px * real_frame_px_per_px); }
  // Where a pair trial shows the photo: `view` when the scaled photo fits the window; else cropped so that what the
  // trial shows (both objects over their whole run) is centred, as far as the photo reaches.
  scene::FrameView ViewFor(const protocol::Protocol& protocol, const calib::SceneCalib& scene,
                            const TrialScene& trial) const;
  // Throws Error(kInput) naming /display/width_deg or /display/scale when the photo would be smaller than 8 px or
  // larger than 16384 px on screen.
  static Presentation Of(const protocol::Protocol& protocol, const StimulusImages& images,
                         const display::Profile& profile);
};

// What a frame shows, in screen terms (run --capture's trial-NNNN.json): the display (the monitor's width_px,
// height_px, width_mm, height_mm, distance_mm, px_per_deg, and window_px, the window's size), where the photo sits (scaling, screen_px_per_photo_px,
// photo_rect_px), the blur plan (blur_plan, r_span_screen_px) and every object on it: side, kind, source, kernel, center_px (its pose's centre), outline_px (the
// screen polygon of its silhouette), r_camera_px, r_screen_px, r_arcmin (its PSF without the motion, 2 x the std of
// its line-spread function, as the measurement states it; under distortion the geometric mean of the elliptical PSF's
// principal radii), r_x_screen_px and r_y_screen_px (the radius across a vertical and a horizontal edge: the profile
// along x and along y), shape (the PSF's map of determinant 1, identity when round), floor_sigma_screen_px and defocus_r_screen_px (its parts:
// r^2 = defocus_r^2 + 4 floor_sigma^2; round values), floor_sigma_x_screen_px and floor_sigma_y_screen_px (the floor
// across a vertical and a horizontal edge, stretched by the shape as r_x and r_y are), motion_screen_px ([x, y], the streak over exposure_ms) and size_deg (the
// outline's largest extent).
// A picture's frame (`scene` may be null; no objects) instead: the virtual picture (rect_px, its outline before the
// blur; cutoff, the level shown; its blur as r_screen_px and r_arcmin; width_arcmin) and the real one (rect_px, the
// lower half; distance_m; with content.real_camera its blur as r_camera_px, r_screen_px and r_arcmin).
Json DescribeFrame(const calib::SceneCalib* scene, const TrialScene& trial, const Presentation& presentation,
                   const scene::FrameView& view, const std::array<std::optional<scene::BlurredObject>, 2>& shown,
                   double cutoff = 0);

// Reads every image the protocol names: each must decode as an image of a size its use can show. Throws
// Error(kInput) naming the protocol file and the field (/scene/background, /content/texture, ...). No GL.
StimulusImages LoadStimulusImages(const protocol::Protocol& protocol, const std::optional<calib::SceneCalib>& scene);

// Decodes the real photo (content.real_photos) of every distance the trials show that is not in `checked` yet, and
// adds it there (a study's participants share their photos: each is decoded once); throws naming
// /content/real_photos. No GL.
void CheckRealPhotos(const protocol::Protocol& protocol, const std::vector<TrialScene>& scenes,
                     std::set<double>* checked);

}  // namespace blurcue::stimulus
