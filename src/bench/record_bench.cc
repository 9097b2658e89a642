#include "bench/record_bench.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <vector>

#include "core/error.h"
#include "core/stats.h"
#include "protocol/vocabulary.h"
#include "store/record.h"

namespace blurcue::bench {

RecordBenchResult RunRecordBench(const RecordBenchOptions& options) {
  if (options.trials < 1 || options.frames_per_trial < 0)
    throw Error(ErrorKind::kUsage, "bench record: trials must be >= 1 and frames >= 0");
  std::error_code error;
  std::filesystem::create_directories(options.folder, error);
  if (error) throw InputError(options.folder.string(), "cannot create the folder: " + error.message());
  struct Arm {
    bool durable;
    std::filesystem::path path;
    std::optional<store::Record> record;
    int64_t session = 0;
    std::vector<double> ms;
  };
  Arm arms[2] = {{true, options.folder / "bench-record-full.sqlite", {}, 0, {}},
                 {false, options.folder / "bench-record-normal.sqlite", {}, 0, {}}};
  std::vector<store::TrialRecord> trials(static_cast<size_t>(options.trials));
  for (int i = 0; i < options.trials; ++i) {
    trials[size_t(i)].index = i;
    trials[size_t(i)].factors_json = R"({"edge":)" + std::to_string(i % 11 + 1) + R"(,"practice":false})";
  }
  for (Arm& arm : arms) {
    for (const char* suffix : {"", "-wal", "-shm"}) std::filesystem::remove(arm.path.string() + suffix, error);
    store::RecordOptions record_options;
    record_options.durable = arm.durable;
    arm.record.emplace(store::Record::Open(arm.path, record_options));
    arm.session = arm.record->StartOrResumeSession("bench", "P1", R"({"name":"bench"})", 1, {}, false).session_id;
    arm.record->SaveTrialList(arm.session, trials);
  }
  std::vector<store::FrameRecord> frames(static_cast<size_t>(options.frames_per_trial));
  // As a moving pair records them: each flip with both sides' radii and the balls' place.
  for (int f = 0; f < options.frames_per_trial; ++f) {
    store::FrameRecord& frame = frames[size_t(f)];
    frame.frame_index = f;
    frame.flip_time_s = f / 60.0;
    frame.sides[0].r_px = 1.5 + 0.01 * f;
    frame.sides[1].r_px = 2.5 + 0.01 * f;
    frame.y_mm = 0.5 * f;
  }
  // Interleaved, so both arms meet the same moments of a shared, noisy machine.
  for (int i = 0; i < options.trials; ++i) {
    for (Arm& arm : arms) {
      store::Response response;
      response.choice = protocol::ToString(i % 2 ? protocol::Side::kLeft : protocol::Side::kRight);
      response.rt_ms = 700;
      const auto start = std::chrono::steady_clock::now();
      arm.record->RecordResponse(arm.session, i, response, frames);
      arm.ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
    if (options.progress && (i + 1) % 50 == 0)
      options.progress("bench record: " + std::to_string(i + 1) + " of " + std::to_string(options.trials));
  }
  RecordBenchResult result;
  result.full_median_ms = Percentile(arms[0].ms, 0.5);
  result.full_p99_ms = Percentile(arms[0].ms, 0.99);
  result.normal_median_ms = Percentile(arms[1].ms, 0.5);
  result.normal_p99_ms = Percentile(arms[1].ms, 0.99);
  for (Arm& arm : arms) {
    arm.record.reset();
    for (const char* suffix : {"", "-wal", "-shm"}) std::filesystem::remove(arm.path.string() + suffix, error);
  }
  return result;
}

}  // namespace blurcue::bench
