#pragma once
// Speed against accuracy of the blur renderers, in one run on this machine: every method, radius and frame size on
// the GPU path (Mesa llvmpipe here) and the CPU reference, with the error against an exact convolution; and the
// test-2 frame (two moving balls at 1920 x 1080) drawn region by region against the thesis's whole-frame blur.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace blurcue::bench {

struct RenderRow {
  // "blur": one blur of a whole frame; "frame": a composed two-ball frame; "growth": how a region-by-region frame's
  // cost grows with one thing swept (method "objects", "size" or "radius"), the rest as in the two-ball frame.
  std::string kind;
  std::string method;   // gaussian, disc, butterworth; for frames: region or whole_frame; for growth: what is swept
  std::string backend;  // gl or cpu
  double radius_px = 0;
  int width = 0, height = 0;
  int samples = 0;
  double median_ms = 0, p99_ms = 0;
  double mean_abs_error = 0, max_abs_error = 0;  // 8-bit grey levels against the exact reference ("blur") or
                                                 // against the region approach ("frame"); NaN: not measured
  int objects = 0;      // balls in the frame (frame and growth rows)
};

struct RenderBenchOptions {
  bool quick = false;        // smaller sizes and fewer frames (a smoke run for CI)
  bool frames_only = false;  // only the two-ball frame comparison
  std::function<void(const std::string&)> progress;
};

std::vector<RenderRow> RunRenderBench(const RenderBenchOptions& options);
// The last column, quick, says a --quick (smoke) run made the rows: charts say so.
void WriteRenderCsv(const std::vector<RenderRow>& rows, const std::filesystem::path& path,
                     bool quick = false);
// The ratios the issue asks for, measured in this run.
std::string SummarizeRender(const std::vector<RenderRow>& rows);

}  // namespace blurcue::bench
