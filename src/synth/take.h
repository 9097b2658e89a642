#pragma once
// Ground-truth moving-camera takes: a fixed-focus lens on a camera moving closer to the board and sideways, frame by
// frame, each frame rendered by the still renderer (RenderScene) with its own pose, so every frame's truth (pose,
// section depths, the applied kernels' second moments) is exactly what a still's truth is.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "synth/scene.h"

namespace blurcue::synth {

struct TakeOptions {
  // The still's options for every frame: camera, board, tilt, lens floor, noise, seed ... . Its focus_mm is the
  // take's fixed focus (a number: a fixed-focus lens does not follow edge 1); edge1_u_mm and lateral_mm are
  // overridden per frame by the path below.
  SceneOptions scene;
  int frames = 12;
  double fps = 30;                 // frame rate of the take (time of frame i = i / fps)
  // The camera's path, linear in the frame index: edge 1's depth and the board's sideways offset, first -> last.
  double edge1_u_start_mm = 440, edge1_u_end_mm = 360;
  double lateral_start_mm = -25, lateral_end_mm = 25;
  TakeOptions() {
    scene.focus_mm = 450;          // inside the board for the whole path (edge 1 to edge 11 spans ~200 mm)
    scene.floor_sigma_px = 0.35;   // a real lens's floor
  }
};

struct TakeFrame {
  int index = 0;
  double time_s = 0;
  Scene scene;  // the frame (image, pose, sections' truth, truth json)
};

// Throws Error(kInput) naming the option (frames, fps, the path's ends, or a still option via RenderScene).
void ValidateTake(const TakeOptions& options);
// Renders frame `index` (0 .. frames - 1) of the take.
TakeFrame RenderTakeFrame(const TakeOptions& options, int index);

struct TakeFiles {
  int frames = 0;
  std::string video;        // file name of the video in the folder; empty when no writer could make one
  std::string video_codec;  // its fourcc ("FFV1", "MJPG")
};

// Renders every frame and writes DIR/frame-NNNN.png, DIR/truth-NNNN.json (the still's truth.json of that frame,
// readable by `calibrate --truth`), DIR/camera.json, DIR/take.json (options, fps, per-frame time and pose) and,
// where OpenCV's videoio can write one, DIR/take.avi (lossless FFV1 where available, else MJPEG). `progress` gets
// one line per frame.
TakeFiles WriteTake(const TakeOptions& options, const std::filesystem::path& dir,
                    const std::function<void(const std::string&)>& progress = {});

// The printf pattern of the frames in a take folder.
inline constexpr const char* kTakeFramePattern = "frame-%04d.png";
std::string TakeFrameName(int index);  // frame-0007.png
std::string TakeTruthName(int index);  // truth-0007.json

}  // namespace blurcue::synth
