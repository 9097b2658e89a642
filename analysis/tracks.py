"""The level tracks of adaptive procedures (a minimal stand-in with the interface the tracks module exposes:
charts(m, study, out_dir, slug, group_note) -> [Chart]; it wraps any_study's former tracks chart, per participant and
procedure cell)."""
import numpy as np
import pandas as pd
import matplotlib.pyplot as plt

from common import Chart, save


def _num(series):
    return pd.to_numeric(series.astype(str).replace({"": np.nan, "nan": np.nan}), errors="coerce")


def _label(value):
    text = str(value)
    return text[:-2] if text.endswith(".0") else text


def charts(m, study, out_dir, slug, group_note):
    """The level each adaptive procedure showed, trial after trial, with the answers, and its threshold estimate:
    QUEST+'s posterior mean after the last answer (its running posterior mean drawn dashed), a staircase's mean of
    its last 6 reversal levels (or of its last 10 levels with fewer than 4 reversals)."""
    name = f"{slug}-tracks"
    d = m.dropna(subset=["level"]).copy()
    d["level"] = d["level"].astype(float)
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    rows = []
    colors = ["#0072B2", "#E69F00", "#009E73", "#CC79A7", "#D55E00", "#56B4E9"]
    for i, ((participant, cell), g) in enumerate(d.sort_values("trial_index").groupby(["participant", "procedure_cell"])):
        levels = g["level"].to_numpy()
        step = np.arange(1, len(levels) + 1)
        c = colors[i % len(colors)]
        ax.plot(step, levels, "-", color=c, lw=1, alpha=0.8)
        ok = g["y"].to_numpy() == 1
        ax.plot(step[ok], levels[ok], "o", color=c, ms=3.5)
        ax.plot(step[~ok], levels[~ok], "x", color=c, ms=4)
        posterior = _num(g["posterior_threshold"]) if "posterior_threshold" in g else pd.Series(dtype=float)
        moves = np.sign(np.diff(levels))
        moves = moves[moves != 0]
        reversals = [levels[1:][np.diff(levels) != 0][j] for j in range(1, len(moves)) if moves[j] != moves[j - 1]]
        if posterior.notna().any():
            ax.plot(step, posterior.to_numpy(), "--", color=c, lw=1)
            estimate, by = float(posterior.dropna().iloc[-1]), "QUEST+ posterior mean after the last answer"
        elif len(reversals) >= 4:
            estimate, by = float(np.mean(reversals[-6:])), "mean of the last 6 reversal levels"
        else:
            estimate, by = float(np.mean(levels[-10:])), "mean of the last 10 levels"
        rows.append({"participant": participant, "procedure_cell": _label(cell), "trials": len(levels),
                     "reversals": len(reversals), "estimate": estimate, "by": by,
                     "share_correct": float(ok.mean())})
    ax.set_xlabel("trial of the procedure")
    ax.set_ylabel("level shown")
    ax.set_title(f"{study}: procedure tracks (o correct, x wrong; dashed: QUEST+'s posterior mean threshold)\n"
                 f"{group_note}", loc="left")
    png, svg = save(fig, out_dir, name)
    return [Chart(name, png, svg, pd.DataFrame(rows), ["one line per participant and crossing of the block's factors; "
                                                        "estimate: each track's threshold as its procedure gives it"])]
