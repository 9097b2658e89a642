#include "live/live_plan.h"

#include <chrono>
#include <set>
#include <utility>

#include "core/error.h"
#include "core/typed.h"
#include "track/take.h"

namespace blurcue::live {
namespace {

// What differs between the camera tracking runs with and the one the lens was calibrated with ("" when none).
std::string CameraDifference(const Camera& lens, const Camera& given) {
  if (lens.image_width_px != given.image_width_px || lens.image_height_px != given.image_height_px)
    return "its image is " + std::to_string(lens.image_width_px) + " x " + std::to_string(lens.image_height_px) +
           " px, --camera's " + std::to_string(given.image_width_px) + " x " + std::to_string(given.image_height_px);
  if (lens.Intrinsics() != given.Intrinsics()) return "its intrinsics differ from --camera's";
  if (lens.dist_coeffs != given.dist_coeffs) return "its dist_coeffs differ from --camera's";
  if (lens.focal_length_mm != given.focal_length_mm || lens.f_number != given.f_number)
    return "its focal length or f-number differs from --camera's";
  return "";
}

calib::SceneCalib WithoutSections(calib::SceneCalib c, const Camera& camera, const std::string& where) {
  if (const std::string d = CameraDifference(c.camera, camera); !d.empty())
    throw InputError(where, "is not of --camera's camera: " + d + " (a lens model holds for the camera it was fitted on)");
  c.sections.clear();
  return c;
}

}  // namespace

calib::SceneCalib LensFromCalib(const std::filesystem::path& calib_json, const Camera& camera) {
  return WithoutSections(calib::LoadSceneCalib(calib_json), camera, calib_json.string());
}

calib::SceneCalib LensFromTrack(const std::filesystem::path& track_dir, const Camera& camera) {
  const stimulus::TrackedTake take = stimulus::LoadTrackedTake(track_dir);
  for (const stimulus::TrackedFrame& f : take.frames)
    if (f.calib) return WithoutSections(*f.calib, camera, (track_dir / track::CalibFileName(f.index)).string());
  throw InputError(track_dir.string(), "has no frame with a pose");  // LoadTrackedTake refuses it first
}

void RequireLiveSource(BlurSource source, const std::string& option) {
  if (source == BlurSource::kMeasured || source == BlurSource::kMeasuredSection)
    throw Error(ErrorKind::kUsage, option + " " + ToString(source) +
                                       ": needs each frame's board sections measured, and live measures a few a "
                                       "frame at most (--measure-sections, which feed its lens model); give fitted "
                                       "(the lens model), estimated, none or a radius in px");
}

bool LiveLens::Update(const calib::CalibResult& frame) {
  for (const calib::EdgeResult& edge : frame.edges)
    for (const calib::SectionResult& s : edge.sections) {
      const std::pair<int, int> key(s.edge, s.section);
      if (s.fit.ok) {
        latest_[key] = {s.u_mm, s.fit.r_px / s.stretch, 1.0};  // ideal px, as calib::ModelSamples gives them
        changed_ = true;
      } else if (!s.fit.flags.empty()) {
        changed_ |= latest_.erase(key) > 0;  // measured and flagged: its earlier reading no longer stands
      }
    }
  if (!changed_ || fit_.valid()) return false;
  std::vector<optics::BlurSample> samples;
  samples.reserve(latest_.size());
  std::set<int> edges;
  for (const auto& [key, sample] : latest_) samples.push_back(sample), edges.insert(key.first);
  if (edges.size() < 3) return false;
  changed_ = false;
  fit_ = std::async(std::launch::async, [lens = optics::Lens::FromCamera(camera_), samples = std::move(samples)] {
    try {
      return std::optional(optics::FitThinLens(lens, samples));
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::kNotFound) throw;  // all at one depth: no model from these readings
      return std::optional<optics::FittedModel>();
    }
  });
  return true;
}

bool LiveLens::TakeModel(optics::FittedModel* model) {
  if (!fit_.valid() || fit_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return false;
  const std::optional<optics::FittedModel> fitted = fit_.get();  // a fit's unexpected error surfaces here
  if (!fitted) return false;
  *model = *fitted;
  sections_ = fitted->samples_used;
  return true;
}

void LiveLens::Wait() {
  if (fit_.valid()) fit_.wait();
}

void LivePlanner::SetModel(const optics::FittedModel& model) {
  for (stimulus::TrackedFrame& f : window_.frames)
    if (f.calib) f.calib->model = model;
}

LivePlanner::LivePlanner(calib::SceneCalib lens, std::vector<stimulus::PlacedObject> objects, stimulus::TakeBlur blur)
    : objects_(std::move(objects)), blur_(std::move(blur)) {
  window_.frames.resize(2);
  window_.frames[1].calib = std::move(lens);
}

stimulus::TrackedFramePlan LivePlanner::Plan(int index, double time_s, track::FrameStatus status,
                                             const std::optional<calib::BoardPose>& pose) {
  stimulus::TrackedFrame& now = window_.frames[1];
  stimulus::TrackedFrame& last = window_.frames[0];
  now.index = index;
  now.time_s = time_s;
  now.status = status;
  if (!pose) return {};
  now.calib->rvec = pose->rvec;
  now.calib->tvec = pose->tvec;
  stimulus::TrackedFramePlan plan = stimulus::PlanTrackedFrame(window_, 1, objects_, blur_);
  // This frame is the next one's "before": its pose and time kept in the calibration made for it once.
  if (!last.calib) last.calib = now.calib;
  last.calib->rvec = now.calib->rvec;
  last.calib->tvec = now.calib->tvec;
  last.index = index;
  last.time_s = time_s;
  last.status = status;
  return plan;
}

}  // namespace blurcue::live
