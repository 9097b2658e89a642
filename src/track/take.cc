#include "track/take.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <sstream>

#include "core/atomic_file.h"
#include "core/json_io.h"

namespace blurcue::track {
namespace {

std::string Number(double v, int digits) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

void WriteTakeInto(const TakeResult& take, const std::filesystem::path& dir, const std::string& input);

}  // namespace

const std::vector<TrackColumn> kTrackColumns = {
    {"frame", "frame index from 0"},
    {"time_s", "frame time: index / frame rate (the video's own rate, or --fps for a sequence)"},
    {"status", "found (full detection), tracked (carried from the previous frames) or lost (no pose)"},
    {"reprojection_error_px", "RMS distance of the inner corners from the solved pose's projection, px"},
    {"rvec_x", "pose rotation (Rodrigues vector, board frame -> camera), rad"},
    {"rvec_y", ""},
    {"rvec_z", ""},
    {"tvec_x_mm", "board origin in the camera frame, mm"},
    {"tvec_y_mm", ""},
    {"tvec_z_mm", ""},
    {"focus_mm", "the take's lens model: focus distance, mm (inf: at infinity)"},
    {"aperture_mm", "the take's lens model: effective aperture diameter, mm"},
    {"floor_px", "the take's lens model: blur floor added in quadrature, px (0: the thin lens alone was kept; empty where "
                 "floor_determined is 0)"},
    {"floor_determined", "1: the sections pin the floor (or the thin lens alone was kept); 0: floors from "
                         "model.choice[\"thin_lens+floor\"].floor_range_px in calib-NNNN.json fit alike, so floor_px is "
                         "not a result (the model still predicts with the value in calib-NNNN.json)"},
    {"usable_sections", "edge sections whose blur measurement is usable"},
    {"pose_ms", "time spent tracking (or detecting) and solving the pose, ms"},
    {"measure_ms", "time spent measuring every section's blur and the frame's estimates, ms"},
    {"frame_ms", "all of the frame's work (decoding excluded), ms"},
    {"note", "why tracking fell back to detection, or why the frame is lost"},
};

std::string CalibFileName(int index) {
  char name[32];
  std::snprintf(name, sizeof name, "calib-%04d.json", index);
  return name;
}

TakeResult TrackTake(FrameSource& source, Tracker& tracker, const std::function<void(const FrameResult&)>& progress) {
  TakeResult take;
  // The next frame is read and decoded on a thread of its own while this one is tracked (decoding is a third of a
  // frame's time, and the measurement's stripes leave a core idle at their ends): the frames, their order and the
  // errors are the reader's, one frame ahead. Two buffers take turns: a frame is never decoded into the one tracked.
  struct Read {
    cv::Mat frame;
    int index = 0;
    double time_s = 0;
    bool got = false;
    double decode_ms = 0;
  };
  auto read = [&source](Read* r) {
    const auto t0 = std::chrono::steady_clock::now();
    r->got = source.Next(&r->frame, &r->index, &r->time_s);
    r->decode_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  };
  Read buffers[2];
  Read *now = &buffers[0], *next = &buffers[1];
  std::future<void> ahead = std::async(std::launch::async, read, now);
  for (;;) {
    try {
      ahead.get();  // an input error of the frame read ahead surfaces here, in its turn
      if (!now->got) break;
      take.decode_ms += now->decode_ms;
      ahead = std::async(std::launch::async, read, next);
      take.frames.push_back(tracker.Process(now->frame, now->index, now->time_s));
      take.frames.back().signature = FrameSignature(now->frame);
    } catch (const Error& e) {
      if (ahead.valid()) ahead.wait();  // the reader is done with its buffer before the take ends
      if (e.kind() != ErrorKind::kInput) throw;
      take.error = e;
      break;
    }
    std::swap(now, next);  // the buffers' roles, not their contents: the reader is filling *next
    const FrameResult& r = take.frames.back();
    switch (r.status) {
      case FrameStatus::kFound: ++take.found; break;
      case FrameStatus::kTracked: ++take.tracked; break;
      case FrameStatus::kLost: ++take.lost; break;
    }
    if (progress) progress(r);
  }
  try {
    take.model = FitTakeModel(take.frames);
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::kNotFound) throw;
    if (!take.error) take.error = e;
  }
  return take;
}

bool IsTrackFile(const std::string& name) {
  // What an earlier version, which wrote into DIR itself, left when killed: .track.csv.tmp-PID. The folder is
  // replaced whole, so it goes with the rest.
  const size_t tmp = name.rfind(".tmp-");
  if (name.size() > 1 && name[0] == '.' && tmp != std::string::npos && tmp + 5 < name.size() &&
      name.find_first_not_of("0123456789", tmp + 5) == std::string::npos)
    return IsTrackFile(name.substr(1, tmp - 1));
  const bool calib = name.size() > 11 && name.rfind("calib-", 0) == 0 && name.compare(name.size() - 5, 5, ".json") == 0 &&
                     name.find_first_not_of("0123456789", 6) == name.size() - 5;
  return calib || name == "track.csv";
}

void WriteTake(const TakeResult& take, const std::filesystem::path& dir, const std::string& input) {
  // Built whole beside `dir`: a calibration of an earlier track, of a frame this take does not pose, would
  // contradict track.csv, and a kill half way must not leave old and new files side by side.
  WriteFolderAtomically(dir, [&](const std::filesystem::path& partial) { WriteTakeInto(take, partial, input); },
                        IsTrackFile);
}

namespace {

void WriteTakeInto(const TakeResult& take, const std::filesystem::path& dir, const std::string& input) {
  std::ostringstream csv;
  for (size_t i = 0; i < kTrackColumns.size(); ++i) csv << (i ? "," : "") << kTrackColumns[i].name;
  csv << "\n";
  for (const FrameResult& f : take.frames) {
    csv << f.index << "," << Number(f.time_s, 6) << "," << Name(f.status) << ",";
    if (f.calib) {
      const calib::CalibResult& c = *f.calib;
      csv << Number(c.pose.reprojection_error_px, 4);
      for (int k = 0; k < 3; ++k) csv << "," << Number(c.pose.rvec[k], 8);
      for (int k = 0; k < 3; ++k) csv << "," << Number(c.pose.tvec[k], 4);
      int usable = 0;
      for (const auto& e : c.edges) usable += e.usable;
      // A floor the sections cannot pin is not printed as a result (optics::FloorText says it in words).
      const bool pinned = optics::FloorPinned(c.model);
      csv << "," << Number(c.model.focus_mm, 3) << "," << Number(c.model.aperture_mm, 5) << ","
          << (pinned ? Number(c.model.floor_px, 4) : std::string()) << "," << (pinned ? 1 : 0) << "," << usable;
      Json json = calib::CalibToJson(c);
      json["photo"] = input;
      json["frame"] = f.index;
      json["time_s"] = f.time_s;
      json["track_status"] = Name(f.status);
      json["frame_signature"] = f.signature;
      json["lens_model"] = "one model for the whole take (fixed focus and aperture): fitted to every usable section "
                           "of every frame";
      WriteJsonFile(dir / CalibFileName(f.index), json);
    } else {
      csv << ",,,,,,,,,,,0";  // no pose, no model for this frame
    }
    std::string note = f.note;
    for (char& ch : note)
      if (ch == '"') ch = '\'';
    csv << "," << Number(f.pose_ms, 2) << "," << Number(f.measure_ms, 2) << "," << Number(f.frame_ms, 2) << ",\""
        << note << "\"\n";
  }
  WriteFileAtomically(dir / "track.csv", csv.str());
}

}  // namespace

}  // namespace blurcue::track
