"""Two within-subject factors crossed (e.g. edge x comparison): the shares per crossing drawn by both factors, and the
logistic models across participants with their interaction, beside the additive model any_study.models fits.

The additive model assumes each factor's effect in log-odds is the same at every level of the other; where the
shares say otherwise (measured vs none rising over the edges while measured vs estimated stays flat) that is the
interaction, which the additive model averages away. The interaction model (`y ~ A * B`) is fitted by the same
across_observers.observer_models as every other model (the cluster-robust GLM and lme4's GLMM, its random part reduced step by
step where not determined, separation found first), so its terms are in the same words and held to the same rules.
"""
import matplotlib.pyplot as plt
import numpy as np

import across_observers
from common import Chart, error_bars, factor_label, save

NO_INTERACTION_NOTE = ("no interaction term: this model assumes each factor's effect (in log-odds) is the same at "
                       "every level of the other{others}; the shares per crossing are in the conditions table and "
                       "the chart by both factors, and the model with the interaction is in {name}")


def missing_crossings(table, factors):
    """The crossings of the factors (each level as the table writes it) that have no row in a conditions table, in
    words ('edge 9 with rotation_deg 30'): a design that left one out, or one nobody answered, has no share there."""
    import itertools
    if len(factors) < 2 or table is None or table.empty:
        return []
    levels = [list(dict.fromkeys(table[f])) for f in factors]
    present = set(map(tuple, table[list(factors)].astype(str).to_numpy()))
    return [" with ".join(f"{f} {v}" for f, v in zip(factors, combo)) for combo in itertools.product(*levels)
            if tuple(map(str, combo)) not in present]


def missing_words(table, factors):
    """A note naming the crossings without answers, or '' when every crossing has some."""
    missing = missing_crossings(table, factors)
    if not missing:
        return ""
    return (f"no answers at {len(missing)} crossing{'s' if len(missing) > 1 else ''} of {' and '.join(factors)}: "
            f"{'; '.join(missing)} - no share there, and the model with the interaction has no term for it")


def crossing_chart(table, a, b, chance, what, study, out_dir, name, group_note):
    """The share per crossing of factors a (x axis) and b (one line each), Wilson 95 % intervals, from
    any_study.condition_table's rows (levels already in their sorted order)."""
    levels_a = list(dict.fromkeys(table[a]))
    fig, ax = plt.subplots(figsize=(max(5.0, 0.8 * len(levels_a) + 3.0), 3.8))
    x = np.arange(len(levels_a))
    offsets = np.linspace(-0.08, 0.08, max(1, table[b].nunique()))
    for off, (level, rows) in zip(offsets, table.groupby(b, sort=False)):
        rows = rows.set_index(a).reindex(levels_a)
        ax.errorbar(x + off, rows["share"], yerr=error_bars(rows["share"], rows["share_low"], rows["share_high"]),
                    fmt="o-", ms=5, capsize=2, label=f"{b} {level}")
    if chance is not None:
        ax.axhline(chance, color="#999999", lw=1, ls="--")
    ax.set_xticks(x)
    ax.set_xticklabels(levels_a)
    ax.set_xlabel(factor_label(a))
    ax.set_ylim(-0.03, 1.08)
    ax.set_ylabel(f"share: {what}")
    ax.legend(fontsize=8, loc="best")
    ax.set_title(f"{study}: {what} per {a} and {b}\n{group_note}, {int(table['n'].sum())} answers", loc="left")
    png, svg = save(fig, out_dir, name)
    missing = missing_words(table, [a, b])
    return Chart(name, png, svg, None, [f"the share per crossing of {a} and {b} with Wilson 95 % intervals (answers "
                                        "pooled: a description); lines that are not parallel on the log-odds scale "
                                        "are what an interaction is (the models table with the interaction tests it)"]
                 + ([missing + " (no point drawn)"] if missing else []))


def interaction_models(d, factors, study, group_note, what, levels):
    """The logistic models across participants with every interaction of the factors (d: the rows with the factors
    as their labels; levels: each factor's sorted levels). Returns a Chart named STUDY-models-interaction."""
    rhs = " * ".join(f"C({f}, levels={levels[f]!r})" for f in factors)
    table, notes = across_observers.observer_models(d, "y", rhs, study=study)
    name = f"{study}-models-interaction"
    if not table.empty:
        notes.insert(0, f"{group_note}: logistic models of '{what}' across participants with the interaction of "
                        f"{' and '.join(factors)}; estimates in log-odds, each term against the baseline it names "
                        "(an interaction term: how much that crossing departs from the two effects added)")
    return Chart(name, None, None, table, notes)
