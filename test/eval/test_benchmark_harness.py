#!/usr/bin/python3
"""Tests of the benchmark harness (scripts/irm_bench): its command line, the configs it writes,
its plan, the table layout, the docs sections and the target rows, on hand-made metrics (no
tool runs). Run: python3 test/eval/test_benchmark_harness.py
"""
import json
import math
import os
import sys
import tempfile
import unittest

import yaml

REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
sys.path.insert(0, os.path.join(REPO, "scripts"))
from irm_bench import (cli, configs, drives, long_stats, plan, registry, report,  # noqa: E402
                       targets)
from irm_bench.runners import BenchmarkError  # noqa: E402
from irm_bench.context import Context  # noqa: E402
from irm_bench.tables import fleet_passes, full_method, long_drive, speed  # noqa: E402


class Folder(unittest.TestCase):
    """A test with a scratch folder and a Context on it (no shared data there)."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)
        self.ctx = Context(repo=REPO, bin="/nonexistent", shared=self.tmp.name, out=self.tmp.name)


class CommandLine(unittest.TestCase):
    base = ["--repo", REPO, "--bin", "/b"]

    def parse(self, *extra):
        return cli.parse(self.base + list(extra))

    def test_modes(self):
        self.assertEqual(self.parse().mode, "all")
        self.assertEqual(self.parse("--long").mode, "long")
        self.assertEqual(self.parse("--fleet-passes").mode, "fleet-passes")
        self.assertEqual(self.parse("--long", "--instructions").instructions, True)

    def test_wrong_combinations_are_refused(self):
        for extra in (["--long", "--fleet-passes"], ["--instructions"],
                      ["--quick", "--write-docs"], ["--scenarios", "port", "--write-docs"]):
            with self.assertRaises(SystemExit, msg=extra):
                with open(os.devnull, "w") as null:
                    sys.stderr, saved = null, sys.stderr
                    try:
                        self.parse(*extra)
                    finally:
                        sys.stderr = saved

    def test_quick_is_public_road_alone(self):
        ctx = cli.context(self.parse("--quick", "--out", "/tmp/x"))
        self.assertEqual((ctx.scenarios, ctx.extra, ctx.fleet), (["public_road"], False, False))
        self.assertEqual(ctx.build, "/")

    def test_every_mode_has_its_help_and_every_table_its_interface(self):
        for mode in registry.modes():
            self.assertIn(mode, registry.MODE_HELP)
        for module in registry.TABLES:
            for name in ("TITLE", "MODES", "requests", "tables"):
                self.assertTrue(hasattr(module, name), (module.__name__, name))
        self.assertEqual([m.__name__.split(".")[-1] for m in registry.tables_of("fleet-passes")],
                         ["fleet_passes"])


class Selection(Folder):
    def test_absent_real_drive_is_left_out_and_said(self):
        ctx = Context.from_selection("public_road,av2_pit_dev,av2_pit_fleet", repo=REPO, bin="/b",
                                     shared=self.tmp.name, out=self.tmp.name)
        self.assertEqual(ctx.scenarios, ["public_road"])
        self.assertTrue(ctx.real_absent and ctx.fleet)
        self.assertEqual(drives.fleet_passes(ctx), [])

    def test_fleet_passes_are_found_in_place(self):
        fleet = os.path.join(self.tmp.name, "data", drives.FLEET)
        for name in ("pass_01", "pass_00", "notes"):
            os.makedirs(os.path.join(fleet, name))
        for name in ("pass_00", "pass_01"):
            open(os.path.join(fleet, name, "ground_truth_odom.json"), "w").close()
        open(os.path.join(fleet, "classes.yaml"), "w").close()
        passes = drives.fleet_passes(self.ctx)
        self.assertEqual([drives.pass_label(p) for p in passes], ["pass_00", "pass_01"])
        self.assertTrue(passes[0].ground_truth.endswith("pass_00/ground_truth_odom.json"))
        self.assertEqual(passes[1].classes, os.path.join(fleet, "classes.yaml"))
        self.assertIsNone(passes[0].scenario)  # read in place, never generated


class Lock(Folder):
    def test_a_second_run_on_one_folder_stops(self):
        first = cli.lock(self.tmp.name)
        self.addCleanup(first.close)
        with self.assertRaises(BenchmarkError) as raised:
            cli.lock(self.tmp.name)
        self.assertEqual(raised.exception.exit_code, 2)
        self.assertIn("another benchmark run is using", str(raised.exception))


class WrittenConfigs(Folder):
    def test_true_extrinsic_comes_from_the_evaluators_figures(self):
        needed = {"extrinsic_true_xyz_m": [1.5, 0.0, 1.4],
                  "extrinsic_true_rpy_deg": [-91.25, 0.5, -90.0]}
        drive = drives.synthetic(self.ctx, "public_road")
        for held in (False, True):
            config = configs.true_extrinsic(held)
            self.assertEqual(config.needs, configs.IPM)
            with open(config.write(self.ctx, drive, needed)) as f:
                content = yaml.safe_load(f)
            self.assertEqual(content["input"]["extrinsic"],
                             {"xyz": [1.5, 0.0, 1.4], "rpy_deg": [-91.25, 0.5, -90.0]})
            self.assertEqual(content.get("backend"),
                             {"optimize_extrinsic": False} if held else None)
            self.assertTrue(os.path.isfile(content["base"]))

    def test_noise_configs_hold_the_rounded_figures(self):
        drive = drives.noise(self.ctx, 0.3)
        with open(drive.scenario) as f:
            scenario = yaml.safe_load(f)
        self.assertEqual(scenario["odometry"], {"jitter_xy_m": 0.2394, "jitter_yaw_deg": 0.376})
        self.assertEqual(scenario["name"], "public_road_noise_0.3")
        with open(configs.noise_told(0.3).write(self.ctx, drive, None)) as f:
            backend = yaml.safe_load(f)["backend"]
        self.assertEqual(backend["pose_prior_sigma_trans_m"], [0.45, 0.45, 0.02])
        self.assertEqual(backend["pose_prior_sigma_rot_deg"], [0.05, 0.05, 0.6])

    def test_variant_scenarios_chain_to_their_base(self):
        drive = drives.variant(self.ctx, drives.CROWN)
        with open(drive.scenario) as f:
            scenario = yaml.safe_load(f)
        self.assertEqual(scenario["road"]["surface"]["crown_pct"], 2.0)
        self.assertTrue(scenario["base"].endswith("config/scenarios/public_road.yaml"))


class Plan(Folder):
    def test_requests_are_unique_and_bring_what_they_need(self):
        drive = drives.synthetic(self.ctx, "port")
        requests = plan.unique([plan.Request(drive, configs.true_extrinsic(True)),
                                plan.Request(drive, configs.ablation("ours_ppsr")),
                                plan.Request(drive, configs.ablation("ours_ppsr"))])
        self.assertEqual([r.key for r in requests], [("port", "ipm"), ("port",
                                                                        "true_extrinsic_held"),
                                                      ("port", "ours_ppsr")])


class Layout(unittest.TestCase):
    def test_text_aligns_columns_as_before(self):
        table = report.Table("T", ["a", "bb"], [["xyz", 1], ["q", None]])
        self.assertEqual(report.text(table), "\nT\na   | bb  \n----+-----\nxyz | 1   \nq   | None")

    def test_markdown_escapes_bars(self):
        self.assertEqual(report.markdown(report.Table("T", ["a"], [["x | y"]])),
                         "**T**\n\n| a |\n|---|\n| x \\| y |")

    def test_fmt(self):
        self.assertEqual((report.fmt(0.12345), report.fmt(2, 1), report.fmt(None),
                          report.fmt(float("nan"))), ("0.123", "2.0", "-", "-"))

    def test_docs_sections_are_replaced_or_appended(self):
        doc = "intro\n%s\nold\n%s\nrest\n" % (report.begin_marker("speed"),
                                             report.end_marker("speed"))
        new = report.replace_section(doc, "speed", "new table")
        self.assertEqual(new, doc.replace("old", "new table"))
        self.assertEqual(report.replace_section(new, "speed", "new table"), new)
        added = report.replace_section("intro\n", "fleet_passes", "rows")
        self.assertTrue(added.endswith("rows\n%s\n" % report.end_marker("fleet_passes")))


def metrics(**figures):
    m = {"_metadata": {"frames_used": 100}, "_wall_s": 1.0, "_cpu_s": 2.0}
    m.update(figures)
    return m


class Tables(Folder):
    def test_speed_side_by_side_is_the_cpu_ratio(self):
        self.ctx.scenarios = ["public_road"]
        results = {("public_road", "ipm"): metrics(_cpu_s=1.0),
                   ("public_road", "ours_ppsr"): metrics(_cpu_s=3.0)}
        table = speed.side_by_side(self.ctx, results)
        self.assertEqual(table.rows, [["public_road", "10.00", "30.00", "3.00"]])

    def test_table_5_lists_the_drives_in_order(self):
        self.ctx.scenarios = ["public_road", "port"]
        keys = ["port_seed2", "public_road_seed2", "port", "public_road", drives.CROWN]
        results = {(k, "ours_ppsr"): metrics() for k in keys}
        self.assertEqual(full_method.drives_of(self.ctx, results),
                         ["public_road", "port", "public_road_seed2", "port_seed2",
                          drives.CROWN])


def path(*legs):
    """Frames along straight legs (heading deg, length m), a frame every 0.5 m."""
    frames, x, y = [], 0.0, 0.0
    for heading, length in legs:
        for _ in range(int(length / 0.5)):
            x += 0.5 * math.cos(math.radians(heading))
            y += 0.5 * math.sin(math.radians(heading))
            frames.append({"T_map_base_true": {"t": [x, y, 0.0]}})
    return frames


class FleetPasses(unittest.TestCase):
    def test_a_turn_is_the_span_of_the_heading(self):
        self.assertAlmostEqual(fleet_passes.heading_change_deg(path((30, 50))), 0.0, places=6)
        self.assertAlmostEqual(fleet_passes.heading_change_deg(path((0, 30), (-90, 30))), 90.0,
                               places=6)
        # A right turn and back left spans the turn, not start against end; across +-180 too.
        self.assertAlmostEqual(fleet_passes.heading_change_deg(
            path((170, 30), (-100, 30), (170, 30))), 90.0, places=6)
        self.assertEqual(fleet_passes.heading_change_deg(path((0, 3))), 0.0)

    def test_worst_and_mean_rows(self):
        rows = [("pass_00", {"marking_matched": 1, "ceiling_markings_reachable": 4,
                             "marking_ape_mean_m": 0.5, "lane_f1": 0.5, "ceiling_lane_f1": 1.0,
                             "lane_ape_mean_m": 0.2, "extrinsic_rot_err_deg_initial": 1.0,
                             "extrinsic_rot_err_deg": 0.5, "pose_trans_err_m_input": 0.2,
                             "pose_trans_err_m": 0.1}),
                ("pass_01", {"marking_matched": 0, "ceiling_markings_reachable": 2,
                             "marking_ape_mean_m": None, "lane_f1": 0.6, "ceiling_lane_f1": 0.8,
                             "lane_ape_mean_m": 0.4, "extrinsic_rot_err_deg_initial": 0.5,
                             "extrinsic_rot_err_deg": 0.7, "pose_trans_err_m_input": 0.2,
                             "pose_trans_err_m": 0.3})]
        table = fleet_passes.per_pass_table("m", rows)
        worst, mean = table.rows[-2], table.rows[-1]
        self.assertEqual(worst[:6], ["worst", "0 / 2 (pass_01)", "0.500 (pass_00)",
                                     "0.50 / 1.00 (pass_00)", "0.400 (pass_01)",
                                     "0.50 -> 0.70 (pass_01)"])
        self.assertEqual(worst[8:], ["0.200 -> 0.300 (pass_01)", "- -> -"])
        self.assertEqual(mean[1:6], ["1 / 6", "0.500", "0.55 / 0.90", "0.300", "0.75 -> 0.60"])
        self.assertEqual(len(table.header), len(worst))


class FleetTargets(Folder):
    def test_the_fleet_rows_read_every_pass(self):
        fleet = os.path.join(self.tmp.name, "data", drives.FLEET)
        for name, legs in (("pass_00", [(0, 40)]), ("pass_01", [(0, 30), (90, 30)])):
            os.makedirs(os.path.join(fleet, name))
            with open(os.path.join(fleet, name, "ground_truth_odom.json"), "w") as f:
                json.dump({"frames": path(*legs)}, f)
        open(os.path.join(fleet, "classes.yaml"), "w").close()
        self.ctx.fleet = True
        common = {"ceiling_markings": [{"gt_id": 1, "reachable": True},
                                       {"gt_id": 2, "reachable": True}],
                  "ceiling_markings_reachable": 2, "lane_f1": 0.5, "ceiling_lane_f1": 1.0,
                  "ipm_grid_err_m": 0.2, "ipm_grid_err_m_initial": 0.3,
                  "extrinsic_trans_err_m": 0.1, "extrinsic_trans_err_m_initial": 0.1,
                  "pose_trans_err_moving_m_input": 0.2}
        results = {
            ("av2_pit_fleet_pass_00", "ours_ppsr"): dict(
                common, marking_matched=1, marking_ape_mean_m=0.4, lane_ape_mean_m=0.3,
                gt_markings=[{"gt_id": 1, "matched": True}], extrinsic_rot_err_deg=0.9,
                extrinsic_rot_err_deg_initial=0.8, pose_trans_err_moving_m=0.1),
            ("av2_pit_fleet_pass_01", "ours_ppsr"): dict(
                common, marking_matched=0, marking_ape_mean_m=None, lane_ape_mean_m=0.1,
                gt_markings=[], extrinsic_rot_err_deg=0.2, extrinsic_rot_err_deg_initial=0.8,
                pose_trans_err_moving_m=0.3)}
        table = targets.group_table(self.ctx, results, targets.load(), fleet_passes.GROUP,
                                    fleet_passes.FUNCTIONS, "")
        now = [row[2] for row in table.rows]
        self.assertEqual(now[0], "1 / 4 (0.25); centre APE mean 0.400 m, worst 0.400 m (pass_00)")
        self.assertEqual(now[1], "1 / 2")
        self.assertEqual(now[2], "F1 0.50 of the ceiling (pass_00); lane APE 0.300 m (pass_00)")
        self.assertEqual(now[3], "IPM grid: none; rotation: pass_00; translation: none")
        self.assertEqual(now[4], "0.20 (pass_01); turning: pass_01")
        self.assertEqual(now[5], "1.50 (pass_01)")


class LongDrive(Folder):
    def test_the_unload_line_is_read(self):
        line = ("long drive: 20118 frames pushed in 300.1 s (20118 poses, 660 markings, 30 lanes, "
                "10.06 km driven); unload: Finish 2.68 s (finished map), saved at 3.00 s, mapping "
                "thread joined at 3.02 s; budget 3.0 s\n")
        self.assertEqual(long_stats.unload_figures(line), (3.02, 3.0))
        self.assertEqual(long_stats.unload_figures("[  SKIPPED ] set IRM_LONG_BAG"), (None, None))

    def test_publish_stats_are_read_by_column_name(self):
        path = os.path.join(self.tmp.name, "publish.csv")
        with open(path, "w") as f:
            f.write("km,frame,markings,lanes,changed_elements,export_changes_ms,"
                    "export_snapshot_ms,publish_ms,publish_old_ms\n1,20,5,2,3,0.02,0.04,0.3,0.9\n")
        rows = long_stats.read_publish_stats(path)
        self.assertEqual((rows[0]["km"], rows[0]["publish_ms"]), (1.0, 0.3))
        table = long_drive.publish_rows(rows)
        self.assertEqual(table[0], ["publish CPU per publish at 1 km (delta + markers)", "0.300 ms"])
        with open(path, "w") as f:
            f.write("km,frame\n1,2\n")
        with self.assertRaises(BenchmarkError):
            long_stats.read_publish_stats(path)
        self.assertIsNone(long_stats.read_publish_stats(path + ".absent"))


class Targets(Folder):
    def test_every_row_of_the_data_file_fills(self):
        rows = targets.load()
        self.ctx.scenarios = ["public_road", "port", "hilly", "urban", "curvy", drives.REAL]
        names = self.ctx.scenarios + ["public_road_seed2", "hilly_seed3", full_method.NOISE,
                                      drives.BLOBS, drives.URBAN_LABELLED]
        figures = dict(marking_matched=2, marking_gt_visible=4, marking_ape_mean_m=0.1,
                       lane_ape_mean_m=0.05, ipm_grid_err_m=0.1, ipm_grid_err_m_initial=0.2,
                       extrinsic_trans_err_m=0.1, extrinsic_trans_err_m_initial=0.05)
        results = {(n, c): metrics(**figures) for n in names
                   for c in ("ours_ppsr", "ipm", "true_extrinsic_held")}
        groups = sorted({r["group"] for r in rows})
        for group in groups:
            table = targets.group_table(self.ctx, results, rows, group, fleet_passes.FUNCTIONS,
                                        group)
            if group == fleet_passes.GROUP:
                self.assertIsNone(table)  # no pass mapped
                continue
            for row in table.rows:
                self.assertNotIn("{", row[2] + row[0], row)
        markings = targets.group_table(self.ctx, results, rows, "markings", targets.FUNCTIONS, "")
        self.assertIn(["av2_pit_dev", "crossing recall", "2 / 4", ">= 3 / 4"], markings.rows)
        calibration = targets.group_table(self.ctx, results, rows, "calibration and poses",
                                          targets.FUNCTIONS, "")
        self.assertEqual(calibration.rows[1][0], "8 benchmark drives")
        self.assertIn("public_road", calibration.rows[1][2])  # translation 0.05 -> 0.1

    def test_templates(self):
        results = {("d", "ours_ppsr"): {"a": 0.12345, "n": 3, "f1": 0.5},
                   ("d", "ipm"): {"a": 0.5},
                   ("d", "true_extrinsic_held"): {"a": 0.25}}
        scope = targets.Scope(self.ctx, results, "d")
        fill = lambda t: targets.fill(t, scope, targets.FUNCTIONS)
        self.assertEqual(fill("{a} / {a:1} / {n} / {missing}"), "0.123 / 0.1 / 3 / -")
        self.assertEqual(fill("{ipm/a}x{@ratio(ipm/a, a):1}"), "0.500x4.1")
        self.assertEqual(fill("{@held(a)}"), " (with the true extrinsic held: 0.250)")
        self.assertEqual(fill("{@held(a, pose )}"), " (pose with the true extrinsic held: 0.250)")
        with self.assertRaises(KeyError):
            fill("{@no_such_function}")

    def test_absent_drive_prints_one_skipped_row(self):
        self.ctx.real_absent = True
        rows = [{"group": "g", "drive": drives.REAL, "figure": "f", "now": "{x}", "target": "t",
                 "absent": "f and more"},
                {"group": "g", "drive": drives.REAL, "figure": "f2", "now": "{x}", "target": "t"}]
        table = targets.group_table(self.ctx, {}, rows, "g", targets.FUNCTIONS, "G")
        self.assertEqual(table.rows, [[drives.REAL, "f and more", "skipped: not present", ""]])

    def test_unknown_keys_are_refused(self):
        path = os.path.join(self.tmp.name, "t.yaml")
        with open(path, "w") as f:
            yaml.safe_dump([{"group": "g", "figure": "f", "now": "n", "target": "t",
                             "taget": "typo"}], f)
        with self.assertRaises(ValueError) as raised:
            targets.load(path)
        self.assertIn("taget", str(raised.exception))


if __name__ == "__main__":
    unittest.main()
