"""Mixed models across participants fitted by lme4 in R (analysis/models.R), called with data in and a table out.

One Rscript process per report (models.R --serve, started at the first model and kept; R and lme4 take a second to
start, a model a fraction of that): the data go to a CSV in a temporary folder, models.R fits the maximal
by-participant model (random intercept and the slopes given), reduces the random part step by step when that is
singular or not determined (a factor's levels as one participant-by-level effect), down to the random intercept
alone, and writes its table back. A fit is determined when bobyqa and Nelder-Mead agree on it (log-likelihood
within 0.01, fixed effects within 0.1 SE), lme4's convergence checks pass for one of them and no participants' SD
exceeds 10 log-odds; where no random part gives one, the Fit's `failed` says so in words and carries no numbers. This module owns the call, its time limit and every
failure, which come back as a sentence (R missing, a package missing, a fit that failed), never as a traceback.

BLURCUE_RSCRIPT names the Rscript to run (default: Rscript on PATH, else /usr/bin/Rscript); set it to a path that
does not exist to see the report without R.
"""
import atexit
import os
import re
import select
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "models.R")
TIMEOUT_S = 300
KINDS = ("glmm", "lmm")


class Unavailable(Exception):
    """lme4 could not be run or could not fit: the message says why in words."""


@dataclass
class Fit:
    """What models.R returns: fixed effects (term -> estimate, se, df, p), SDs and correlations of the
    by-participant effects (term -> value, or 0 with singular=True), and the words around them."""
    engine: str
    structure: str                      # which random part was fitted and why
    fixed: pd.DataFrame                 # columns term, estimate, se, df, p (terms are the caller's column names)
    sds: list = field(default_factory=list)    # (term or 'Residual', value, singular)
    corrs: list = field(default_factory=list)  # ((term, term), value, singular)
    singular: bool = False              # the chosen model's fit is singular
    failed: str = ""                    # not empty: no fixed effects (the reason in words)
    slopes: tuple = ()                  # the columns with a random slope in the fitted model
    intercept: bool = True              # the fitted model has a random intercept (left out when estimated at 0)
    correlated: bool = True             # its random effects are correlated (the maximal model) or not
    factors: dict = field(default_factory=dict)  # factor name -> its columns, reduced as one (1 | g:factor) effect

    def random_text(self, source=lambda c: c, group="participant"):
        """The fitted random part as R users write it: (1 + x | participant) for the maximal model; uncorrelated or
        reduced, one term per column, (1 | participant) + (0 + x | participant), a factor's level as lme4 writes one
        column of it, dummy(f, "level") (a factor in (1 + f || participant) would give every level a slope)."""
        if not self.slopes:
            return f"(1 | {group})"
        if self.correlated:
            names = list(dict.fromkeys(source(c) for c in self.slopes))
            return "(1" + "".join(f" + {v}" for v in names) + f" | {group})"
        parts = [f"(1 | {group})"] if self.intercept else []
        of_factor = {c: name for name, cols in self.factors.items() for c in cols}
        for c in self.slopes:
            if c in of_factor:  # a factor's participant-by-level effect, once for all its columns
                part = f"(1 | {group}:{of_factor[c]})"
                if part not in parts:
                    parts.append(part)
                continue
            level = re.search(r"\[T\.(.*)\]$", str(c))
            term = f'dummy({source(c)}, "{level.group(1)}")' if level else source(c)
            parts.append(f"(0 + {term} | {group})")
        return " + ".join(parts)


