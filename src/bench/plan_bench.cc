#include "bench/plan_bench.h"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <thread>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/stats.h"
#include "plan/plan.h"
#include "procedure/prepare.h"

namespace blurcue::bench {
namespace {

std::string Number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", v);
  return text;
}

// CPU time of the whole process (every thread), seconds.
double CpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace

std::vector<PlanBenchRow> RunPlanBench(const PlanBenchOptions& options) {
  std::vector<PlanBenchRow> rows;
  plan::PlanOptions p;
  p.observer = options.observer;
  p.participants = options.participants;
  p.seed = options.seed;
  // Each study is prepared once (protocol, calibration, images: not what a participant costs), then one untimed run:
  // caches and pages warm for every timed run alike.
  std::vector<std::filesystem::path> files = {options.protocol_file};
  if (!options.adaptive_file.empty()) files.push_back(options.adaptive_file);
  std::vector<procedure::PreparedSession> studies;
  for (const auto& file : files) {
    studies.push_back(procedure::PrepareStudy(file));
    std::vector<plan::Condition> conditions;
    std::vector<std::string> notes;
    int used = 0;
    p.threads = 1;
    p.studies = 1;
    plan::SimulateStudies(p, studies.back(), &conditions, &notes, &used);
  }
  // The adaptive protocol is timed and summarised by its name beside the first: the same study twice had its runs
  // merged into one median ("median of 2 runs" with --rounds 1), and a protocol without a procedure is no adaptive one.
  if (studies.size() == 2) {
    const std::string what = "--adaptive-protocol " + options.adaptive_file.string() + ": ";
    if (studies[1].protocol.name == studies[0].protocol.name)
      throw Error(ErrorKind::kUsage, what + "the same study as --protocol (" + studies[0].protocol.name +
                                         "); 'none' times --protocol alone");
    bool adaptive = false;
    for (const auto& block : studies[1].protocol.blocks) adaptive = adaptive || block.procedure.has_value();
    if (!adaptive)
      throw Error(ErrorKind::kUsage, what + "no block has a procedure (staircase or QUEST+), got study " +
                                         studies[1].protocol.name);
  }
  p.studies = options.studies;
  std::vector<std::vector<std::vector<std::pair<int, procedure::Choice>>>> reference(files.size());
  for (int round = 0; round < options.rounds; ++round) {
    // Interleaved: every protocol and thread count in each round, so a change of machine load falls on all of them.
    for (size_t f = 0; f < files.size(); ++f)
      for (int threads : options.threads) {
        p.threads = threads;
        std::vector<plan::Condition> conditions;
        std::vector<std::string> notes;
        int used = 0;
        const double cpu_start = CpuSeconds();
        const auto start = std::chrono::steady_clock::now();
        const auto simulated = plan::SimulateStudies(p, studies[f], &conditions, &notes, &used);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const double cpu = CpuSeconds() - cpu_start;
        std::vector<std::vector<std::pair<int, procedure::Choice>>> answers;
        for (const auto& participant : simulated.front()) answers.push_back(participant.answers);
        if (reference[f].empty()) reference[f] = answers;
        if (answers != reference[f])
          throw Error(ErrorKind::kInternal, "bench plan: " + std::to_string(threads) +
                                                " threads gave other answers than the first run");
        PlanBenchRow row;
        row.protocol = studies[f].protocol.name;
        row.threads = used;
        row.round = round;
        row.participants = options.participants * options.studies;
        row.seconds = seconds;
        row.ms_per_participant = 1000 * seconds / row.participants;
        row.cpu_seconds = cpu;
        rows.push_back(row);
        if (options.progress) {
          char line[256];
          std::snprintf(line, sizeof line,
                        "bench plan: round %d, %s, %d thread%s: %d participants in %.3f s (%.3f ms each; %.2f cores "
                        "busy)",
                        round + 1, row.protocol.c_str(), used, used == 1 ? "" : "s", row.participants, seconds,
                        row.ms_per_participant, cpu / seconds);
          options.progress(line);
        }
      }
  }
  return rows;
}

void WritePlanBenchCsv(const std::vector<PlanBenchRow>& rows, const std::filesystem::path& path) {
  std::string out = "protocol,threads,round,participants,seconds,ms_per_participant,cpu_seconds\n";
  char line[256];
  for (const auto& r : rows) {
    std::snprintf(line, sizeof line, "%s,%d,%d,%d,%.6f,%.6f,%.6f\n", r.protocol.c_str(), r.threads, r.round,
                  r.participants, r.seconds, r.ms_per_participant, r.cpu_seconds);
    out += line;
  }
  WriteFileAtomically(path, out);
}

std::string SummarizePlanBench(const std::vector<PlanBenchRow>& rows) {
  std::string out;
  char line[320];
  std::vector<std::string> protocols;
  for (const auto& r : rows)
    if (std::find(protocols.begin(), protocols.end(), r.protocol) == protocols.end()) protocols.push_back(r.protocol);
  std::map<std::string, double> one_thread;  // per protocol: median wall ms and CPU ms per participant, 1 thread
  std::map<std::string, double> one_thread_cpu;
  for (const std::string& protocol : protocols) {
    std::map<int, std::vector<double>> per, busy, cpu;
    for (const auto& r : rows) {
      if (r.protocol != protocol) continue;
      per[r.threads].push_back(r.ms_per_participant);
      busy[r.threads].push_back(r.seconds > 0 ? r.cpu_seconds / r.seconds : 0);
      cpu[r.threads].push_back(1000 * r.cpu_seconds / r.participants);
    }
    out += protocol + ":\n";
    const double one = per.count(1) ? Percentile(per[1], 0.5) : 0;
    if (one > 0) one_thread[protocol] = one, one_thread_cpu[protocol] = Percentile(cpu[1], 0.5);
    for (const auto& [threads, times] : per) {
      const double median = Percentile(times, 0.5);
      if (threads == 1 || one <= 0)
        std::snprintf(line, sizeof line, "  %d thread%s: %.3f ms per simulated participant (median of %zu runs)\n",
                      threads, threads == 1 ? "" : "s", median, times.size());
      else
        std::snprintf(line, sizeof line,
                      "  %d threads: %.3f ms per simulated participant (median of %zu runs); speed-up over 1 thread "
                      "%.2fx (%.0f %% of the ideal %dx)\n",
                      threads, median, times.size(), one / median, 100 * one / median / threads, threads);
      out += line;
      std::snprintf(line, sizeof line,
                    "    cores it got: %.2f (CPU time / wall time, median); CPU time per participant %.3f ms%s\n",
                    Percentile(busy[threads], 0.5), Percentile(cpu[threads], 0.5),
                    threads == 1 || !cpu.count(1)
                        ? ""
                        : (" (" + Number(Percentile(cpu[threads], 0.5) / Percentile(cpu[1], 0.5)) +
                           "x 1 thread's: the cost of running in parallel)").c_str());
      out += line;
    }
  }
  if (protocols.size() >= 2 && one_thread.count(protocols[0]) && one_thread.count(protocols[1])) {
    std::snprintf(line, sizeof line,
                  "%s costs %.3f ms per simulated participant on 1 thread (CPU %.3f ms), %.2fx %s's %.3f ms, "
                  "measured in the same rounds\n",
                  protocols[1].c_str(), one_thread[protocols[1]], one_thread_cpu[protocols[1]],
                  one_thread[protocols[1]] / one_thread[protocols[0]], protocols[0].c_str(), one_thread[protocols[0]]);
    out += line;
  }
  std::snprintf(line, sizeof line,
                "this machine has %u hardware threads; a speed-up below the cores it got means the work itself does "
                "not scale, below the threads asked for that other processes held the cores\n",
                std::thread::hardware_concurrency());
  return out + line;
}

}  // namespace blurcue::bench
