"""scenes.py: a study on a tracked video described from a hand-made record, track.csv, trials and frames."""
import json
import os
import shutil
import sqlite3
import sys
import tempfile
import unittest

import pandas as pd

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import scenes  # noqa: E402

# Three frames 0.04 s apart (25 fps): one found, one tracked, one lost; one lens model (the lost frame has none).
TRACK_CSV = """frame,time_s,status,reprojection_error_px,focus_mm,aperture_mm,floor_px,note
0,0.000000,found,0.02,339.643,3.73897,0.69,""
1,0.040000,tracked,0.03,339.643,3.73897,0.69,""
2,0.080000,lost,,,,,"board not found"
"""


def make_record(path, protocols):
    """A record with the tables scenes.py reads: studies and protocol_versions (latest version last)."""
    con = sqlite3.connect(path)
    con.executescript("CREATE TABLE studies (id INTEGER PRIMARY KEY, name TEXT NOT NULL UNIQUE, created TEXT);"
                      "CREATE TABLE protocol_versions (id INTEGER PRIMARY KEY, study_id INTEGER, json TEXT, hash TEXT,"
                      " created TEXT);")
    for i, (study, protocol) in enumerate(protocols, start=1):
        sid = con.execute("SELECT id FROM studies WHERE name = ?", (study,)).fetchone()
        if sid is None:
            sid = (con.execute("INSERT INTO studies (name, created) VALUES (?, '')", (study,)).lastrowid,)
        con.execute("INSERT INTO protocol_versions (study_id, json, hash, created) VALUES (?, ?, ?, '')",
                    (sid[0], json.dumps(protocol), str(i)))
    con.commit()
    con.close()


