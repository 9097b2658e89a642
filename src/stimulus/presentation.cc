#include "stimulus/stimulus.h"

#include <algorithm>
#include <cmath>

#include <opencv2/calib3d.hpp>

#include "core/error.h"
#include "scene/frame.h"
#include "scene/objects.h"
#include "stimulus/internal.h"

namespace blurcue::stimulus {

Presentation Presentation::Of(const protocol::Protocol& protocol, const StimulusImages& images,
                              const display::Profile& profile) {
  Presentation p;
  p.window_width_px = protocol.display.width_px;
  p.window_height_px = protocol.display.height_px;
  p.profile = profile;
  // The prompt's band: a line of text at the display's scale (TextScreen's unit).
  if (std::any_of(protocol.blocks.begin(), protocol.blocks.end(), [](const auto& b) { return !b.prompt.empty(); }))
    p.prompt_band_px = std::max(32, protocol.display.height_px / 12);
  // The stimulus has the window above the prompt's band.
  const int W = p.window_width_px, H = p.window_height_px - p.prompt_band_px;
  if (protocol.content.type == protocol::ContentType::kPicture) {
    // The depth-matching frame, 4:3, as large as the window holds (the thesis's 960 x 720 in a 1280 x 720 one).
    p.layout = scene::DepthMatchingLayout::Of(std::min(W, H * 4 / 3), images.picture.size());
    p.frame_width_px = p.layout.frame.width;
    p.frame_height_px = p.layout.frame.height;
    p.scaling = "fit";
    p.view = {W, p.window_height_px, p.frame_width_px, p.frame_height_px, (W - p.frame_width_px) / 2,
              (H - p.frame_height_px) / 2};
    if (const auto& camera = protocol.content.real_camera)
      p.real_frame_px_per_px = p.layout.LowerScale(cv::Size(camera->image_width_px, camera->image_height_px));
    return p;
  }
  p.frame_width_px = images.photo.cols;
  p.frame_height_px = images.photo.rows;
  const int w = p.frame_width_px, h = p.frame_height_px;
  if (w <= 0 || h <= 0) return p;
  using protocol::Scaling;
  const Scaling scaling = protocol.display.scaling;
  double scale = 1;
  switch (scaling) {
    case Scaling::kFit: scale = scene::FitScale(w, h, W, H), p.scaling = "fit"; break;
    case Scaling::kNative: scale = 1, p.scaling = "native"; break;
    case Scaling::kScale: scale = protocol.display.scale, p.scaling = "scale"; break;
    case Scaling::kDegrees:
      scale = protocol.display.width_deg * display::PxPerDeg(profile) / w, p.scaling = "degrees";
      break;
  }
  // Whole screen px: the photo's shown width sets the scale recorded, its height follows.
  const double shown_w = std::round(w * scale);
  if (!(shown_w >= 8 && shown_w <= 16384 && h * scale >= 8 && h * scale <= 16384)) {
    const bool degrees = scaling == Scaling::kDegrees;
    throw InputError(protocol.file.string() + (degrees ? ": /display/width_deg" : ": /display/scale"),
                     "shows the " + std::to_string(w) + " x " + std::to_string(h) + " px photo " +
                         std::to_string(int(shown_w)) + " px wide" +
                         (degrees ? " (at " + std::to_string(display::PxPerDeg(profile)) + " px/deg)" : "") +
                         "; it must be 8 to 16384 px on screen");
  }
  p.scale = shown_w / w;
  const int pw = int(shown_w), ph = int(std::lround(h * p.scale));
  p.view = {W, p.window_height_px, pw, ph, (W - pw) / 2, (H - ph) / 2};
  return p;
}

double Presentation::LevelScreenPx(double cutoff) const {
  return cutoff > 0 ? ScreenPx(2 * scene::ButterworthEquivalentSigma(cutoff) * layout.picture.width) : 0;
}

scene::FrameView Presentation::ViewFor(const protocol::Protocol& protocol, const calib::SceneCalib& scene,
                                        const TrialScene& trial) const {
  scene::FrameView v = view;
  if (v.photo_width_px <= v.width_px && v.photo_height_px <= v.height_px - prompt_band_px) return v;
  // What the trial shows, in photo px: both objects at the start and at the end of their run.
  cv::Rect shows;
  for (const auto& objects : RunEnds(protocol, scene, trial))
    for (const auto& object : objects)
      if (object) {
        const cv::Rect b = scene::FootprintOf(scene.camera, scene.rvec, scene.tvec, object->object).bounds;
        shows = shows.empty() ? b : (shows | b);
      }
  if (shows.empty()) return v;
  // Centre it, then keep the window covered by the photo along any side where the photo is the larger.
  auto place = [](double centre_photo_px, double scale, int photo_px, int window_px) {
    if (photo_px <= window_px) return (window_px - photo_px) / 2;
    const int x = int(std::lround(window_px / 2.0 - (scale * (centre_photo_px + 0.5) - 0.5)));
    return std::clamp(x, window_px - photo_px, 0);
  };
  const double sx = double(v.photo_width_px) / frame_width_px, sy = double(v.photo_height_px) / frame_height_px;
  v.x_px = place(shows.x + shows.width / 2.0, sx, v.photo_width_px, v.width_px);
  v.y_px = place(shows.y + shows.height / 2.0, sy, v.photo_height_px, v.height_px - prompt_band_px);
  return v;
}

Json DescribeFrame(const calib::SceneCalib* scene, const TrialScene& trial, const Presentation& presentation,
                   const scene::FrameView& view, const std::array<std::optional<scene::BlurredObject>, 2>& shown,
                   double cutoff) {
  const display::Profile& profile = presentation.profile;
  auto round = [](double x, double unit) {  // to a decimal unit, printed as such
    const double per = std::round(1 / unit);
    return std::round(x * per) / per;
  };
  Json frame = {
      {"display",
       // The monitor (its px go with its mm) and the window on it.
       {{"width_px", profile.width_px}, {"height_px", profile.height_px}, {"width_mm", profile.width_mm},
        {"height_mm", profile.height_mm}, {"distance_mm", profile.distance_mm},
        {"px_per_deg", round(display::PxPerDeg(profile), 1e-4)}, {"profile", profile.name},
        {"window_px", {view.width_px, view.height_px}}}},
      {"scaling", presentation.scaling},
      {"screen_px_per_photo_px", round(presentation.scale, 1e-6)},
      {"photo_rect_px", {view.x_px, view.y_px, view.photo_width_px, view.photo_height_px}},
      {"blur_plan", trial.content == protocol::ContentType::kPicture ? "none" : trial.per_pixel ? "per_pixel" : "one_radius"},
      {"r_span_screen_px", std::round(trial.r_span_screen_px * 1e4) / 1e4},
      {"objects", Json::array()}};
  if (trial.content == protocol::ContentType::kPicture) {
    // The frame is shown at one screen px per frame px where `view` places it.
    const scene::DepthMatchingLayout& l = presentation.layout;
    auto on_screen = [&](const cv::Rect& r) { return Json{view.x_px + r.x, view.y_px + r.y, r.width, r.height}; };
    frame["picture"] = {{"rect_px", on_screen(l.picture)},
                        {"cutoff", cutoff},
                        {"r_screen_px", round(presentation.LevelScreenPx(cutoff), 1e-4)},
                        {"r_arcmin", round(presentation.LevelArcmin(cutoff), 1e-4)},
                        {"width_arcmin", round(presentation.Arcmin(l.picture.width), 1e-4)}};
    Json real = {{"rect_px", on_screen(l.lower)}, {"distance_m", trial.distance_m}};
    if (presentation.real_frame_px_per_px > 0) {
      real["r_camera_px"] = round(trial.r_scene_px, 1e-4);
      real["r_screen_px"] = round(presentation.ScreenPx(trial.r_scene_px * presentation.real_frame_px_per_px), 1e-4);
      real["r_arcmin"] = round(presentation.RealArcmin(trial.r_scene_px), 1e-4);
    }
    frame["real_picture"] = real;
    return frame;
  }
  if (!scene) return frame;
  const Camera camera = view.CameraOf(scene->camera);
  for (int side = 0; side < 2; ++side) {
    if (!shown[size_t(side)]) continue;
    const scene::BlurredObject& b = *shown[size_t(side)];
    const double floor = std::min(b.floor_sigma_px, std::max(0.0, b.r_px) / 2);  // as drawn (render::Psf)
    const std::vector<cv::Point2d> outline = scene::OutlineOf(camera, scene->rvec, scene->tvec, b.object);
    std::vector<cv::Point2d> centre;
    cv::projectPoints(std::vector<cv::Point3d>{cv::Point3d(b.object.center_board_mm)}, scene->rvec, scene->tvec,
                      cv::Matx33d(camera.Intrinsics().data()), camera.dist_coeffs, centre);
    Json polygon = Json::array();
    for (const cv::Point2d& p : outline) polygon.push_back({round(p.x, 1e-3), round(p.y, 1e-3)});
    frame["objects"].push_back(
        {{"side", protocol::ToString(protocol::Vocabulary<protocol::Side>::values[size_t(side)])},
         {"kind", b.object.kind == scene::VirtualObject::Kind::kBall ? "ball" : "card"},
         {"source", ToString(trial.sides[size_t(side)].source)},
         {"kernel", b.method},
         {"center_px", {round(centre[0].x, 1e-3), round(centre[0].y, 1e-3)}},
         {"outline_px", polygon},
         {"r_camera_px", round(b.r_px, 1e-4)},
         {"r_screen_px", round(presentation.ScreenPx(b.r_px), 1e-4)},
         {"r_arcmin", round(presentation.Arcmin(b.r_px), 1e-4)},
         // Under lens distortion the PSF is elliptical (its shape): the radius across a vertical edge (the profile
         // along x) and across a horizontal one (along y), as a section's r_px is measured across its edge.
         {"r_x_screen_px", round(presentation.ScreenPx(b.r_px * cv::norm(cv::Vec2d(b.shape(0, 0), b.shape(0, 1)))), 1e-4)},
         {"r_y_screen_px", round(presentation.ScreenPx(b.r_px * cv::norm(cv::Vec2d(b.shape(1, 0), b.shape(1, 1)))), 1e-4)},
         {"shape", {{round(b.shape(0, 0), 1e-6), round(b.shape(0, 1), 1e-6)},
                    {round(b.shape(1, 0), 1e-6), round(b.shape(1, 1), 1e-6)}}},
         // The PSF's parts (render/psf.h): r^2 = defocus_r^2 + 4 floor_sigma^2, and the motion streak beside it.
         {"floor_sigma_screen_px", round(presentation.ScreenPx(floor), 1e-4)},
         // The floor is inside the PSF the shape stretches: across a vertical and a horizontal edge, as the photo's.
         {"floor_sigma_x_screen_px", round(presentation.ScreenPx(floor * cv::norm(cv::Vec2d(b.shape(0, 0), b.shape(0, 1)))), 1e-4)},
         {"floor_sigma_y_screen_px", round(presentation.ScreenPx(floor * cv::norm(cv::Vec2d(b.shape(1, 0), b.shape(1, 1)))), 1e-4)},
         {"defocus_r_screen_px", round(presentation.ScreenPx(std::sqrt(std::max(0.0, b.r_px * b.r_px - 4 * floor * floor))), 1e-4)},
         {"motion_screen_px", {round(presentation.ScreenPx(b.motion_px[0]), 1e-4),
                               round(presentation.ScreenPx(b.motion_px[1]), 1e-4)}},
         {"exposure_ms", trial.exposure_ms},
         {"size_deg", round(display::ArcminOfScreenPx(profile, ExtentPx(outline)) / 60, 1e-4)}});
    if (b.r_of_depth_px) {
      // The per-pixel plan: each pixel of it is blurred for its own depth, so the frame shows the radii of its
      // visible surface, nearest to farthest depth (a ball's rim lies a little nearer than the centre r_screen_px
      // is given for).
      const scene::Footprint f = scene::FootprintOf(camera, scene->rvec, scene->tvec, b.object);
      double lo = 1e300, hi = -1e300;
      for (int i = 0; i <= 32; ++i) {
        const double r = std::max(0.0, b.r_of_depth_px(f.z_min_mm + (f.z_max_mm - f.z_min_mm) * i / 32));
        lo = std::min(lo, r), hi = std::max(hi, r);
      }
      frame["objects"].back()["r_range_screen_px"] = {round(presentation.ScreenPx(lo), 1e-4),
                                                      round(presentation.ScreenPx(hi), 1e-4)};
    }
  }
  return frame;
}

}  // namespace blurcue::stimulus
