#!/usr/bin/python3
"""One participant's test against chance, its golden table: k of n answers at a chance level, and
analysis/study_tests.py one_participant_test's answer for each - tested (1) or not (0: a single answer), and p.
`--write` makes tests/data/one_participant_golden.csv; without it, checks the Python against the table (exit 1 on a
difference). The C++ twin that plan counts its rejections by (src/plan/power.h OneParticipantTestP) is held to the
same table by plan_test (OneParticipantTest.MatchesTheReportOnTheGoldenTable): plan and report give one answer for
one participant's cell, a single answer included (chance 0.04 or 0.01: one answer right has p = chance < 0.05, which
plan counted as a rejection where the report says no test)."""
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "analysis"))
import study_tests  # noqa: E402

TABLE = os.path.join(HERE, "data", "one_participant_golden.csv")
HEADER = "k,n,chance,tested,p"
CHANCES = (0.5, 1 / 3, 0.25, 0.1, 0.04, 0.01)


def rows():
    out = []
    for chance in CHANCES:
        for n in list(range(1, 13)) + [20, 40]:
            for k in range(n + 1):
                r = study_tests.one_participant_test(k, n, chance)
                tested = not math.isnan(r["p"])
                if tested != (not r["test"].startswith("none")):
                    raise SystemExit(f"k={k} n={n} chance={chance}: test {r['test']!r} with p {r['p']}")
                out.append(f"{k},{n},{chance!r},{int(tested)},{r['p']!r}")
    return out


if __name__ == "__main__":
    got = rows()
    if "--write" in sys.argv:
        with open(TABLE, "w") as f:
            f.write(HEADER + "\n" + "\n".join(got) + "\n")
        print(f"wrote {TABLE}: {len(got)} cases")
        sys.exit(0)
    want = open(TABLE).read().split("\n")[1:-1]
    bad = 0
    for g, w in zip(got, want):
        gk, wk = g.split(","), w.split(",")
        same = gk[:4] == wk[:4] and (gk[3] == "0" or abs(float(gk[4]) - float(wk[4])) <= 1e-9 * max(1, float(wk[4])))
        if not same:
            bad += 1
            print(f"differs: got {g}, table {w}")
    if bad or len(got) != len(want):
        print(f"FAIL: {bad} of {len(want)} cases differ ({len(got)} computed)")
        sys.exit(1)
    print(f"ok: one_participant_test matches {TABLE} on {len(got)} cases")