class _Server:
    """One `Rscript models.R --serve` process: a job per line on its stdin, "done" on its stdout when the table is
    written. stderr goes to a file (a pipe nobody reads could fill and stall R)."""

    def __init__(self, exe):
        self.exe = exe
        self.err = tempfile.TemporaryFile(mode="w+")
        try:
            self.proc = subprocess.Popen([exe, "--vanilla", SCRIPT, "--serve"], stdin=subprocess.PIPE,
                                         stdout=subprocess.PIPE, stderr=self.err, text=True, bufsize=1)
        except OSError as e:
            raise Unavailable(f"Rscript could not be started ({e.strerror}): no mixed model")

    def _died(self):
        code = self.proc.wait()
        self.err.seek(0)
        lines = self.err.read().strip().splitlines()
        if code == 4 and lines and lines[-1].startswith("missing R package:"):
            package = lines[-1].split(":")[-1].strip()
            return Unavailable(f"the R package {package} is not installed: no mixed model; install "
                               f"r-cran-{package.lower()}")
        return Unavailable(f"Rscript models.R stopped (exit {code}: {lines[-1] if lines else 'no message'}): "
                           f"no mixed model")

    def run(self, kind, data_path, out_path, slopes, factors=""):
        try:
            self.proc.stdin.write(f"{kind}\t{data_path}\t{out_path}\t{slopes}\t{factors}\n")
            self.proc.stdin.flush()
        except (BrokenPipeError, OSError):
            raise self._died()
        ready, _, _ = select.select([self.proc.stdout], [], [], TIMEOUT_S)
        if not ready:
            self.proc.kill()
            self.proc.wait()
            raise Unavailable(f"lme4 did not finish within {TIMEOUT_S} s: no mixed model")
        line = self.proc.stdout.readline()
        if line.strip() != "done":
            raise self._died()

    def close(self):
        if self.proc.poll() is None:
            try:
                self.proc.stdin.close()
                self.proc.wait(timeout=30)
            except (OSError, subprocess.TimeoutExpired):
                self.proc.kill()
                self.proc.wait()
        self.err.close()


_SERVERS = {}  # Rscript path -> its _Server, or the Unavailable it ended with


def _server(exe):
    """The running server for this Rscript, started on first use; a server that failed keeps its reason."""
    s = _SERVERS.get(exe)
    if isinstance(s, Unavailable):
        raise s
    if s is None or s.proc.poll() is not None:
        s = _SERVERS[exe] = _Server(exe)
    return _Proxy(exe, s)


class _Proxy:
    """Runs a job on a server and remembers a server that died (R or lme4 missing) so the next model says the same
    without starting R again."""

    def __init__(self, exe, server):
        self.exe, self.server = exe, server

    def run(self, *job):
        try:
            self.server.run(*job)
        except Unavailable as e:
            if self.server.proc.poll() is not None:
                self.server.close()
                _SERVERS[self.exe] = e if "not installed" in str(e) else None
            raise


@atexit.register
def _close_servers():
    for s in list(_SERVERS.values()):
        if isinstance(s, _Server):
            s.close()
    _SERVERS.clear()


def rscript():
    """The Rscript to run, or None when there is none."""
    path = os.environ.get("BLURCUE_RSCRIPT")
    if path is not None:
        return path if path and os.path.isfile(path) and os.access(path, os.X_OK) else None
    return shutil.which("Rscript") or (("/usr/bin/Rscript") if os.path.isfile("/usr/bin/Rscript") else None)


def within_columns(design, groups, min_share=0.5):
    """Design columns that vary within participants (in at least min_share of them): the ones a random slope can be
    estimated for. A column constant within every participant (a between-participant factor) gets none."""
    g = pd.Series(np.asarray(groups)).reset_index(drop=True)
    out = []
    for col in design.columns:
        v = pd.Series(np.asarray(design[col], float))
        varies = v.groupby(g).nunique() > 1
        if varies.mean() >= min_share:
            out.append(col)
    return out


def slope_columns(design, groups):
    """The random slopes of the maximal model: within-participant columns, other than the intercept, chosen so that
    together with the random intercept they are linearly independent (a cell-means design loses one cell: the
    random intercept already spans it)."""
    chosen = []
    base = [np.ones(len(design))]
    for col in within_columns(design, groups):
        x = np.asarray(design[col], float)
        trial = np.column_stack(base + [x])
        if np.linalg.matrix_rank(trial) == trial.shape[1]:
            base.append(x)
            chosen.append(col)
    return chosen


