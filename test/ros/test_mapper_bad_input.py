#!/usr/bin/python3
"""rostest (b): bad input is skipped, counted and leaves the map (see mapper_bad_input.test);
and masks that arrive png-compressed (ros/mask_transport: compressed) are mapped as the raw
ones are.

The drive is test/tools/make_test_bag.py's (2.5 s straight at 8 m/s, an arrow at x 18..21
and one at 32..35, a lane line at y 1.675), published live with stamps of a synthetic clock.
"""
import math
import os
import sys
import time
import unittest

import io

import numpy as np
import rospy
import rostest
from nav_msgs.msg import Odometry
from PIL import Image as PilImage
from sensor_msgs.msg import CameraInfo, CompressedImage, Image
from std_srvs.srv import Trigger

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import irm_rostest as irm  # noqa: E402
from irm_rostest import camera_info, drive, mask_image  # noqa: E402
from ipm_road_mapper.msg import VectorMap  # noqa: E402
from ipm_road_mapper.srv import SaveMap  # noqa: E402

FRAMES = "mapper: frames"
T0 = 1700000000.0


class BadInputTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.diagnostics = irm.Diagnostics()
        cls.maps = []
        rospy.Subscriber("/mapper/vector_map", VectorMap, cls.maps.append, queue_size=10)
        cls.odom_pub = rospy.Publisher("/odom", Odometry, queue_size=100)
        cls.info_pub = rospy.Publisher("/camera/camera_info", CameraInfo, queue_size=20)
        cls.mask_pub = rospy.Publisher("/camera/instances", Image, queue_size=20)
        rospy.wait_for_service("/mapper/save_map", timeout=60)
        for pub in (cls.odom_pub, cls.info_pub, cls.mask_pub):
            irm.wait_for(lambda: pub.get_num_connections() > 0, 30, "a subscriber on " + pub.name)
        cls.x_base, cls.y_base = drive.ground_points_base()
        cls.masks = {}
        cls.counts = {}
        cls.good_map = cls.drive_and_map(0.0)
        cls.run_bad_inputs()

    @classmethod
    def render(cls, vehicle_x):
        key = round(vehicle_x, 3)
        if key not in cls.masks:
            cls.masks[key] = drive.render_mask(cls.x_base, cls.y_base, vehicle_x)
        return cls.masks[key]

    @classmethod
    def publish(cls, t0, t1, odometry=True, masks=True, make_mask=None, make_info=None,
                make_odom=None):
        """Odometry at 50 Hz and masks at 10 Hz for stamps T0 + t, t in [t0, t1]; about twice
        real time (stamps are what the mapper uses). Returns the number of masks sent."""
        steps = int(round((t1 - t0) / drive.ODOM_PERIOD))
        masks_sent = 0
        for i in range(steps + 1):
            t = t0 + i * drive.ODOM_PERIOD
            stamp = rospy.Time.from_sec(T0 + t)
            if odometry:
                odom = make_odom(stamp, t) if make_odom else Odometry()
                if not make_odom:
                    odom.header.stamp = stamp
                    odom.header.frame_id = "odom"
                    odom.child_frame_id = "base_link"
                    odom.pose.pose.position.x = drive.SPEED * (t % 100.0)
                    odom.pose.pose.orientation.w = 1.0
                cls.odom_pub.publish(odom)
            if masks and i % 5 == 0 and t > t0:
                info = make_info(stamp) if make_info else camera_info(stamp)
                image = make_mask(stamp, t) if make_mask else \
                    mask_image(stamp, cls.render(drive.SPEED * (t % 100.0)))
                cls.info_pub.publish(info)
                cls.mask_pub.publish(image)
                masks_sent += 1
            time.sleep(0.01)
        return masks_sent

    @classmethod
    def count(cls, key, status=FRAMES):
        return cls.diagnostics.number(status, key)

    @classmethod
    def wait_count(cls, key, at_least, what):
        irm.wait_for(lambda: cls.count(key) >= at_least, 30, "%s (%s >= %d; %s)"
                     % (what, key, at_least, cls.diagnostics.keys(FRAMES)))
        cls.counts[what] = cls.count(key)

    @classmethod
    def drive_and_map(cls, t_start):
        used_before = cls.count("frames used")
        masks = cls.publish(t_start, t_start + 2.6)
        # Every good mask is used (odometry brackets them all).
        cls.wait_count("frames used", used_before + masks, "good drive used")
        used = cls.count("frames used")
        # The published map is the one after the last used frame (published on change).
        def settled():
            time.sleep(0.6)  # a publish period
            return cls.maps and cls.maps[-1].markings and cls.count("frames used") == used
        irm.wait_for(settled, 30, "the map after the good drive")
        time.sleep(1.0)
        return cls.maps[-1]

    @classmethod
    def run_bad_inputs(cls):
        t = 2.6
        # a. A wrong encoding (mono8): the mask callback refuses it.
        cls.publish(t, t + 0.5, make_mask=lambda stamp, _: mask_image(
            stamp, np.zeros((drive.HEIGHT, drive.WIDTH)), encoding="mono8"))
        cls.wait_count("skipped: bad_mask_encoding", 4, "wrong encoding")
        t += 0.5
        # b. A wrong size (640x360 against a 1280x720 camera_info): the core refuses it.
        cls.publish(t, t + 0.5, make_mask=lambda stamp, _: mask_image(
            stamp, np.full((360, 640), 10001)))
        cls.wait_count("skipped: bad_mask", 4, "wrong size")
        t += 0.5
        # c. A NaN in camera_info's K.
        cls.publish(t, t + 0.5, make_info=lambda stamp: camera_info(stamp, fx=math.nan))
        cls.wait_count("skipped: bad_camera_info", 4, "NaN camera_info")
        t += 0.5
        # d. NaN odometry (masks paused).
        def nan_odom(stamp, _):
            odom = Odometry()
            odom.header.stamp = stamp
            odom.header.frame_id = "odom"
            odom.pose.pose.position.x = math.nan
            odom.pose.pose.orientation.w = 1.0
            return odom
        cls.publish(t, t + 0.2, masks=False, make_odom=nan_odom)
        cls.wait_count("odometry bad", 10, "NaN odometry")
        t += 0.2
        # e. Missing odometry: masks go on, odometry does not; decided after
        #    ros/odometry_wait_s (1 s of mask stamps), not after the queue overflows.
        cls.publish(t, t + 1.6, odometry=False)
        cls.wait_count("skipped: after_last_odometry", 4, "missing odometry")
        # f. A time jump backwards: the drive starts again at T0 (a bag loop).
        cls.publish(0.0, 1.0)
        irm.wait_for(lambda: cls.count("time jumps") >= 1, 30, "a time jump")
        cls.wait_count("skipped: time_jump", 5, "time jump")
        cls.counts["used after bad input"] = cls.count("frames used")
        time.sleep(1.5)  # two publish periods: a changed map would be published by now
        cls.map_after = cls.maps[-1]

    def centers(self, vector_map):
        return sorted((m.class_id, sum(c.x for c in m.corners) / 4, sum(c.y for c in m.corners) / 4)
                      for m in vector_map.markings)

    def test_every_bad_input_is_counted(self):
        print("counts: %s" % self.counts)
        for what in ("wrong encoding", "wrong size", "NaN camera_info", "NaN odometry",
                     "missing odometry", "time jump"):
            self.assertIn(what, self.counts)
        self.assertGreaterEqual(self.count("time jumps"), 1)

    def test_map_stays_intact(self):
        before, after = self.centers(self.good_map), self.centers(self.map_after)
        self.assertGreaterEqual(len(before), 1)
        self.assertEqual(len(before), len(after), (before, after))
        for (ca, xa, ya), (cb, xb, yb) in zip(before, after):
            self.assertEqual(ca, cb)
            self.assertLess(math.hypot(xa - xb, ya - yb), 0.3)
        self.assertEqual(len(self.good_map.lanes), len(self.map_after.lanes))
        # The arrow the drive saw best is where the ground truth put it (x 19.5, y 0).
        best = min(before, key=lambda c: abs(c[1] - 19.5) + abs(c[2]))
        self.assertLess(math.hypot(best[1] - 19.5, best[2]), 0.5, before)
        # No bad or jumped frame was used.
        self.assertEqual(self.counts["used after bad input"], self.counts["good drive used"])

    def test_node_keeps_answering_and_resets(self):
        response = rospy.ServiceProxy("/mapper/save_map", SaveMap)(path="/tmp/irm_bad_input_map.json")
        self.assertTrue(response.success, response.message)
        response = rospy.ServiceProxy("/mapper/reset", Trigger)()
        self.assertTrue(response.success, response.message)
        irm.wait_for(lambda: self.maps and not self.maps[-1].markings, 30, "an empty map")
        # A new drive (the player restarted: older stamps than the looped part) maps again.
        remapped = self.drive_and_map(200.0)
        self.assertGreaterEqual(len(remapped.markings), 1)
        self.assertEqual(len(self.centers(remapped)), len(self.centers(self.good_map)))


    def test_png_compressed_masks_are_mapped(self):
        """A second instance reads the same drive's masks as 16-bit png CompressedImages on
        <mask_topic>/compressed (as image_transport's compressed transport sends them) and
        maps the same markings as the raw instance did."""
        params = irm.load_config(**{
            "input/extrinsic": {"xyz": [1.0, 0.0, 1.5], "rpy_deg": [-95.0, 0.0, -90.0]},
            "ros/mask_transport": "compressed", "ros/mask_topic": "/png/instances",
            "ros/camera_info_topic": "/png/camera_info", "ros/odom_topic": "/png/odom",
            "ros/vector_map_full_period_s": 1.0})
        manager = irm.Manager("/manager")
        self.assertTrue(manager.load("/mapper_png", params), "cannot load /mapper_png")
        maps = []
        rospy.Subscriber("/mapper_png/vector_map", VectorMap, maps.append, queue_size=10)
        odom_pub = rospy.Publisher("/png/odom", Odometry, queue_size=100)
        info_pub = rospy.Publisher("/png/camera_info", CameraInfo, queue_size=20)
        mask_pub = rospy.Publisher("/png/instances/compressed", CompressedImage, queue_size=20)
        for pub in (odom_pub, info_pub, mask_pub):
            irm.wait_for(lambda: pub.get_num_connections() > 0, 30, "a subscriber on " + pub.name)
        steps = int(round(2.6 / drive.ODOM_PERIOD))
        sent = 0
        for i in range(steps + 1):
            t = i * drive.ODOM_PERIOD
            stamp = rospy.Time.from_sec(T0 + 500.0 + t)
            odom = Odometry()
            odom.header.stamp = stamp
            odom.header.frame_id = "odom"
            odom.child_frame_id = "base_link"
            odom.pose.pose.position.x = drive.SPEED * t
            odom.pose.pose.orientation.w = 1.0
            odom_pub.publish(odom)
            if i % 5 == 0 and t > 0:
                raw = self.render(drive.SPEED * t).astype(np.uint16)
                png = io.BytesIO()
                PilImage.fromarray(raw).save(png, format="PNG")
                mask = CompressedImage()
                mask.header.stamp = stamp
                mask.header.frame_id = "camera_optical"
                mask.format = "16UC1; png compressed "
                mask.data = png.getvalue()
                info_pub.publish(camera_info(stamp))
                mask_pub.publish(mask)
                sent += 1
            time.sleep(0.01)
        irm.wait_for(lambda: self.diagnostics.number("mapper_png: frames", "frames used") >= sent,
                     30, "every png mask used (%s)" % self.diagnostics.keys("mapper_png: frames"))
        irm.wait_for(lambda: maps and len(maps[-1].markings) >= len(self.good_map.markings), 30,
                     "the png instance's map")
        png_centers, raw_centers = self.centers(maps[-1]), self.centers(self.good_map)
        self.assertEqual(len(png_centers), len(raw_centers), (png_centers, raw_centers))
        for (ca, xa, ya), (cb, xb, yb) in zip(png_centers, raw_centers):
            self.assertEqual(ca, cb)
            self.assertLess(math.hypot(xa - xb, ya - yb), 0.3)
        self.assertEqual(self.diagnostics.number("mapper_png: frames",
                                                 "skipped: bad_mask_encoding"), 0)
        self.assertTrue(manager.unload("/mapper_png"))


if __name__ == "__main__":
    rospy.init_node("test_mapper_bad_input")
    rostest.rosrun("ipm_road_mapper", "mapper_bad_input", BadInputTest)
