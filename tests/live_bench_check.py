#!/usr/bin/python3
"""`blurcue bench live --quick`'s table checked on its values (no timing bound: speed is the bench's printed ratios).

What every run must show whatever the machine's speed:
  - one row per N asked (0, 4, 77), every frame of the 12-frame take delivered: shown or dropped, none lost count;
    at least one frame shown and drawn in each run; latencies positive, p95 >= median
  - the sections: N = 0 measures none and draws with the given model (lens_sections 0); N > 0 measures N a frame at
    most (all 77 at 77) and its last model was fitted live to readings on the board (lens_sections 3 .. 77)
  - the accuracy against the take's true lens: the given model is stale (calibrated at a focus of 400 mm, the take's
    is 450 mm), so N = 0 is off by more than 10 % (the stale lens's own error at the ball: ~25-30 %); measuring every
    section brings the ball within 3 % of the true lens's r (ar's bound against the true lens, tests/ar_check.py)
    on the last third of its frames, and below the stale model's error by 5x at least; the stale model never comes
    within 2 % (settle_frames = frames drawn)

usage: live_bench_check.py live.csv
"""
import csv
import sys


def main():
    rows = {int(r["sections_per_frame"]): r for r in csv.DictReader(open(sys.argv[1]))}
    problems = []

    def check(ok, what):
        if not ok:
            problems.append(what)

    check(sorted(rows) == [0, 4, 77], f"rows for N = {sorted(rows)}, not 0, 4, 77")
    for n, r in rows.items():
        i = {k: int(r[k]) for k in ("frames_delivered", "frames_shown", "frames_dropped", "frames_drawn",
                                     "max_sections", "lens_sections")}
        f = {k: float(r[k]) for k in ("median_latency_ms", "p95_latency_ms", "r_median_rel_error",
                                       "r_late_median_rel_error", "r_late_max_rel_error")}
        check(i["frames_delivered"] == 12 and i["frames_shown"] + i["frames_dropped"] == 12,
              f"N={n}: {i['frames_shown']} shown + {i['frames_dropped']} dropped of {i['frames_delivered']}, not 12")
        check(1 <= i["frames_drawn"] <= i["frames_shown"], f"N={n}: {i['frames_drawn']} drawn of {i['frames_shown']}")
        check(0 < f["median_latency_ms"] <= f["p95_latency_ms"],
              f"N={n}: latency median {f['median_latency_ms']}, p95 {f['p95_latency_ms']}")
        check(i["max_sections"] == min(n, 77), f"N={n}: a frame measured {i['max_sections']} sections")
        if n == 0:
            check(i["lens_sections"] == 0, f"N=0: drew with a model fitted to {i['lens_sections']} readings")
        else:
            check(3 <= i["lens_sections"] <= 77, f"N={n}: the last model was fitted to {i['lens_sections']} readings")
        check(f["r_late_median_rel_error"] <= f["r_late_max_rel_error"], f"N={n}: late median above late max")
    if 0 in rows and 77 in rows:
        stale, full = float(rows[0]["r_median_rel_error"]), float(rows[77]["r_late_median_rel_error"])
        check(stale > 0.10, f"N=0: the stale model's error {100 * stale:.2f} % (> 10 % expected: focus 400 vs 450 mm)")
        check(full <= 0.03, f"N=77: the ball's r {100 * full:.2f} % from the true lens's (<= 3 %)")
        check(full * 5 <= stale, f"N=77's error {100 * full:.2f} % not 5x below the stale model's {100 * stale:.2f} %")
        never = int(rows[0]["settle_frames"])
        check(never == int(rows[0]["frames_drawn"]), f"N=0: the stale model settled within 2 % after {never} frames")
    if problems:
        print("\n".join(problems))
        return 1
    print(f"ok: live_bench_check: {len(rows)} runs; N=0 {100 * float(rows[0]['r_median_rel_error']):.1f} % off, "
          f"N=77 {100 * float(rows[77]['r_late_median_rel_error']):.2f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
