#include "synth/take.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/media.h"

#include "core/error.h"
#include "core/image.h"
#include "core/json_io.h"

namespace blurcue::synth {
namespace {

std::string Indexed(const char* pattern, int index) {
  char name[64];
  std::snprintf(name, sizeof name, pattern, index);
  return name;
}

// The frame's still: the path's point at `index`, linear from start to end.
SceneOptions FrameOptions(const TakeOptions& o, int index) {
  SceneOptions s = o.scene;
  const double t = o.frames > 1 ? double(index) / (o.frames - 1) : 0;
  s.edge1_u_mm = o.edge1_u_start_mm + t * (o.edge1_u_end_mm - o.edge1_u_start_mm);
  s.lateral_mm = o.lateral_start_mm + t * (o.lateral_end_mm - o.lateral_start_mm);
  return s;
}

}  // namespace

std::string TakeFrameName(int index) { return Indexed(kTakeFramePattern, index); }
std::string TakeTruthName(int index) { return Indexed("truth-%04d.json", index); }

void ValidateTake(const TakeOptions& o) {
  if (o.frames < 1 || o.frames > 10000)
    throw InputError("frames", "must be in [1, 10000], got " + std::to_string(o.frames));
  if (!(o.fps > 0 && o.fps <= 1000)) throw InputError("fps", "must be in (0, 1000] frames per second, got " + Num(o.fps));
  if (!std::isfinite(o.scene.focus_mm))
    throw InputError("focus_mm", "a take's lens has one fixed focus distance (a number of mm), got " +
                                     Num(o.scene.focus_mm));
  for (auto [name, v] : {std::pair{"edge1_u_start_mm", o.edge1_u_start_mm}, {"edge1_u_end_mm", o.edge1_u_end_mm},
                         {"lateral_start_mm", o.lateral_start_mm}, {"lateral_end_mm", o.lateral_end_mm}})
    if (!std::isfinite(v)) throw InputError(name, "must be finite, got " + Num(v));
}

TakeFrame RenderTakeFrame(const TakeOptions& o, int index) {
  ValidateTake(o);
  if (index < 0 || index >= o.frames)
    throw Error(ErrorKind::kInternal, "take frame " + std::to_string(index) + " of " + std::to_string(o.frames));
  TakeFrame f;
  f.index = index;
  f.time_s = index / o.fps;
  // Every frame is a still of its own pose (the renderer is the stills' one). The board and table stay put, so the
  // texture and flaws follow the take's seed in every frame; the sensor noise is drawn anew per frame.
  SceneOptions s = FrameOptions(o, index);
  s.noise_seed = o.scene.seed + 0x9E3779B97F4A7C15ULL * static_cast<uint64_t>(index + 1);
  f.scene = RenderScene(s);
  f.scene.truth["generator"] = "blurcue synth-take";
  f.scene.truth["take"] = {{"frame", index}, {"frames", o.frames}, {"time_s", f.time_s}, {"fps", o.fps}};
  return f;
}

TakeFiles WriteTake(const TakeOptions& o, const std::filesystem::path& dir,
                    const std::function<void(const std::string&)>& progress) {
  ValidateTake(o);
  for (int i = 0; i < o.frames; ++i) CheckSceneOptions(FrameOptions(o, i));  // nothing written for a path out of view
  std::filesystem::create_directories(dir);
  TakeFiles files;
  media::VideoWriter video;
  Json frames = Json::array();
  for (int i = 0; i < o.frames; ++i) {
    const TakeFrame f = RenderTakeFrame(o, i);
    WriteImage(dir / TakeFrameName(i), f.scene.image);
    WriteJsonFile(dir / TakeTruthName(i), f.scene.truth);
    if (i == 0) {
      Camera camera = f.scene.camera;
      camera.exposure_ms = 0;  // each frame is rendered at one pose: an instantaneous shutter, no streak in the take
      WriteJsonFile(dir / "camera.json", CameraToJson(camera));
      if (const char* codec = OpenLosslessVideo(video, dir / "take.avi", o.fps, f.scene.image.size())) {
        files.video = "take.avi";
        files.video_codec = codec;
      }
    }
    if (video.IsOpened()) video.Write(f.scene.image);
    frames.push_back({{"frame", i},
                      {"file", TakeFrameName(i)},
                      {"truth", TakeTruthName(i)},
                      {"time_s", f.time_s},
                      {"pose", f.scene.truth["pose"]}});
    if (progress)
      progress("frame " + std::to_string(i + 1) + "/" + std::to_string(o.frames) + ": edge 1 at " +
               Num(std::round(f.scene.sections.front().u_mm * 10) / 10) + " mm");
  }
  video.Release();
  files.frames = o.frames;
  Json take = {{"generator", "blurcue synth-take"},
               {"frames", o.frames},
               {"fps", o.fps},
               {"frame_pattern", kTakeFramePattern},
               {"video", files.video.empty() ? Json(nullptr) : Json(files.video)},
               {"video_codec", files.video_codec.empty() ? Json(nullptr) : Json(files.video_codec)},
               {"focus_mm", o.scene.focus_mm},
               {"floor_sigma_px", o.scene.floor_sigma_px},
               {"path", {{"edge1_u_start_mm", o.edge1_u_start_mm}, {"edge1_u_end_mm", o.edge1_u_end_mm},
                         {"lateral_start_mm", o.lateral_start_mm}, {"lateral_end_mm", o.lateral_end_mm},
                         {"interpolation", "linear in the frame index"}}},
               {"per_frame", frames}};
  WriteJsonFile(dir / "take.json", take);
  return files;
}

}  // namespace blurcue::synth