def fit(kind, y, design, groups, slopes=(), factors=None):
    """Fits y ~ 0 + design + (1 + slopes | groups) by lme4 (kind 'glmm': binomial glmer; 'lmm': lmer with
    Satterthwaite df). factors: {factor name: its columns among the slopes}, each reduced as one participant-by-level
    effect (1 | groups:factor) where the maximal model fails (models.R, reduce_random), the same model whatever the
    factor's reference level. A fit models.R did not keep (failed, its optimizers disagree, lme4's convergence checks
    failed, a participants' SD beyond its bound) comes back with `failed` in words and no numbers. Returns a Fit;
    raises Unavailable with the reason in words when R, a package or the call fails."""
    if kind not in KINDS:
        raise ValueError(f"unknown mixed model kind {kind!r}")
    exe = rscript()
    if exe is None:
        raise Unavailable("R is not installed (no Rscript" +
                          (f" at {os.environ['BLURCUE_RSCRIPT']}" if os.environ.get("BLURCUE_RSCRIPT") else
                           " on PATH") + "): no mixed model fitted; install r-base-core and r-cran-lme4")
    names = list(design.columns)
    code = {name: f"X{i}" for i, name in enumerate(names)}
    back = {v: k for k, v in code.items()}
    frame = pd.DataFrame({"y": np.asarray(y, float), "g": np.asarray(groups).astype(str)})
    for name in names:
        frame[code[name]] = np.asarray(design[name], float)
    with tempfile.TemporaryDirectory(prefix="blurcue-lme4-") as tmp:
        data_path, out_path = os.path.join(tmp, "data.csv"), os.path.join(tmp, "out.csv")
        frame.to_csv(data_path, index=False, float_format="%.17g")
        factors = {name: [c for c in cols if c in slopes] for name, cols in (factors or {}).items()}
        factors = {name: cols for name, cols in factors.items() if cols}
        _server(exe).run(kind, data_path, out_path, ",".join(code[s] for s in slopes),
                         ";".join(",".join(code[c] for c in cols) for cols in factors.values()))
        out = pd.read_csv(out_path, keep_default_na=True)
    missing = out[(out["row"] == "info") & (out["term"] == "missing")]
    if len(missing):
        package = str(missing["note"].iloc[0])
        raise Unavailable(f"the R package {package} is not installed: no mixed model; install "
                          f"r-cran-{package.lower()}")
    out["note"] = out["note"].fillna("").astype(str)
    info = {r["term"]: r["note"] for _, r in out[out["row"] == "info"].iterrows()}
    fixed = out[out["row"] == "fixed"][["term", "estimate", "se", "df", "p"]].copy()
    fixed["term"] = fixed["term"].map(lambda t: back.get(t, t))
    result = Fit(engine=info.get("engine", "lme4"), structure=info.get("structure", ""), fixed=fixed.reset_index(
        drop=True), singular="singular" in info, failed=info.get("failed", ""))
    kept = str(info.get("slopes", "")).split(",") if info.get("slopes", "") else []
    result.slopes = tuple(back.get(c, c) for c in kept)
    result.intercept = info.get("intercept", "yes") != "no"
    result.correlated = result.structure.startswith("random intercept and slopes") and "uncorrelated" not in \
        result.structure.split(":")[0]
    level_of = {f"F{i}": name for i, name in enumerate(factors)}  # models.R's codes of the factors, in order
    result.factors = {name: tuple(cols) for name, cols in factors.items() if set(cols) <= set(result.slopes)}
    for _, r in out[out["row"] == "sd"].iterrows():
        term = r["term"] if r["term"] in ("Intercept", "Residual") else f"level:{level_of[r['term']]}" \
            if r["term"] in level_of else back.get(r["term"], r["term"])
        result.sds.append((term, float(r["estimate"]), r["note"] == "singular"))
    for _, r in out[out["row"] == "corr"].iterrows():
        a, b = (t if t == "Intercept" else back.get(t, t) for t in r["term"].split(":"))
        result.corrs.append(((a, b), float(r["estimate"]), r["note"] == "singular"))
    # The structure note names the R-side columns; put the caller's names back.
    for name, cols in factors.items():
        said = "each level of " + "/".join(code[c] for c in cols)
        result.structure = result.structure.replace(said, f"each level of {name}")
        result.failed = result.failed.replace(said, f"each level of {name}")
    for c, name in sorted(back.items(), key=lambda kv: -len(kv[0])):
        result.structure = result.structure.replace(c, name)
        result.failed = result.failed.replace(c, name)
    return result
