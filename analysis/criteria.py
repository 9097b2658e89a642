"""What a threshold means, where the stimuli were tested, and what lies beyond them: one definition each, read by the
tracks (tracks.py), the psychometric functions (any_study.py) and the report's summary alike, so that a threshold in
the summary and the one in its section are the same quantity, stated with the same criterion and the same range.

  criterion     the share correct a threshold stands for, said with it:
                  QUEST+          its threshold parameter, the Weibull's scale: F = 1 - 1/e of the way from guessing
                                  to the top (at guess g and no lapses, g + (1 - g)(1 - 1/e): 81.6 % at g = 0.5);
                                  with a lapse rate l the function gives g + (1 - g - l)(1 - 1/e) there (77.6 % at
                                  l = 0.063), and a label of a fitted function says that share (Criterion.label)
                  staircase       the point its rule converges to (Levitt 1971): 1-up/n-down 0.5^(1/n) of the answers
                                  correct (70.7 % for 2-down), n-up/1-down 1 - 0.5^(1/n)
                  fixed levels    half way from guessing to the top (75 % correct at guess 0.5)
  tested range  what the procedure could show (QUEST+: its stimuli within its grid; a staircase: its min to max), or,
                without a procedure, the levels shown
  beyond        a threshold below or above the tested range: "not determined", in words, never a number
"""
import math
from dataclasses import dataclass

CORE_AT_ALPHA = 1 - math.exp(-1)  # the Weibull's F at its scale: QUEST+'s threshold parameter


@dataclass(frozen=True)
class Criterion:
    """A threshold's criterion: either a point of the core F (0-1, guess and lapse apart) or a share of the answers
    correct (guess and lapse included), with its words."""
    words: str
    core: float = math.nan      # F at the threshold (QUEST+, fixed levels)
    answers: float = math.nan   # share correct at the threshold (a staircase's target)

    def psi(self, guess, lapse):
        """The psychometric function's value (share correct) at the threshold, for a fit with this guess and lapse."""
        if math.isfinite(self.core):
            return guess + (1 - guess - lapse) * self.core
        return self.answers

    def short(self):
        """'81.6 % correct without lapses' - the criterion in a few words for a summary."""
        return self.words.split(":")[0]

    def label(self, guess, lapse):
        """The criterion as a fitted function with this guess and lapse gives it: a point of the core F is a lower
        share correct where the fit has lapses ("81.6 % correct without lapses; the fitted function gives 77.6 % there
        (lapse 0.063)"); a share of the answers (a staircase's target, fixed levels' half way) is that share whatever
        the lapse. A lapse of 0 or unknown (NaN: on its bound) leaves the short words."""
        if not math.isfinite(self.core) or lapse is None or not math.isfinite(lapse) or lapse < 5e-4:
            return self.short()
        return (f"{self.short()}; the fitted function gives {_pct(self.psi(guess, lapse))} there "
                f"(lapse {lapse:.2g})")


def _pct(v):
    return f"{100 * v:.1f} %".replace(".0 %", " %")


def staircase_target(up, down):
    """Where an up/down rule converges (plan::TargetShare): the share p at which a run of `down` correct answers is as
    likely to come before a run of `up` wrong ones as after, p^(d-1) (1 - q^u) / (p^(d-1) + q^(u-1) - p^(d-1) q^(u-1))
    = 1/2, q = 1 - p, by bisection."""
    lo, hi = 0.0, 1.0
    for _ in range(100):
        p = (lo + hi) / 2
        a, b = p ** (down - 1), (1 - p) ** (up - 1)
        first = a * (1 - (1 - p) ** up) / (a + b - a * b) if a + b - a * b > 0 else 0.5
        lo, hi = (p, hi) if first < 0.5 else (lo, p)
    return (lo + hi) / 2


def criterion(kind, params, guess):
    """The Criterion of a procedure cell (kind: quest_plus, staircase or "" for fixed levels; params: its
    procedures.csv JSON, None where the export has none) at this guess rate."""
    if kind == "quest_plus":
        params = params or {}
        g = float(params.get("guess", guess))
        return Criterion(f"{_pct(g + (1 - g) * CORE_AT_ALPHA)} correct without lapses: QUEST+'s threshold "
                         f"parameter, the Weibull's scale, where the function has risen 1 - 1/e = 63.2 % of the way "
                         f"from guessing ({g:.3g}) to the top; with a lapse rate l it gives g + (1 - g - l) 63.2 % "
                         "there", core=CORE_AT_ALPHA)
    if kind == "staircase":
        if not params:
            return Criterion("the staircase's target (procedures.csv missing: its rule, so its target, unknown)")
        up, down = int(params.get("up", 1)), int(params.get("down", 1))
        if up == 1:
            target = 0.5 ** (1 / down)
        elif down == 1:
            target = 1 - 0.5 ** (1 / up)
        else:
            target = staircase_target(up, down)
        return Criterion(f"{_pct(target)} correct: the point the {up}-up/{down}-down staircase converges to (Levitt "
                         "1971)", answers=target)
    return Criterion(f"{_pct(guess + (1 - guess) / 2)} correct: half way from guessing ({guess:.3g}) to the top (no "
                     "lapses)", answers=guess + (1 - guess) / 2)


def tested_range(params, levels):
    """(low, high): what the procedure could show, or the levels shown (levels: the stimuli of these answers)."""
    params = params or {}
    if params.get("thresholds") and params.get("stimuli"):  # QUEST+
        return (max(min(params["thresholds"]), min(params["stimuli"])),
                min(max(params["thresholds"]), max(params["stimuli"])))
    if "min" in params and "max" in params:  # a staircase
        return float(params["min"]), float(params["max"])
    return float(min(levels)), float(max(levels))


def _text(v):
    return f"{v:.4g}"


def range_words(low, high):
    return f"the tested range {_text(low)} to {_text(high)}"


def beyond_words(side, low, high, why=""):
    """'not determined: above the tested range 0.1 to 2 (why)': a threshold outside the range (side: below, above,
    beyond)."""
    return f"not determined: {side} {range_words(low, high)}" + (f" ({why})" if why else "")


def inside(value, low, high):
    return value is not None and math.isfinite(value) and low <= value <= high
