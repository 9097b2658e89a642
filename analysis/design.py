"""The design of a study as its record declares it, read in one place: which columns of trials.csv are within-subject
factors, which one is the between-subject group, which split a procedure into cells, which is the practice flag.

`blurcue export` writes codebook.csv beside trials.csv with every column's `role` (src/protocol/design.h:
within | group | procedure_cell | label | practice). The codebook is one for the whole export, so a column two studies
use differently has both roles ("procedure_cell|within": edge is a procedure cell in one study and varied within in
another); a study's own rows settle it - a procedure trial names its cell's levels in `cell` ("edge=9;speed_cm_s=3").
An export from before roles were recorded has no `role` column: its design columns are the ones whose meaning says
"a level of the protocol's design", all taken as within-subject, and `group` (when there is one) as the group.
"""
import os
from collections import namedtuple
from dataclasses import dataclass

import numpy as np
import pandas as pd

from common import read_text_csv, text

DESIGN_MEANING = "a level of the protocol's design"
# A codebook row of trials.csv: what it means, its roles (a set; empty for a column of no design role), its allowed
# values as the codebook writes them.
Column = namedtuple("Column", "meaning roles allowed")
# Columns that identify a level rather than vary the stimulus (a pattern's id beside the pattern itself), and the
# procedure's own variable (what a procedure chose to show, not a condition of the design).
NOT_FACTORS = {"id", "level"}


def load_codebook(trials_path):
    """codebook.csv beside trials.csv as {column: Column}; {} when there is none."""
    path = os.path.join(os.path.dirname(os.path.abspath(trials_path)), "codebook.csv")
    if not os.path.isfile(path):
        return {}
    book = read_text_csv(path)
    book = book[book["table"] == "trials.csv"]
    roles = book["role"] if "role" in book else pd.Series([""] * len(book), index=book.index)
    allowed = book["allowed"] if "allowed" in book else pd.Series([""] * len(book), index=book.index)
    out = {}
    for column, meaning, role, allow in zip(book["column"], book["meaning"], roles, allowed):
        role_set = frozenset(r for r in str(role).split("|") if r)
        if "role" not in book:  # an export from before roles: the design's levels are within, group is the group
            role_set = frozenset({"group"} if column == "group" else
                                 {"within"} if str(meaning).startswith(DESIGN_MEANING) else set())
        out[column] = Column(str(meaning), role_set, str(allow))
    return out


def _text(series):
    return text(series)


def varies(d, column):
    """True when the column holds more than one non-empty value in these rows."""
    return column in d and _text(d[column]).replace("", np.nan).dropna().nunique() > 1


def cell_columns(d):
    """The factors that split these rows' procedures into cells, read off the rows' own `cell` text
    (NAME=LEVEL;...), in the order first named."""
    out = []
    if "cell" not in d:
        return out
    for cell_text in _text(d["cell"]).unique():
        for part in filter(None, cell_text.split(";")):
            name = part.split("=", 1)[0]
            if name not in out:
                out.append(name)
    return out


def comparing_factors(d, factors):
    """The factors whose levels change which sources a pair compares (left_source and right_source as an unordered
    pair, whatever side each was shown on): a share pooled across their levels would average the answers to
    different questions (measured vs none with measured vs estimated), so a summary goes per level of these."""
    if not {"left_source", "right_source"} <= set(d.columns):
        return []
    left, right = _text(d["left_source"]), _text(d["right_source"])
    pair = pd.Series([" vs ".join(sorted(p)) for p in zip(left, right)], index=d.index)
    return [f for f in factors if f in d and
            len({frozenset(v) for _, v in pair.groupby(_text(d[f]))}) > 1]


@dataclass(frozen=True)
class Design:
    """The design of one set of rows (a study, or a part of one): the columns that vary in them, by role."""
    within: tuple = ()      # within-subject factors that vary here (procedure cells apart), in column order
    group: str = ""         # the between-subject group column when these rows hold more than one group, else ""
    cells: tuple = ()       # the factors whose crossing makes a procedure cell (each its own track and threshold)
    labels: tuple = ()      # recorded only (an id, participant information): never a factor
    varying: tuple = ()     # the cells' factors that take more than one level here
    practice: str = "practice"

    @property
    def factors(self):
        """Every factor a condition is a crossing of: the within factors and the cells' factors."""
        return tuple(self.within) + tuple(c for c in self.cells if c not in self.within and c in self.varying)

    def cell_of(self, d):
        """Each row's procedure cell as text by its levels ("edge=9"); the `cell` column where the export wrote it,
        else procedure_cell's number, else one cell."""
        if "cell" in d and _text(d["cell"]).ne("").any():
            return _text(d["cell"])
        if "procedure_cell" in d and _text(d["procedure_cell"]).ne("").any():
            return "cell " + _text(d["procedure_cell"]).str.replace(r"\.0$", "", regex=True)
        return pd.Series(["all"] * len(d), index=d.index)


def design_of(d, codebook):
    """The Design of rows d (one study or part of one) from the codebook's roles and the rows' own cells."""
    # A level named like a recorded column is exported as factor_NAME (store::DesignColumn); its cell text says NAME.
    cells = tuple(c if c in d else f"factor_{c}" for c in cell_columns(d) if c in d or f"factor_{c}" in d)
    within, labels = [], []
    for column in d.columns:
        roles = codebook[column].roles if column in codebook else frozenset()
        if "label" in roles or column in NOT_FACTORS:
            if "label" in roles:
                labels.append(column)
            continue
        if column in cells or not roles & {"within", "procedure_cell"}:
            continue
        if varies(d, column):
            within.append(column)
    group = "group" if "group" in d and ("group" not in codebook or "group" in codebook["group"].roles) \
        and varies(d, "group") else ""
    return Design(within=tuple(within), group=group, cells=cells, labels=tuple(labels),
                  varying=tuple(c for c in cells if varies(d, c)))
