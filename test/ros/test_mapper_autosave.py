#!/usr/bin/python3
"""rostest (e): the live map survives a crash, and the shutdown save is logged (mapper_autosave.test).

A generated drive is played (rosbag, wall time) into a nodelet in a manager this test
starts. Once an autosave holds markings and lanes, the manager is killed with SIGKILL while
the drive still plays; the autosaved files must be complete: the JSON parses (json module and
the package's reader, evaluate_map), holds markings and lanes, and the GeoJSON and TUM
siblings are there. A second manager holds two instances, one saving to an unwritable
path, the other reset after its autosave; it is stopped with SIGINT and must log both
shutdown saves through rosconsole (the failure as [ERROR]) before it exits, and the
post-reset map must go to map_reset1.json, the autosaved map.json kept.
"""
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import unittest

import rospy
import rostest
from std_srvs.srv import Trigger

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import irm_rostest as irm  # noqa: E402

FRAMES = 260  # 13 s at 20 Hz: the first arrows are mapped after about 9 s
SCENARIO = os.path.join(irm.SOURCE_DIR, "config", "scenarios", "public_road.yaml")
AUTOSAVE_PERIOD_S = 2.0
SAVE_STATUS = re.compile(r"ok: (\d+) markings, (\d+) lanes")


def start_manager(name, log_path):
    """A nodelet manager in its own process, its stdout + stderr in log_path."""
    log = open(log_path, "w")
    env = dict(os.environ, ROSCONSOLE_STDOUT_LINE_BUFFERED="1")
    process = subprocess.Popen(["rosrun", "nodelet", "nodelet", "manager", "__name:=" + name],
                               stdout=log, stderr=subprocess.STDOUT, env=env,
                               start_new_session=True)
    return process, log


def mapper_params(save_map_path, **overrides):
    return irm.load_config(**dict({"ros/save_map_path": save_map_path,
                                   "ros/autosave_period_s": AUTOSAVE_PERIOD_S,
                                   "ros/sync_queue_size": 200,
                                   "ros/input_queue_size": 5000}, **overrides))


class MapperAutosaveTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.out = sys.argv[1] if len(sys.argv) > 1 and not sys.argv[1].startswith("__") else \
            "/tmp/irm_rostest_autosave"
        shutil.rmtree(cls.out, ignore_errors=True)
        os.makedirs(cls.out)
        drive = os.path.join(cls.out, "drive")
        rc, log = irm.run(["rosrun", "ipm_road_mapper", "generate_drive", "--scenario", SCENARIO,
                           "--seed", "1", "--max-frames", str(FRAMES), "--out", drive], 120)
        assert rc == 0, log
        cls.bag = os.path.join(drive, "drive.bag")
        cls.diagnostics = irm.Diagnostics()

    def test_a_sigkill_mid_drive_leaves_the_last_autosave(self):
        start = time.monotonic()
        path = os.path.join(self.out, "killed", "map.json")
        manager, log = start_manager("autosave_manager", os.path.join(self.out, "killed.log"))
        try:
            self.assertTrue(irm.Manager("/autosave_manager").load("/autosaving",
                                                                  mapper_params(path)))
            play = subprocess.Popen(["rosbag", "play", "-q", "-d", "1", self.bag],
                                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

            def saved_counts():
                status = self.diagnostics.value("autosaving: saves", "last save status", "")
                match = SAVE_STATUS.match(status)
                return (int(match.group(1)), int(match.group(2))) if match else None

            counts = irm.wait_for(lambda: (saved_counts() or (0, 0))[0] > 0 and
                                  saved_counts()[1] > 0 and saved_counts(), 60,
                                  "an autosave with markings and lanes")
            self.assertIsNone(play.poll(), "the drive ended before an autosave held markings")
            manager.send_signal(signal.SIGKILL)
            manager.wait(10)
            killed_at = time.time()
            play.wait(60)
        finally:
            if manager.poll() is None:
                manager.kill()
            log.close()
        print("autosave before the kill: %d markings, %d lanes (%.1f s)"
              % (counts[0], counts[1], time.monotonic() - start))

        with open(path) as f:
            saved = json.load(f)
        self.assertGreater(len(saved["markings"]), 0)
        self.assertGreater(len(saved["lanes"]), 0)
        self.assertGreater(len(saved["trajectory"]), 0)
        self.assertLess(killed_at - os.path.getmtime(path), 4 * AUTOSAVE_PERIOD_S + 2)
        self.assertGreater(
            os.path.getsize(os.path.join(self.out, "killed", "map_trajectory_tum.txt")), 0)
        # No geo_origin in the config: no GeoJSON (local metres are not WGS84).
        self.assertFalse(os.path.exists(os.path.join(self.out, "killed", "map.geojson")))
        ground_truth = os.path.join(self.out, "drive", "ground_truth.json")
        rc, text = irm.run(["rosrun", "ipm_road_mapper", "evaluate_map", "--map", path,
                            "--ground-truth", ground_truth], 60)
        self.assertEqual(rc, 0, text)

    def test_b_sigint_logs_the_shutdown_saves(self):
        good = os.path.join(self.out, "sigint", "map.json")
        blocker = os.path.join(self.out, "not_a_folder")
        with open(blocker, "w") as f:
            f.write("a file where the save folder should be\n")
        bad = os.path.join(blocker, "map.json")
        log_path = os.path.join(self.out, "sigint.log")
        manager, log = start_manager("sigint_manager", log_path)
        try:
            services = irm.Manager("/sigint_manager")
            self.assertTrue(services.load("/good_saver", mapper_params(good)))
            self.assertTrue(services.load("/bad_saver", mapper_params(bad)))
            rc, text = irm.run(["rosbag", "play", "-q", "-d", "1", "-u", "5", self.bag], 60)
            self.assertEqual(rc, 0, text)
            irm.wait_for(lambda: self.diagnostics.value("bad_saver: saves", "failures", "0")
                         != "0", 30, "a failed autosave on the diagnostics")
            # ~reset, then the shutdown save of the (empty) post-reset map must not
            # overwrite the autosaved one.
            irm.wait_for(lambda: SAVE_STATUS.match(self.diagnostics.value(
                "good_saver: saves", "last save status", "") or "") and
                os.path.isfile(good), 30, "an autosave of /good_saver")
            with open(good) as f:
                autosaved = json.load(f)
            self.assertGreater(len(autosaved["markings"]) + len(autosaved["lanes"]), 0)
            rospy.wait_for_service("/good_saver/reset", timeout=30)
            reset = rospy.ServiceProxy("/good_saver/reset", Trigger)()
            self.assertTrue(reset.success, reset.message)
            manager.send_signal(signal.SIGINT)
            rc = manager.wait(30)
        finally:
            if manager.poll() is None:
                manager.kill()
            log.close()
        with open(log_path) as f:
            text = f.read()
        print(text[-3000:])
        self.assertEqual(rc, 0, text[-3000:])
        # Through rosconsole ("[ INFO] [...]:", "[ERROR] [...]:"), not only on stderr.
        after_reset = good[:-len(".json")] + "_reset1.json"
        self.assertRegex(text, r"\[ INFO\] [^\n]*map saved at shutdown: 0 markings, 0 lanes "
                               r"to " + re.escape(after_reset))
        self.assertRegex(text, r"\[ WARN\] [^\n]*after ~reset 1 has fewer elements")
        self.assertRegex(text, r"\[ERROR\] [^\n]*cannot save the map at shutdown to " +
                         re.escape(bad) + r"[^\n]*" + re.escape(blocker))
        self.assertRegex(text, r"autosave to " + re.escape(bad) + " failed")
        with open(good) as f:  # the pre-reset map is still there
            kept = json.load(f)
        self.assertEqual(len(kept["markings"]) + len(kept["lanes"]),
                         len(autosaved["markings"]) + len(autosaved["lanes"]))
        with open(after_reset) as f:
            self.assertEqual(len(json.load(f)["markings"]), 0)
        self.assertTrue(os.path.isfile(good[:-len(".json")] + "_reset1_trajectory_tum.txt"))
        self.assertFalse(os.path.exists(good[:-len(".json")] + "_reset1.geojson"))


if __name__ == "__main__":
    rospy.init_node("test_mapper_autosave")
    rostest.rosrun("ipm_road_mapper", "mapper_autosave", MapperAutosaveTest)
