#!/usr/bin/python3
"""rostest (c): unload and reload of the nodelet in a running manager (mapper_reload.test)."""
import json
import os
import sys
import threading
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, Image

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import irm_rostest as irm  # noqa: E402
from irm_rostest import camera_info, drive, mask_image  # noqa: E402

CYCLES = 5
UNLOAD_LIMIT_S = 20.0  # a hang shows as a time-out far beyond this
SHUTDOWN_BUDGET_S = 2.0  # ros/shutdown_budget_s of the instance that saves on unload


class Feeder(threading.Thread):
    """Publishes the make_test_bag drive over and over (stamps always increasing)."""

    def __init__(self):
        super().__init__(daemon=True)
        self.stop = threading.Event()
        x_base, y_base = drive.ground_points_base()
        self.masks = [drive.render_mask(x_base, y_base, drive.SPEED * 0.1 * k) for k in range(25)]
        self.odom_pub = rospy.Publisher("/odom", Odometry, queue_size=100)
        self.info_pub = rospy.Publisher("/camera/camera_info", CameraInfo, queue_size=20)
        self.mask_pub = rospy.Publisher("/camera/instances", Image, queue_size=20)

    def run(self):
        t0, i = 1700000000.0, 0
        while not self.stop.is_set() and not rospy.is_shutdown():
            t = i * drive.ODOM_PERIOD
            lap = t % 2.5  # the car drives the same 20 m again and again
            stamp = rospy.Time.from_sec(t0 + t)
            odom = Odometry()
            odom.header.stamp = stamp
            odom.header.frame_id = "odom"
            odom.child_frame_id = "base_link"
            odom.pose.pose.position.x = drive.SPEED * lap
            odom.pose.pose.orientation.w = 1.0
            self.odom_pub.publish(odom)
            if i % 5 == 0:
                self.info_pub.publish(camera_info(stamp))
                self.mask_pub.publish(mask_image(stamp, self.masks[int(round(lap / 0.1)) % 25]))
            i += 1
            time.sleep(0.01)


class ReloadTest(unittest.TestCase):
    def test_unload_and_reload_while_data_flows(self):
        manager = irm.Manager("/manager")
        diagnostics = irm.Diagnostics()
        feeder = Feeder()
        feeder.start()
        save_path = "/tmp/irm_reload_test/map.json"
        if os.path.exists(save_path):
            os.remove(save_path)
        unload_times = []
        save_s = float("nan")
        try:
            for cycle in range(CYCLES):
                name = "/mapper_r%d" % cycle
                last = cycle == CYCLES - 1
                params = irm.load_config(**{
                    "input/extrinsic": {"xyz": [1.0, 0.0, 1.5], "rpy_deg": [-95.0, 0.0, -90.0]},
                    "ros/save_map_path": save_path if last else "",
                    "ros/shutdown_budget_s": SHUTDOWN_BUDGET_S})
                self.assertTrue(manager.load(name, params), "load %s" % name)
                self.assertIn(name, manager.loaded())
                status = name.lstrip("/") + ": "
                # Mapping, and the optimizer thread has windows to solve.
                irm.wait_for(lambda: diagnostics.number(status + "frames", "frames used") >= 15 and
                             diagnostics.number(status + "optimizer", "windows submitted") >= 2,
                             60, "%s to map and submit windows" % name)
                start = time.monotonic()
                self.assertTrue(manager.unload(name), "unload %s" % name)
                unload_times.append(time.monotonic() - start)
                self.assertLess(unload_times[-1], UNLOAD_LIMIT_S)
                self.assertNotIn(name, manager.loaded())
                # Its services went with it.
                irm.wait_for(lambda: name + "/save_map" not in irm.advertised_services(), 10,
                             "%s/save_map to be unadvertised" % name)
            # The last instance saved its map on the way out, within its shutdown budget
            # (+ 1 s) from the unload request, data still flowing. nodelet may destroy an
            # unloaded instance only at the end of a callback in flight, after unload
            # returned: wait for the file, and time it from the unload request.
            irm.wait_for(lambda: os.path.isfile(save_path), 60, "the map saved at shutdown")
            save_s = time.monotonic() - start
            self.assertLess(save_s, SHUTDOWN_BUDGET_S + 1.0)
            self.assertLess(unload_times[-1], SHUTDOWN_BUDGET_S + 1.0)
            with open(save_path) as f:
                saved = json.load(f)  # valid JSON (written atomically)
            self.assertGreater(len(saved["trajectory"]), 0)
            self.assertGreater(len(saved["lanes"]) + len(saved["markings"]), 0)
            # The manager is alive and takes the nodelet once more.
            self.assertTrue(manager.load("/mapper_again", params))
            rospy.wait_for_service("/mapper_again/save_map", timeout=30)
            self.assertTrue(manager.unload("/mapper_again"))
        finally:
            feeder.stop.set()
            feeder.join(5)
        print("unload times (s): %s; the saving unload wrote its map after %.2f s" %
              (", ".join("%.2f" % t for t in unload_times), save_s))


if __name__ == "__main__":
    rospy.init_node("test_mapper_reload")
    rostest.rosrun("ipm_road_mapper", "mapper_reload", ReloadTest)
