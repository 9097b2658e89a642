#include <cstdio>
#include <iostream>
#include <string>

#include "bench/live_bench.h"
#include "bench/measure_bench.h"
#include "bench/plan_bench.h"
#include "bench/procedure_bench.h"
#include "bench/record_bench.h"
#include "bench/render_bench.h"
#include "bench/track_bench.h"
#include "cli/commands.h"
#include "core/output_guard.h"
#include "core/own_output.h"
#include "core/data_dir.h"

namespace blurcue::cli {
namespace {

// An existing --out is replaced only when it is this bench's CSV (its header's first columns): a protocol, a
// calib.json or one's own table given by mistake is refused before the run.
void RequireBenchCsv(const std::string& out, const std::string& bench, const std::string& header_start) {
  RequireOwnFile("--out", out, "a CSV bench " + bench + " wrote", BeginsWith(header_start));
}

// A bench's progress: one line on stderr (stdout carries its results).
void ProgressLine(const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); }

void AddMeasure(CLI::App& bench) {
  struct Args {
    std::string out = "results/bench/measure.csv";
    bool quick = false, no_full_res = false;
    uint64_t seed = 1;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = bench.add_subcommand(
      "measure",
      "Speed against accuracy of the blur measurement and estimation methods.\n"
      "Renders ground-truth scenes (the thesis set-up), sweeping one factor at a time - sensor noise, contrast,\n"
      "JPEG quality, printing flaws, blur size, PSF shape, vignetting, distortion, camera tilt, a filter on the\n"
      "sampled image, the edges' angle to the pixel rows, their sub-pixel phase - calibrates each, and records\n"
      "for every method (model_fit = r_px, thesis = r_thesis_px, eq37 = r_estimated_px, fitted_model =\n"
      "r_fitted_px) how many sections it answered (and how many were flagged phase_limited), its error against\n"
      "the true radius and its time per section. A method meets the\n"
      "target in a condition when it answers >= 50 % of sections and >= 90 % of those are within max(0.25 px, 5 %);\n"
      "under a filter on the sampled image (and per phase) when every section it answers is within\n"
      "max(0.05 px, 10 %) (the others flagged), and the fitted model within median 2 %, p90 5 %.\n"
      "Then times the whole calibration of one full-resolution 4592 x 3056 photo.\n"
      "Takes a few minutes; --quick runs two levels per factor.");
  cmd->add_option("--out", args->out, "CSV, one row per (method, condition)")->capture_default_str();
  cmd->add_option("--seed", args->seed, "seed of the scenes' noise, texture and flaws")->capture_default_str()
      ->transform(SeedValidator());
  cmd->add_flag("--quick", args->quick, "two levels per factor (smoke run)");
  cmd->add_flag("--no-full-res", args->no_full_res, "skip the full-resolution timing");
  cmd->callback([args] {
    OutputGuard().OutputFile("--out", args->out).Check();
    RequireBenchCsv(args->out, "measure", "method,factor,level,");
    bench::MeasureBenchOptions options;
    options.quick = args->quick;
    options.seed = args->seed;
    options.progress = ProgressLine;
    const auto rows = bench::RunMeasureBench(options);
    bench::WriteMeasureCsv(rows, args->out, args->quick);
    std::printf("wrote %s (%zu rows)\n\nwhere each method breaks (target: max(0.25 px, 5 %%) on >= 90 %% of answered "
                "sections, >= 50 %% answered):\n%s",
                args->out.c_str(), rows.size(), bench::DescribeBreakpoints(rows).c_str());
    for (const auto& r : rows)
      if (r.factor == "base" && r.method == "model_fit")
        for (const auto& t : rows)
          if (t.factor == "base" && t.method == "thesis")
            std::printf("\nbase scene: model fit %.1f us/section, mean |error| %.3f px; thesis %.1f us/section, "
                        "mean |error| %.3f px (time ratio model/thesis %.2f)\n",
                        r.time_us_per_section, r.mean_abs_error_px, t.time_us_per_section, t.mean_abs_error_px,
                        r.time_us_per_section / t.time_us_per_section);
    if (args->no_full_res) return;
    const bench::PipelineTiming t = bench::TimeFullResolution(3, options.progress);
    std::printf("\nfull resolution %dx%d (best of 3): calibration %.0f ms = detect+pose %.0f + measure %.0f + "
                "estimate %.1f ms (PNG decode %.0f ms more; target < 1000 ms: %s)\n"
                "  per section: model fit %.1f us, thesis %.1f us\n",
                t.width, t.height, t.total_ms, t.detect_ms, t.measure_ms, t.estimate_ms, t.decode_ms,
                t.total_ms < 1000 ? "met" : "NOT met", t.model_us_per_section, t.thesis_us_per_section);
  });
}

void AddRender(CLI::App& bench) {
  struct Args {
    std::string out = "results/bench/render.csv";
    bool quick = false, frames_only = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = bench.add_subcommand(
      "render",
      "Speed against accuracy of the blur renderers, in one run on this machine.\n"
      "1. One blur of a whole frame for each method (gaussian, disc; butterworth on the CPU), radius (1, 4, 8, 16 px)\n"
      "   and size (1280x720, 1920x1080, 4592x3056), on the GPU (EGL; Mesa's llvmpipe where there is no GPU) and on\n"
      "   the CPU: time, and error in 8-bit levels against an exact convolution with the continuous PSF.\n"
      "2. The test-2 frame: two soccer balls rolling from edge 1 to 11 at 1920x1080, each blurred by the thin lens,\n"
      "   composed object by object (blur only what a ball covers) and the thesis's way (blur a whole-frame buffer\n"
      "   per ball): per-frame time (median, 99th percentile) and how much the two outputs differ.\n"
      "3. How that frame's cost grows: balls per frame (1, 2, 8, 32), frame size (720p, 1080p, 2160p) and blur\n"
      "   radius (1-16 px), one swept at a time, 120 frames each.\n"
      "Ends with the targets it checks: the two-ball frame's p99 within one 120 Hz refresh and >= 100x faster than\n"
      "the whole-frame way, 8 balls' p99 within one 60 Hz refresh, the CPU Gaussian no slower than OpenCV's own\n"
      "GaussianBlur on the same float image (timed in turn), Butterworth over 4592x3056 under 2 s.\n"
      "Takes about five minutes; --quick uses small frames (a smoke run: its figures are not the targets').");
  cmd->add_option("--out", args->out, "CSV, one row per measurement")->capture_default_str();
  cmd->add_flag("--quick", args->quick, "small sizes, few frames (smoke run)");
  cmd->add_flag("--frames-only", args->frames_only, "only parts 2 and 3, the frames (about two minutes)");
  cmd->callback([args] {
    OutputGuard().OutputFile("--out", args->out).Check();
    RequireBenchCsv(args->out, "render", "kind,method,backend,");
    bench::RenderBenchOptions options;
    options.quick = args->quick;
    options.frames_only = args->frames_only;
    options.progress = ProgressLine;
    const auto rows = bench::RunRenderBench(options);
    bench::WriteRenderCsv(rows, args->out, args->quick);
    std::printf("wrote %s (%zu rows)\n%s", args->out.c_str(), rows.size(), bench::SummarizeRender(rows).c_str());
  });
}

void AddRecord(CLI::App& bench) {
  struct Args {
    std::string folder = "results/bench";
    int trials = 200, frames = 60;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = bench.add_subcommand(
      "record",
      "What each answer's durability costs, on this disk, in one run.\n"
      "Records the same session twice, interleaved answer by answer: synchronous=FULL (what blurcue run uses: an\n"
      "answer once committed survives a power loss or an OS crash) and NORMAL (survives only a killed process).\n"
      "Each answer carries a second of display flips (60 frames), committed with it in one transaction.\n"
      "Prints the time per answer (median, 99th percentile) of each and their ratio. Run it on the disk the lab's\n"
      "records live on: --folder names it.");
  cmd->add_option("--folder", args->folder, "where the two scratch records are written (removed after)")
      ->capture_default_str();
  cmd->add_option("--trials", args->trials, "answers per record")->capture_default_str()->transform(IntRange(10, 100000));
  cmd->add_option("--frames", args->frames, "display flips per answer")->capture_default_str()->transform(IntRange(0, 10000));
  cmd->callback([args] {
    bench::RecordBenchOptions options;
    options.folder = args->folder;
    options.trials = args->trials;
    options.frames_per_trial = args->frames;
    options.progress = ProgressLine;
    const bench::RecordBenchResult r = bench::RunRecordBench(options);
    std::printf("per answer with %d frames, %d answers each, in %s:\n"
                "  synchronous=FULL   median %.2f ms  p99 %.2f ms\n"
                "  synchronous=NORMAL median %.2f ms  p99 %.2f ms\n"
                "  FULL costs %.2f ms more per answer (median), %.1fx NORMAL\n",
                args->frames, args->trials, args->folder.c_str(), r.full_median_ms, r.full_p99_ms, r.normal_median_ms,
                r.normal_p99_ms, r.full_median_ms - r.normal_median_ms, r.full_median_ms / r.normal_median_ms);
  });
}

void AddProcedures(CLI::App& bench) {
  struct Args {
    std::string out = "results/bench/procedures.csv";
    int runs = 200;
    bool quick = false;
    uint64_t seed = 1;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = bench.add_subcommand(
      "procedures",
      "Which procedure to choose: speed (trials) against accuracy of threshold estimates, and where each fails.\n"
      "Simulated 2AFC observers of known Weibull threshold and slope answer seeded runs of the method of constant\n"
      "stimuli (8 levels, maximum-likelihood fit), 1-up/2-down and 1-up/3-down staircases (the report's posterior\n"
      "median at the target, docs/thresholds.md) and QUEST+ (posterior mean), each given the same stimulus range. After 20, 40, 80 and 160 trials\n"
      "each estimate is compared with what the procedure aims at (the Weibull threshold; a staircase's 70.7 % or\n"
      "79.4 % point of the observer's sensory function): bias, SD and RMSE. Conditions: nominal, lapses (5 %), a\n"
      "side bias (25 % of answers 'left'), a slope unlike QUEST+'s prior (8), a threshold beyond the range (4 > 3).\n"
      "The report charts it. --quick runs 40 runs.");
  cmd->add_option("--out", args->out, "CSV, one row per (procedure, condition, trials)")->capture_default_str();
  cmd->add_option("--runs", args->runs, "seeded runs per procedure and condition")->capture_default_str()
      ->transform(IntRange(2, 100000));
  cmd->add_option("--seed", args->seed, "seed of the runs")->capture_default_str()->transform(SeedValidator());
  cmd->add_flag("--quick", args->quick, "40 runs (smoke run)");
  cmd->callback([args] {
    OutputGuard().OutputFile("--out", args->out).Check();
    RequireBenchCsv(args->out, "procedures", "procedure,condition,trials,");
    bench::ProcedureBenchOptions options;
    options.runs = args->quick ? 40 : args->runs;
    options.seed = args->seed;
    options.progress = ProgressLine;
    const auto rows = bench::RunProcedureBench(options);
    bench::WriteProcedureCsv(rows, args->out, args->quick);
    std::printf("wrote %s (%zu rows, %d runs each)\n%s", args->out.c_str(), rows.size(), options.runs,
                bench::SummarizeProcedures(rows).c_str());
  });
}

void AddPlan(CLI::App& bench) {
  struct Args {
    std::string out = "results/bench/plan.csv", protocol, adaptive;
    bench::PlanBenchOptions options;
    bool quick = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = bench.add_subcommand(
      "plan",
      "What 'blurcue plan' costs: the time per simulated participant, and how it scales with cores.\n"
      "Simulates --studies studies of --participants participants of a protocol (default: the shipped test 1, which\n"
      "needs the demo's calibration) with 1 thread and with 2, interleaved, --rounds times each, in one run; prints\n"
      "the median time per participant for each and the speed-up of 2 threads over 1 (and its share of the ideal 2x).\n"
      "The shipped QUEST+ protocol (quest-blur-difference) is timed in the same rounds (--adaptive-protocol), and its\n"
      "time per participant given beside test 1's.\n"
      "Every run must give the same answers (it stops if not). --quick: 1 round of 2 studies.");
  cmd->add_option("--out", args->out, "CSV, one row per timed run")->capture_default_str();
  cmd->add_option("--protocol", args->protocol, "the protocol to simulate (default protocols/test1-static-grids.json)");
  cmd->add_option("--adaptive-protocol", args->adaptive,
                  "the adaptive protocol timed beside it (default protocols/quest-blur-difference.json; 'none': none)");
  cmd->add_option("--participants", args->options.participants, "participants per study")->capture_default_str()
      ->transform(IntRange(1, 10000));
  cmd->add_option("--studies", args->options.studies, "studies per timed run")->capture_default_str()
      ->transform(IntRange(1, 10000));
  cmd->add_option("--rounds", args->options.rounds, "timed runs per thread count")->capture_default_str()
      ->transform(IntRange(1, 100));
  cmd->add_option("--observer", args->options.observer, "the simulated observer")->capture_default_str();
  cmd->add_flag("--quick", args->quick, "1 round of 2 studies (smoke run)");
  cmd->callback([args] {
    OutputGuard().OutputFile("--out", args->out).Check();
    RequireBenchCsv(args->out, "plan", "protocol,threads,round,");
    bench::PlanBenchOptions options = args->options;
    options.protocol_file = args->protocol.empty() ? DataDir().path / "protocols" / "test1-static-grids.json"
                                                   : std::filesystem::path(args->protocol);
    options.adaptive_file = args->adaptive.empty() ? DataDir().path / "protocols" / "quest-blur-difference.json"
                            : args->adaptive == "none" ? std::filesystem::path()
                                                       : std::filesystem::path(args->adaptive);
    if (args->quick) options.rounds = 1, options.studies = 2;
    options.progress = ProgressLine;
    const auto rows = bench::RunPlanBench(options);
    bench::WritePlanBenchCsv(rows, args->out);
    std::printf("wrote %s (%zu rows)\n%s", args->out.c_str(), rows.size(), bench::SummarizePlanBench(rows).c_str());
  });
}

void AddTrack(CLI::App& bench) {
  struct Args {
    std::string out = "results/bench/track.csv";
    bool quick = false;
    int frames = 12;
    uint64_t seed = 1;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = bench.add_subcommand(
      "track",
      "Speed against accuracy of `blurcue track`: carried pose vs full detection vs calibrate, frame by frame.\n"
      "Renders a ground-truth moving-camera take (synth-take's defaults: 1148 x 764, fixed focus inside the board,\n"
      "0.35 px lens floor, noise 0.004), PNG-encodes each frame, then in one process runs on every frame: tracking\n"
      "(track, the next frame decoded meanwhile as `blurcue track` does; track-inline: each frame decoded before it\n"
      "is tracked; track-serial: decoded in line, its sections measured on one core), full detection on every frame\n"
      "(detect) and calib::Calibrate as `calibrate` does (calibrate); then\n"
      "runs `blurcue calibrate` as a command on each frame's PNG, one process a frame (calibrate-process: wall and\n"
      "the child's CPU time, start-up and calib.json included). Each row: the frame's time (decoding timed apart\n"
      "in process; period_ms: decoding included), its pose and measurement parts, depth and blur errors against the\n"
      "truth. Prints the ratios measured in the run. Targets: track's median <= 33 ms a frame, decoding included, and\n"
      ">= 6x faster than calibrate run on each frame.\n"
      "analysis/track_chart.py charts time per frame against accuracy. --quick: the first 4 frames of the take.");
  cmd->add_option("--out", args->out, "CSV, one row per (mode, frame)")->capture_default_str();
  cmd->add_option("--frames", args->frames, "frames in the take")->capture_default_str()->transform(IntRange(2, 1000));
  cmd->add_option("--seed", args->seed, "seed of the take's texture and noise")->capture_default_str()
      ->transform(SeedValidator());
  cmd->add_flag("--quick", args->quick, "the first 4 frames of the take (smoke run)");
  cmd->callback([args] {
    // It runs this blurcue as a child: --out naming it would replace the executable with the CSV.
    OutputGuard().Input("the blurcue it runs", ExecutablePath()).OutputFile("--out", args->out).Check();
    RequireBenchCsv(args->out, "track", "mode,frame,status,");
    bench::TrackBenchOptions options;
    options.frames = args->frames;
    options.quick = args->quick;
    options.seed = args->seed;
    options.progress = ProgressLine;
    const auto rows = bench::RunTrackBench(options);
    bench::WriteTrackCsv(rows, args->out, args->quick);
    std::printf("wrote %s (%zu rows)\n%s", args->out.c_str(), rows.size(), bench::SummarizeTrackBench(rows).c_str());
  });
}

void AddLive(CLI::App& bench) {
  struct Args {
    std::string out = "results/bench/live.csv";
    bool quick = false;
    bench::LiveBenchOptions options;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = bench.add_subcommand(
      "live",
      "Speed against accuracy of `blurcue live --measure-sections N`: latency and dropped frames against the board\n"
      "sections measured a frame, and the blur accuracy that buys.\n"
      "Renders a ground-truth take (synth-take's defaults: 1148 x 764, fixed focus at 450 mm, 0.35 px lens floor,\n"
      "noise 0.004) and a lens model calibrated at a focus of 400 mm (the focus ring turned since: a stale model),\n"
      "then runs `blurcue live` on the take's video, headless, at --fps, once for each N, with a ball at 87.5,125:\n"
      "N sections measured a frame in turn and the lens fitted again to their latest readings (N = 0: the stale\n"
      "model throughout). Each row, from the run's own log: frames shown and dropped, latency (median, p95), the\n"
      "time measuring took, and the ball's drawn r against the true lens's (median over the frames drawn, and over\n"
      "their last third). Prints the ratios measured in the run. analysis/live_chart.py charts it.\n"
      "--quick: 12 frames, N = 0, 4, 77 (a smoke run).");
  cmd->add_option("--out", args->out, "CSV, one row per N")->capture_default_str();
  cmd->add_option("--frames", args->options.frames, "frames in the take")->capture_default_str()
      ->transform(IntRange(4, 1000));
  cmd->add_option("--fps", args->options.fps, "the pace the take is played at")->capture_default_str()
      ->check(FiniteRange(1, 240, "frames per second"));
  cmd->add_option("--sections", args->options.sections, "the values of N (sections measured a frame)")
      ->capture_default_str()->check(IntRange(0, 10000))->delimiter(',');
  cmd->add_option("--seed", args->options.seed, "seed of the take's texture and noise")->capture_default_str()
      ->transform(SeedValidator());
  cmd->add_flag("--quick", args->quick, "12 frames, N = 0, 4, 77 (smoke run)");
  cmd->callback([args, cmd] {
    // --quick sets the values of N itself and runs at most 12 frames: --sections, or --frames over 12, given beside
    // it would be ignored.
    if (args->quick && cmd->count("--sections") > 0)
      throw Error(ErrorKind::kUsage, "--sections: --quick runs N = 0, 4, 77 and would ignore it; leave out --quick "
                                     "or --sections");
    if (args->quick && cmd->count("--frames") > 0 && args->options.frames > 12)
      throw Error(ErrorKind::kUsage, "--frames " + std::to_string(args->options.frames) +
                                         ": --quick runs at most 12 frames and would ignore it; leave out --quick or "
                                         "give --frames 12 or fewer");
    // A value of N given twice ran twice into the same log folder and wrote two rows for it.
    for (size_t i = 0; i < args->options.sections.size(); ++i)
      for (size_t j = 0; j < i; ++j)
        if (args->options.sections[i] == args->options.sections[j])
          throw Error(ErrorKind::kUsage, "--sections: " + std::to_string(args->options.sections[i]) +
                                             " is given twice; give each value of N once");
    // It runs this blurcue once for each N: --out naming it replaced the executable with the CSV.
    OutputGuard().Input("the blurcue it runs", ExecutablePath()).OutputFile("--out", args->out).Check();
    RequireBenchCsv(args->out, "live", "sections_per_frame,frames_delivered,");
    bench::LiveBenchOptions options = args->options;
    options.quick = args->quick;
    options.progress = ProgressLine;
    const auto rows = bench::RunLiveBench(options);
    bench::WriteLiveBenchCsv(rows, args->out, args->quick);
    std::printf("wrote %s (%zu rows)\n%s", args->out.c_str(), rows.size(), bench::SummarizeLiveBench(rows).c_str());
  });
}

}  // namespace

void AddBenchCommand(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks that chart speed against accuracy (CSV under results/bench/).");
  bench->require_subcommand(1);
  AddMeasure(*bench);
  AddRender(*bench);
  AddRecord(*bench);
  AddProcedures(*bench);
  AddPlan(*bench);
  AddTrack(*bench);
  AddLive(*bench);
}

}  // namespace blurcue::cli
