"""Reads every table of a `blurcue export` with pandas, typed by the export's own codebook.csv, and checks that
- every column of every table is in the codebook, and every codebook row names a column that exists;
- every cell parses as its declared type and reads back as the same value (numbers exactly, booleans 0/1, allowed
  values where the codebook lists them);
- every seed is the session's 64-bit seed in the record, digit for digit.

usage: codebook_check.py EXPORT_DIR RECORD.sqlite
"""
import csv
import os
import sqlite3
import sys
from decimal import Decimal

import pandas as pd

PANDAS_TYPES = {"string": "string", "integer": "Int64", "number": "float64", "boolean": "Int64", "datetime": "string"}


def fail(message):
    print("FAIL:", message)
    sys.exit(1)


def main(export_dir, db_path):
    codebook = pd.read_csv(os.path.join(export_dir, "codebook.csv"), dtype=str, keep_default_na=False)
    tables = sorted(f for f in os.listdir(export_dir) if f.endswith(".csv") and f != "codebook.csv")
    checked = 0
    for table in tables:
        book = codebook[codebook["table"] == table]
        if book.empty:
            fail(f"{table}: not in the codebook")
        with open(os.path.join(export_dir, table), newline="", encoding="utf-8") as f:
            header = next(csv.reader(f))
        if header != list(book["column"]):
            fail(f"{table}: columns {header} but the codebook lists {list(book['column'])}")
        types = dict(zip(book["column"], book["type"]))
        unknown = set(types.values()) - set(PANDAS_TYPES)
        if unknown:
            fail(f"{table}: types {unknown} the codebook does not define")
        raw = pd.read_csv(os.path.join(export_dir, table), dtype=str, keep_default_na=False)
        # float_precision="round_trip": pandas's default parser can be one unit in the last place off.
        typed = pd.read_csv(os.path.join(export_dir, table), dtype={c: PANDAS_TYPES[t] for c, t in types.items()},
                            float_precision="round_trip")
        for _, entry in book.iterrows():
            column, kind, allowed = entry["column"], entry["type"], entry["allowed"]
            for text, value in zip(raw[column], typed[column]):
                if text == "":
                    if not pd.isna(value):
                        fail(f"{table}.{column}: an empty cell read as {value!r}")
                    continue
                if kind in ("integer", "boolean"):
                    if Decimal(text) != Decimal(int(value)):
                        fail(f"{table}.{column}: {text!r} read as {value!r}")
                    if kind == "boolean" and int(value) not in (0, 1):
                        fail(f"{table}.{column}: {text!r} is not 0 or 1")
                elif kind == "number":
                    if float(text) != value or repr(float(text)) != repr(value):
                        fail(f"{table}.{column}: {text!r} read as {value!r}")
                elif str(value) != text:
                    fail(f"{table}.{column}: {text!r} read as {value!r}")
                if kind == "datetime" and not pd.notna(pd.to_datetime(text, utc=True)):
                    fail(f"{table}.{column}: {text!r} is no date")
                # A numeric column's allowed values are numbers (the design's levels: 4 allows a cell 4.0).
                if allowed and "|" in allowed and text not in allowed.split("|") and not (
                        kind in ("integer", "number") and Decimal(text) in {Decimal(a) for a in allowed.split("|")}):
                    fail(f"{table}.{column}: {text!r} is not one of {allowed}")
                checked += 1
        # Seeds: exact, as the record holds them (SQLite keeps the uint64's bits as an int64).
        if "seed" in typed.columns:
            with sqlite3.connect(f"file:{db_path}?mode=ro", uri=True) as db:
                seeds = {str(i): s % 2**64 for i, s in db.execute("SELECT id, seed FROM sessions")}
            for session, seed in zip(raw["session_id"], typed["seed"]):
                if not seed.startswith("s") or int(seed[1:]) != seeds[session]:
                    fail(f"{table}: session {session} seed {seed} is not the record's {seeds[session]}")
            big = sum(1 for s in seeds.values() if s > 2**53)
            print(f"{table}: {len(seeds)} seeds exact ({big} above 2^53)")
    print(f"ok: {len(tables)} tables, {len(codebook)} codebook rows, {checked} cells read back as their declared types")


if __name__ == "__main__":
    main(*sys.argv[1:])