class VideoSceneLines(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="blurcue-scenes-")
        self.addCleanup(shutil.rmtree, self.tmp, True)
        os.makedirs(os.path.join(self.tmp, "study", "track"))
        with open(os.path.join(self.tmp, "study", "track", "track.csv"), "w") as f:
            f.write(TRACK_CSV)
        self.db = os.path.join(self.tmp, "record.sqlite")
        video = {"scene": {"video": "take/take.avi", "track": "track"}}
        make_record(self.db, [("photo-study", {"scene": {"background": "scene.png"}}),
                              ("video-study", {"scene": {"background": "old.png"}}),  # an earlier version
                              ("video-study", video)])
        # Main trials: exposure 20 ms, streaks (3, 4) -> 5 px and (0, 0) on the left, (6, 8) -> 10 px on the right;
        # a practice trial's 100 px streak is left out.
        self.trials = pd.DataFrame({
            "study": ["video-study"] * 3 + ["photo-study"],
            "practice": [0, 0, 1, 0],
            "exposure_ms": [20, 20, 20, 0],
            "motion_left_x_screen_px": [3, 0, 100, 0], "motion_left_y_screen_px": [4, 0, 0, 0],
            "motion_right_x_screen_px": [6, 6, 0, 0], "motion_right_y_screen_px": [8, 8, 0, 0]})
        self.frames = os.path.join(self.tmp, "frames.csv")
        # Frames per trial: 3 and 5 (median 4).
        pd.DataFrame({"study": ["video-study"] * 8, "session_id": [1] * 8,
                      "trial_index": [0, 0, 0, 1, 1, 1, 1, 1]}).to_csv(self.frames, index=False)

    def test_a_video_study_is_described_from_its_track_folder(self):
        lines = scenes.video_scene_lines(self.db, self.trials, self.frames, [os.path.join(self.tmp, "study")])
        self.assertEqual([study for study, _ in lines], ["video-study"])  # the photo study has no line
        line = lines[0][1]
        self.assertIn("a tracked video: take take/take.avi, track folder track", line)
        self.assertIn("3 frames at 25 fps (1 found, 1 tracked, 1 lost)", line)
        self.assertIn("one lens model: focus 339.6 mm, aperture 3.74 mm", line)
        self.assertIn("exposure 20 ms", line)
        self.assertIn("left 2.50 (max 5.00), right 10.00 (max 10.00) screen px", line)
        self.assertIn("frames of the take presented per trial (frames.csv): median 4 (3-5)", line)
        # Frames without the take's columns (a record from before schema 9): no per-frame streak, no hold count.
        self.assertNotIn("held", line)

    def test_per_frame_streaks_and_held_frames_come_from_frames_csv(self):
        # Per frame (photo px): left (3, 4) -> 5 and (0, 0) -> 0, right (6, 8) -> 10 twice; 1 of 4 frames held.
        # A fifth frame, after a timed stimulus (the answer screen: no take frame, no ball), counts nowhere.
        pd.DataFrame({"study": ["video-study"] * 5, "session_id": [1] * 5, "trial_index": [0, 0, 1, 1, 1],
                      "take_status": ["found", "tracked", "held", "tracked", None],
                      "motion_left_x_px": [3, 0, None, None, None], "motion_left_y_px": [4, 0, None, None, None],
                      "motion_right_x_px": [6, 6, None, None, None], "motion_right_y_px": [8, 8, None, None, None]}
                     ).to_csv(self.frames, index=False)
        line = scenes.video_scene_lines(self.db, self.trials, self.frames, [os.path.join(self.tmp, "study")])[0][1]
        self.assertIn("motion streak per frame (frames.csv), mean over frames: left 2.50 (max 5.00), right 10.00 "
                      "(max 10.00) photo px", line)
        self.assertNotIn("mean over trials", line)
        self.assertIn("3 of 4 frames at the take frame's own pose, 1 held", line)
        self.assertIn("frames of the take presented per trial (frames.csv): median 2 (2-2)", line)

    def test_practice_trials_frames_are_left_out(self):
        # Trial 0 of session 1 is practice (9 frames); trials 1 and 2 show 3 and 5: the median is 4, not 5.
        trials = pd.DataFrame({"study": ["video-study"] * 3, "session_id": [1, 1, 1], "trial_index": [0, 1, 2],
                               "practice": [1, 0, 0], "exposure_ms": [0, 0, 0]})
        pd.DataFrame({"study": ["video-study"] * 17, "session_id": [1] * 17,
                      "trial_index": [0] * 9 + [1] * 3 + [2] * 5}).to_csv(self.frames, index=False)
        line = scenes.video_scene_lines(self.db, trials, self.frames, [os.path.join(self.tmp, "study")])[0][1]
        self.assertIn("frames of the take presented per trial (frames.csv): median 4 (3-5)", line)

    def test_versions_on_different_takes_are_described_each_with_its_own_trials(self):
        # A record merged from two stations, each with its own take: version hashes "1" and "2".
        self.db = os.path.join(self.tmp, "merged.sqlite")
        make_record(self.db, [("two-takes", {"scene": {"video": "a/take.avi", "track": "track"}}),
                              ("two-takes", {"scene": {"video": "b/take.avi", "track": "elsewhere"}})])
        hashes = [h for study, h, _, _ in scenes.protocol_versions(self.db) if study == "two-takes"]
        self.assertEqual(hashes, ["1", "2"])
        trials = pd.DataFrame({"study": ["two-takes"] * 2, "protocol_hash": hashes, "exposure_ms": [5, 40]})
        lines = [line for study, line in scenes.video_scene_lines(self.db, trials, None,
                                                                  [os.path.join(self.tmp, "study")])
                 if study == "two-takes"]
        self.assertEqual(len(lines), 2, lines)
        self.assertIn(f"2 takes in this record's protocol versions; version ({hashes[0]}): a tracked video: take "
                      "a/take.avi", lines[0])
        self.assertIn("exposure 5 ms", lines[0])
        self.assertNotIn("40 ms", lines[0])
        self.assertIn("take b/take.avi", lines[1])
        self.assertIn("exposure 40 ms", lines[1])
        self.assertIn("the take's frames: not determined", lines[1])

    def test_one_protocol_text_on_two_takes_is_two_takes(self):
        # Two stations ran one protocol file on takes of their own: blurcue recorded each take's identity with the
        # text (recorded_take), so the record holds two texts; the report describes two takes.
        self.db = os.path.join(self.tmp, "stations.sqlite")
        scene = {"video": "take/take.avi", "track": "track"}
        make_record(self.db, [("s", {"scene": scene, "recorded_take": {"frames": 3, "fps": 25, "frames_fnv1a64": "a"}}),
                              ("s", {"scene": scene, "recorded_take": {"frames": 8, "fps": 30, "frames_fnv1a64": "b"}})])
        trials = pd.DataFrame({"study": ["s", "s"], "protocol_hash": ["1", "2"], "exposure_ms": [0, 0]})
        lines = [line for _, line in scenes.video_scene_lines(self.db, trials, None, [os.path.join(self.tmp, "none")])]
        self.assertEqual(len(lines), 2, lines)
        self.assertIn("as run: 3 frames at 25 fps", lines[0])
        self.assertIn("as run: 8 frames at 30 fps", lines[1])

    def test_a_track_folder_found_nowhere_is_not_determined(self):
        lines = scenes.video_scene_lines(self.db, self.trials, None, [os.path.join(self.tmp, "elsewhere")])
        self.assertIn("the take's frames: not determined", lines[0][1])
        self.assertNotIn("frames at", lines[0][1])

    def test_a_focus_pull_is_a_range(self):
        rows = [{"frame": "0", "time_s": "0", "status": "found", "focus_mm": "300"},
                {"frame": "1", "time_s": "0.5", "status": "tracked", "focus_mm": "420.04"}]
        self.assertEqual(scenes.describe_take(rows),
                         "2 frames at 2 fps (1 found, 1 tracked, 0 lost), focus per frame 300.0-420.0 mm")


if __name__ == "__main__":
    unittest.main(verbosity=2)
