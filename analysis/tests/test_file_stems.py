"""common.file_stem against tests/data/file_stems.csv, the table the C++ twin (src/store/export.h FileStem) is pinned
by too: one rule for every file name made from a name of the record."""
import csv
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from common import file_stem  # noqa: E402

TABLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "data", "file_stems.csv")


def golden():
    with open(TABLE, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


class FileStems(unittest.TestCase):
    def test_each_name_gets_the_tables_stem(self):
        rows = golden()
        self.assertGreater(len(rows), 30)
        for row in rows:
            self.assertEqual(file_stem(row["name"]), row["stem"], repr(row["name"]))

    def test_stems_fit_a_file_system_and_are_unique(self):
        stems = [file_stem(row["name"]) for row in golden()]
        self.assertEqual(len(set(stems)), len(stems))
        self.assertEqual(len({s.lower() for s in stems}), len(stems))  # none differs by case only
        for s in stems:
            self.assertLessEqual(len(s.encode("utf-8")), 100, s)
            self.assertFalse(s.startswith("."), s)
            self.assertNotIn("/", s)

    def test_a_shorter_limit_is_kept_too(self):
        self.assertLessEqual(len(file_stem("\u6f22" * 72, 48)), 48)
        self.assertEqual(file_stem("pilot", 48), "pilot")
        self.assertNotEqual(file_stem("pilot 1", 48), file_stem("pilot/1", 48))


if __name__ == "__main__":
    unittest.main()
