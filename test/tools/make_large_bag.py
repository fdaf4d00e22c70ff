#!/usr/bin/python3
"""Writes a large lz4 bag to measure map_from_bag's start-up (docs/map_from_bag.md).

make_test_bag.py's drive (8 m/s along x, masks rendered from its ground truth) extended to
N frames at 10 Hz: per frame a 16UC1 mask, its camera_info and a mono8 noise image
(incompressible, so the bag is large on disk; 1100 frames ~ 1.0 GB), odometry at 50 Hz and
/tf_static. Messages are recorded 30 ms after their stamps, camera_info before its mask.

usage: make_large_bag.py <out.bag> [--frames N]
then:  map_from_bag --bag <out.bag> --config config/ablations/ipm.yaml --out /tmp/x
       (stderr: "map_from_bag: first frame mapped after X.XXX s"; summary: startup_s)
"""
import argparse
import os
import sys

import numpy as np
import rosbag
import rospy
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, Image
from tf2_msgs.msg import TFMessage

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_test_bag as drive  # noqa: E402

FRAME_PERIOD, ODOM_PERIOD = 0.1, 0.02
MARKED_ROAD_M = 120.0  # beyond it the masks are empty (no marking or lane in the drive)


def tf_static():
    tf = TransformStamped()
    tf.header.stamp = rospy.Time.from_sec(drive.T0)
    tf.header.frame_id, tf.child_frame_id = "base_link", "camera_optical"
    (tf.transform.translation.x, tf.transform.translation.y,
     tf.transform.translation.z) = drive.CAMERA_XYZ
    (tf.transform.rotation.x, tf.transform.rotation.y, tf.transform.rotation.z,
     tf.transform.rotation.w) = drive.quaternion_xyzw(drive.r_base_cam())
    return TFMessage(transforms=[tf])


def odometry(t):
    odom = Odometry()
    odom.header.stamp = rospy.Time.from_sec(drive.T0 + t)
    odom.header.frame_id, odom.child_frame_id = "odom", "base_link"
    odom.pose.pose.position.x = drive.SPEED * t
    odom.pose.pose.orientation.w = 1.0
    return odom


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("out")
    parser.add_argument("--frames", type=int, default=1100)
    args = parser.parse_args()
    x_base, y_base = drive.ground_points_base()
    rng = np.random.default_rng(1)
    noise = [rng.integers(0, 256, drive.WIDTH * drive.HEIGHT, dtype=np.uint8).tobytes()
             for _ in range(8)]
    empty = np.zeros((drive.HEIGHT, drive.WIDTH), np.uint16)
    with rosbag.Bag(args.out, "w", compression="lz4") as bag:
        bag.write("/tf_static", tf_static(), rospy.Time.from_sec(drive.T0))
        next_odom = 0
        for k in range(1, args.frames + 1):
            t = k * FRAME_PERIOD
            while next_odom * ODOM_PERIOD <= t + 0.05:  # odometry brackets every frame
                odom = odometry(next_odom * ODOM_PERIOD)
                bag.write("/odom", odom, odom.header.stamp)
                next_odom += 1
            stamp = rospy.Time.from_sec(drive.T0 + t)
            x = drive.SPEED * t
            mask = drive.render_mask(x_base, y_base, x) if x < MARKED_ROAD_M else empty
            image = Image(height=drive.HEIGHT, width=drive.WIDTH, encoding="16UC1",
                          is_bigendian=0, step=drive.WIDTH * 2, data=mask.astype("<u2").tobytes())
            image.header.stamp, image.header.frame_id = stamp, "camera_optical"
            raw = Image(height=drive.HEIGHT, width=drive.WIDTH, encoding="mono8", is_bigendian=0,
                        step=drive.WIDTH, data=noise[k % len(noise)])
            raw.header = image.header
            info = CameraInfo(height=drive.HEIGHT, width=drive.WIDTH, distortion_model="plumb_bob",
                              D=[0.0] * 5, K=[drive.FX, 0, drive.CX, 0, drive.FY, drive.CY, 0, 0, 1],
                              R=[1, 0, 0, 0, 1, 0, 0, 0, 1],
                              P=[drive.FX, 0, drive.CX, 0, 0, drive.FY, drive.CY, 0, 0, 0, 1, 0])
            info.header = image.header
            recorded = stamp + rospy.Duration(0.03)
            bag.write("/camera/camera_info", info, recorded)
            bag.write("/camera/instances", image, recorded)
            bag.write("/camera/image_raw", raw, recorded)
    print("%s: %d frames, %.2f GB" % (args.out, args.frames, os.path.getsize(args.out) / 1e9))


if __name__ == "__main__":
    main()
