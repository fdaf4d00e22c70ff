#!/usr/bin/python3
"""rostest (poses, REP-105): see mapper_poses.test.

The drive is the default public_road scenario (odometry: 8 cm of per-message random error
over a 2 cm slow drift). Every ~corrected_odom message and a tf lookup map -> base_link at
its stamp are compared with the true pose of that frame (ground_truth.json), as is the input
odometry at the same frames.
"""
import json
import math
import os
import shutil
import sys
import threading
import time
import unittest

import rospy
import rostest
import tf2_ros
from nav_msgs.msg import Odometry

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import irm_rostest as irm  # noqa: E402

FRAMES = 300  # 15 s at 20 Hz
SCENARIO = os.path.join(irm.SOURCE_DIR, "config", "scenarios", "public_road.yaml")
# The corrected poses' mean error at most this fraction of the input's. Measured
# 0.564-0.579 (0.0855 -> 0.0482-0.0495 m over nine runs) with the newest pose's tail under the
# constant-twist prior (pose_extrapolator.h); 0.63-0.65 under the map-frame motion prior,
# which bent the tail outwards on curves, and 0.76 with the two newest solved frames held as
# the tail's data. What is left is the window's newest frames' own error (a causal estimate:
# no later frame smooths them; docs/backend.md, "Poses after a solve"). A correction that
# made the poses worse (1.5x with the velocity taken from the odometry) fails here.
MAX_ERROR_RATIO = 0.62
# The published covariance against the error it describes: the mean squared x/y error over
# the mean x/y variance of the messages after the first solve must stay below 1 (not
# overconfident). Measured 0.06: the newest frame's full odometry noise (0.15 m per axis) is
# on top of the solve's carried marginal, against an rms error of ~0.04 m. The tail's own
# covariance in its place (0.25 here) was overconfident on port (2.6: its slow drift is in
# neither the solve's marginal nor the tail's white-noise model; docs/backend.md).
MAX_COVARIANCE_CONSISTENCY = 1.0


def distance(a, b):
    return math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)))


class MapperPosesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.out = sys.argv[1] if len(sys.argv) > 1 and not sys.argv[1].startswith("__") else \
            "/tmp/irm_rostest_poses"
        shutil.rmtree(cls.out, ignore_errors=True)
        os.makedirs(cls.out)
        drive = os.path.join(cls.out, "drive")
        rc, log = irm.run(["rosrun", "ipm_road_mapper", "generate_drive", "--scenario", SCENARIO,
                           "--seed", "1", "--max-frames", str(FRAMES), "--out", drive], 180)
        assert rc == 0, log
        with open(os.path.join(drive, "ground_truth.json")) as f:
            cls.truth = {round(fr["stamp"], 3): fr for fr in json.load(f)["frames"]}

        cls.lock = threading.Lock()
        cls.odometry = []
        rospy.Subscriber("/mapper/corrected_odom", Odometry, cls._on_odom, queue_size=1000)
        cls.tf_buffer = tf2_ros.Buffer(cache_time=rospy.Duration(600.0))
        cls.tf_listener = tf2_ros.TransformListener(cls.tf_buffer)
        cls.diagnostics = irm.Diagnostics()
        rospy.wait_for_service("/mapper/save_map", timeout=60)
        rc, log = irm.run(["rosbag", "play", "--clock", "-q", "-d", "2",
                           os.path.join(drive, "drive.bag")], 240)
        assert rc == 0, log
        irm.wait_for(lambda: cls.diagnostics.number("mapper: frames", "frames used") +
                     cls.diagnostics.number("mapper: frames", "frames skipped") >= FRAMES,
                     60, "the mapper to account for all %d frames" % FRAMES)
        time.sleep(1.0)  # the last transforms reach the listener
        with cls.lock:
            cls.messages = list(cls.odometry)
        cls.errors = {"input": [], "corrected_odom": [], "tf": []}
        cls.squared_xy, cls.variance_xy = [], []
        cls.tf_failures = 0
        for msg in cls.messages:
            frame = cls.truth.get(round(msg.header.stamp.to_sec(), 3))
            if frame is None:
                continue
            t_true = frame["T_map_base_true"]["t"]
            p = msg.pose.pose.position
            cls.errors["input"].append(distance(frame["T_map_base_odom"]["t"], t_true))
            cls.errors["corrected_odom"].append(distance((p.x, p.y, p.z), t_true))
            if msg.pose.covariance[0] != cls.messages[0].pose.covariance[0]:  # after a solve
                cls.squared_xy.append((p.x - t_true[0]) ** 2 + (p.y - t_true[1]) ** 2)
                cls.variance_xy.append(msg.pose.covariance[0] + msg.pose.covariance[7])
            try:
                tf = cls.tf_buffer.lookup_transform("map", "base_link", msg.header.stamp)
                t = tf.transform.translation
                cls.errors["tf"].append(distance((t.x, t.y, t.z), t_true))
            except tf2_ros.TransformException:
                cls.tf_failures += 1
        cls.mean = {k: sum(v) / len(v) if v else float("nan") for k, v in cls.errors.items()}
        cls.consistency = (sum(cls.squared_xy) / sum(cls.variance_xy) if cls.variance_xy
                           else float("nan"))
        print("mean translation error (m) over %d frames: %s; tf lookups failed: %d; "
              "squared x/y error over variance: %.3f"
              % (len(cls.errors["input"]), json.dumps({k: round(v, 4) for k, v in cls.mean.items()}),
                 cls.tf_failures, cls.consistency))

    @classmethod
    def _on_odom(cls, msg):
        with cls.lock:
            cls.odometry.append(msg)

    def test_corrected_odom_is_in_the_map_frame_with_a_covariance(self):
        self.assertGreaterEqual(len(self.messages), 0.9 * FRAMES)
        for msg in self.messages:
            self.assertEqual((msg.header.frame_id, msg.child_frame_id), ("map", "base_link"))
            c = msg.pose.covariance
            for i in range(6):
                self.assertGreater(c[7 * i], 0.0)
                for j in range(6):
                    self.assertAlmostEqual(c[6 * i + j], c[6 * j + i], places=9)
        # The covariance follows the solves: the last one is not the odometry's alone.
        self.assertNotEqual(list(self.messages[0].pose.covariance),
                            list(self.messages[-1].pose.covariance))

    def test_corrected_odom_covariance_describes_its_error(self):
        self.assertGreaterEqual(len(self.variance_xy), 0.8 * FRAMES)
        self.assertLessEqual(self.consistency, MAX_COVARIANCE_CONSISTENCY)

    def test_corrected_odom_is_closer_to_the_truth_than_the_input(self):
        self.assertGreaterEqual(len(self.errors["corrected_odom"]), 0.9 * FRAMES)
        self.assertLessEqual(self.mean["corrected_odom"], MAX_ERROR_RATIO * self.mean["input"],
                             self.mean)

    def test_map_to_base_link_on_tf_is_closer_to_the_truth_than_the_input(self):
        self.assertGreaterEqual(len(self.errors["tf"]), 0.9 * len(self.errors["input"]),
                                "tf lookups failed: %d" % self.tf_failures)
        self.assertLessEqual(self.mean["tf"], MAX_ERROR_RATIO * self.mean["input"], self.mean)
        # map -> odom is the nodelet's; odom -> base_link stays the odometry source's.
        self.assertEqual(self.tf_buffer.lookup_transform("map", "odom", rospy.Time(0))
                         .header.frame_id, "map")


if __name__ == "__main__":
    rospy.init_node("test_mapper_poses")
    rostest.rosrun("ipm_road_mapper", "mapper_poses", MapperPosesTest, sys.argv)
