#!/usr/bin/python3
"""Tests of the long-drive benchmark's arithmetic (scripts/irm_bench/long_split.py and the
per-part CPU / RSS figures of scripts/irm_bench/long_stats.py) on a hand-made drive, map and
--stats-out CSV. Run: python3 test/eval/test_long_split.py
"""
import math
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
from irm_bench import long_split  # noqa: E402
from irm_bench import long_stats  # noqa: E402
from irm_bench.runners import BenchmarkError  # noqa: E402


def pose(x, y):
    return {"t": [x, y, 0.0], "q_xyzw": [0.0, 0.0, 0.0, 1.0]}


def straight_drive(length_m=600.0, step_m=0.5):
    """A drive along +x: a frame every step_m, stamps 0.05 s apart."""
    n = int(length_m / step_m) + 1
    return [{"stamp": 1000.0 + 0.05 * k, "T_map_base_true": pose(k * step_m, 0.0),
             "T_map_base_odom": pose(k * step_m, 0.0)} for k in range(n)]


def marking(mid, x):
    return {"id": mid, "class_id": 10, "corners": [[x - 1, -1, 0], [x + 1, -1, 0],
                                                   [x + 1, 1, 0], [x - 1, 1, 0]]}


def ground_truth():
    return {"format": "ipm_road_mapper/ground_truth", "frames": straight_drive(),
            "markings": [marking(i + 1, 50.0 + 100.0 * i) for i in range(6)],
            "lanes": [{"id": 1, "class_id": 1, "points": [[0.1 * k, 1.75, 0.0]
                                                          for k in range(6001)]}]}


def vector_map():
    control = [[3.0 * k - 3.0, 1.8, 0.0] for k in range(203)]  # -3 .. 603 m
    return {"format": "ipm_road_mapper/vector_map",
            "markings": [marking(100 + i, 52.0 + 100.0 * i) for i in range(6)],
            "lanes": [{"id": 7, "class_id": 1, "control_points": control}],
            "trajectory": [dict(pose(0.5 * k, 0.0), stamp=1000.0 + 0.05 * k)
                           for k in range(0, 1201, 10)]}


class DriveIndexTest(unittest.TestCase):
    def test_distances_and_nearest_frames(self):
        index = long_split.DriveIndex(straight_drive())
        self.assertAlmostEqual(index.total_m, 600.0)
        self.assertAlmostEqual(index.distance_at_point([123.4, 8.0]), 124.0)  # indexed every 2 m
        self.assertAlmostEqual(index.distance_at_point([-50.0, 0.0]), 0.0)
        self.assertAlmostEqual(index.distance_at_point([900.0, 30.0]), 600.0)
        self.assertAlmostEqual(index.distance_at_point([1e5, -3e4]), 600.0)  # far: all frames
        self.assertAlmostEqual(index.distance_at_stamp(1000.0 + 0.05 * 10.5), 5.25)
        self.assertAlmostEqual(index.distance_at_stamp(0.0), 0.0)

    def test_equal_parts_cover_the_drive(self):
        parts = long_split.equal_parts(600.0, 6)
        self.assertEqual(parts[0], (0.0, 100.0))
        self.assertEqual(parts[-1], (500.0, 600.0))


class DriveSplitTest(unittest.TestCase):
    def setUp(self):
        self.split = long_split.DriveSplit(ground_truth(), vector_map(), margin_m=30.0)
        self.parts = long_split.equal_parts(self.split.index.total_m, 6)

    def test_every_spline_segment_lands_in_exactly_one_part(self):
        original = vector_map()["lanes"][0]["control_points"]
        segments = []
        for d0, d1 in self.parts:
            for lane in self.split.map_part(d0, d1)["lanes"]:
                c = lane["control_points"]
                self.assertGreaterEqual(len(c), 4)
                first = original.index(c[0])
                # A contiguous slice of the original: the same curve, with its phantom ends.
                self.assertEqual(c, original[first:first + len(c)])
                segments += list(range(first + 1, first + len(c) - 2))
                for p in c[1:-1]:
                    self.assertGreaterEqual(p[0], d0 - 3.0)
                    self.assertLessEqual(p[0], d1 + 3.0)
        self.assertEqual(sorted(segments), list(range(1, len(original) - 2)))

    def test_renumbered_lane_pieces_carry_no_stale_topology(self):
        # A joined map names lanes by the whole map's ids; the crop renumbers its pieces, so a
        # kept predecessor could name the piece itself (evaluate_map refuses such a map).
        whole = vector_map()
        whole["lanes"][0]["predecessors"] = [1]
        whole["lanes"][0]["successors"] = [9]
        split = long_split.DriveSplit(ground_truth(), whole, margin_m=30.0)
        for d0, d1 in self.parts:
            for lane in split.map_part(d0, d1)["lanes"]:
                self.assertEqual(lane["predecessors"], [])
                self.assertEqual(lane["successors"], [])

    def test_unmeasured_ranges_follow_their_points_into_the_pieces(self):
        # Control points 30-36 (x 87-105 m) and 66 (x 195 m) were laid by a join: each piece
        # flags exactly those of its points, at its own indices (evaluate_map refuses a range
        # beyond a lane's points).
        whole = vector_map()
        whole["lanes"][0]["unmeasured"] = [[30, 36], [66, 66]]
        laid_x = {3.0 * k - 3.0 for k in list(range(30, 37)) + [66]}
        split = long_split.DriveSplit(ground_truth(), whole, margin_m=30.0)
        flagged = set()
        for d0, d1 in self.parts:
            for lane in split.map_part(d0, d1)["lanes"]:
                c = lane["control_points"]
                for first, last in lane["unmeasured"]:
                    self.assertLessEqual(0, first)
                    self.assertLessEqual(first, last)
                    self.assertLess(last, len(c))
                    flagged |= {c[i][0] for i in range(first, last + 1)}
                for i, p in enumerate(c):
                    inside = any(a <= i <= b for a, b in lane["unmeasured"])
                    self.assertEqual(inside, p[0] in laid_x, p)
        self.assertEqual(flagged, laid_x)

    def test_markings_frames_and_poses_are_cropped(self):
        map_part = self.split.map_part(100.0, 200.0)
        self.assertEqual([m["id"] for m in map_part["markings"]], [101])
        self.assertTrue(all(100.0 <= p["t"][0] < 200.0 for p in map_part["trajectory"]))
        gt_part = self.split.ground_truth_part(100.0, 200.0)
        self.assertEqual([m["id"] for m in gt_part["markings"]], [2])
        self.assertEqual(self.split.marking_ids_inside(100.0, 200.0), {2})
        xs = [p[0] for p in gt_part["lanes"][0]["points"]]
        self.assertAlmostEqual(min(xs), 69.0, delta=1.1)  # 30 m margin, 2 m index step
        self.assertAlmostEqual(max(xs), 229.0, delta=1.1)
        stamps = [f["stamp"] for f in gt_part["frames"]]
        self.assertEqual(len(stamps), 200)
        self.assertAlmostEqual(stamps[0], 1000.0 + 0.05 * 200)


class StatsTest(unittest.TestCase):
    def write(self, text):
        f = tempfile.NamedTemporaryFile("w", suffix=".csv", delete=False)
        f.write(text)
        f.close()
        self.addCleanup(os.remove, f.name)
        return f.name

    def test_cpu_per_frame_per_tenth_from_cumulative_cpu(self):
        # 5 s of start-up in the first row, then 10 ms per frame, 20 ms in the second half.
        lines, cpu = ["frame,stamp,cpu_s,rss_kb"], 5.0
        for k in range(101):
            if k > 0:
                cpu += 0.010 if k < 50 else 0.020
            lines.append("%d,%.2f,%.3f,%d" % (k, 1000.0 + 0.05 * k, cpu, 100000 + 1024 * k))
        stats = long_stats.read_stats(self.write("\n".join(lines) + "\n"))
        distances = [10.0 * k for k in range(101)]  # 1 km drive
        tenths = long_stats.cpu_ms_per_frame_by_part(stats, distances, 1000.0, 10)
        for ms in tenths[:5]:
            self.assertAlmostEqual(ms, 10.0, places=6)
        for ms in tenths[5:]:
            self.assertAlmostEqual(ms, 20.0, places=6)
        # Rows sparser than frames (every 5th frame) give the same cost per frame.
        sparse = long_stats.cpu_ms_per_frame_by_part(stats[::5], distances[::5], 1000.0, 10)
        for ms in sparse[:4]:
            self.assertAlmostEqual(ms, 10.0, places=6)
        for ms in sparse[6:]:
            self.assertAlmostEqual(ms, 20.0, places=6)
        growth = long_stats.slope([d / 1e3 for d in distances],
                                  [row[3] / 1024.0 for row in stats])
        self.assertAlmostEqual(growth, 100.0)  # 1 MB per 10 m

    def test_a_wrong_header_is_a_clear_error(self):
        with self.assertRaises(BenchmarkError) as raised:
            long_stats.read_stats(self.write("frame,cpu_s\n1,2\n"))
        self.assertIn("expected the header frame,stamp,cpu_s,rss_kb", str(raised.exception))

    def test_startup_is_read_from_the_summary(self):
        self.assertAlmostEqual(long_stats.startup_s(self.write("x\n  startup_s: 1.25\n")), 1.25)
        self.assertIsNone(long_stats.startup_s(self.write("nothing here\n")))


if __name__ == "__main__":
    unittest.main()
