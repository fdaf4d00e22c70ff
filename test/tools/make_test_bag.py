#!/usr/bin/python3
"""Writes a small drive for the map_from_bag test (run with /usr/bin/python3).

A car drives straight along x at 8 m/s for 2.5 s. Masks (1280x720, 16UC1, 10 Hz) are
rendered exactly from the ground truth: every pixel's ray is intersected with the road
(z = 0 in base_link) and labelled when the ground point falls in a marking rectangle or the
lane strip. Odometry at 50 Hz (perfect), camera_info with the masks' stamps, and /tf_static
base_link -> camera_optical: the camera 1.5 m high, 1 m ahead, pitched down 5 deg.

usage: make_test_bag.py <out.bag> [--no-tf] [--camera-info-offset <s>] [--loop]
  --no-tf                no /tf_static (the extrinsic must then come from the config)
  --camera-info-offset   camera_info stamps shifted by this (tests approximate sync)
  --loop                 append the drive again with the same stamps (a bag loop)
"""
import argparse
import math

import numpy as np
import rosbag
import rospy
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, Image
from tf2_msgs.msg import TFMessage

WIDTH, HEIGHT = 1280, 720
FX = FY = 1000.0
CX, CY = 640.0, 360.0
CAMERA_XYZ = np.array([1.0, 0.0, 1.5])
PITCH_DOWN = math.radians(5.0)
SPEED = 8.0  # m/s
T0 = 1700000000.0  # a realistic epoch stamp: exact sync must compare ros::Time, not doubles
MASK_PERIOD, N_MASKS, ODOM_PERIOD = 0.1, 25, 0.02
# Ground truth in the map (= odom at t0): (value, x_min, x_max, y_min, y_max).
MARKINGS = [(10001, 18.0, 21.0, -0.6, 0.6), (10002, 32.0, 35.0, -0.6, 0.6)]
LANE = (2001, 0.0, 80.0, 1.60, 1.75)


def r_base_cam():
    """Optical axes (x right, y down, z forward) in base_link, then pitched down."""
    r0 = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    c, s = math.cos(PITCH_DOWN), math.sin(PITCH_DOWN)
    ry = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])  # +pitch about y: nose down
    return ry @ r0


def quaternion_xyzw(r):
    w = math.sqrt(max(0.0, 1.0 + r[0, 0] + r[1, 1] + r[2, 2])) / 2.0
    x = math.copysign(math.sqrt(max(0.0, 1.0 + r[0, 0] - r[1, 1] - r[2, 2])) / 2.0, r[2, 1] - r[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1.0 - r[0, 0] + r[1, 1] - r[2, 2])) / 2.0, r[0, 2] - r[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1.0 - r[0, 0] - r[1, 1] + r[2, 2])) / 2.0, r[1, 0] - r[0, 1])
    return x, y, z, w


def ground_points_base():
    """Ground point (x, y) in base_link of every pixel; NaN above the horizon."""
    u, v = np.meshgrid(np.arange(WIDTH) + 0.0, np.arange(HEIGHT) + 0.0)
    rays_cam = np.stack([(u - CX) / FX, (v - CY) / FY, np.ones_like(u)], axis=-1)
    rays_base = rays_cam @ r_base_cam().T
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(rays_base[..., 2] < -1e-9, -CAMERA_XYZ[2] / rays_base[..., 2], np.nan)
    return CAMERA_XYZ[0] + scale * rays_base[..., 0], CAMERA_XYZ[1] + scale * rays_base[..., 1]


def render_mask(x_base, y_base, vehicle_x):
    mask = np.zeros((HEIGHT, WIDTH), dtype=np.uint16)
    x_map = x_base + vehicle_x
    for value, x0, x1, y0, y1 in [LANE] + MARKINGS:
        with np.errstate(invalid="ignore"):
            inside = (x_map >= x0) & (x_map <= x1) & (y_base >= y0) & (y_base <= y1)
        mask[inside & (x_base - CAMERA_XYZ[0] < 40.0)] = value
    return mask


def write_drive(bag, args, x_base, y_base, record_delay=0.0):
    """The drive; messages are recorded record_delay s after their stamps (a loop: > 0)."""
    delay = rospy.Duration(record_delay)
    n_odom = int(round((N_MASKS + 1) * MASK_PERIOD / ODOM_PERIOD)) + 1
    for i in range(n_odom):
        t = i * ODOM_PERIOD
        odom = Odometry()
        odom.header.stamp = rospy.Time.from_sec(T0 + t)
        odom.header.frame_id = "odom"
        odom.child_frame_id = "base_link"
        odom.pose.pose.position.x = SPEED * t
        odom.pose.pose.orientation.w = 1.0
        bag.write("/odom", odom, odom.header.stamp + delay)
    for k in range(1, N_MASKS + 1):
        t = k * MASK_PERIOD
        stamp = rospy.Time.from_sec(T0 + t)
        data = render_mask(x_base, y_base, SPEED * t)
        image = Image(height=HEIGHT, width=WIDTH, encoding="16UC1", is_bigendian=0,
                      step=WIDTH * 2, data=data.astype("<u2").tobytes())
        image.header.stamp = stamp
        image.header.frame_id = "camera_optical"
        info = CameraInfo(height=HEIGHT, width=WIDTH, distortion_model="plumb_bob",
                          D=[0.0] * 5, K=[FX, 0, CX, 0, FY, CY, 0, 0, 1],
                          R=[1, 0, 0, 0, 1, 0, 0, 0, 1], P=[FX, 0, CX, 0, 0, FY, CY, 0, 0, 0, 1, 0])
        info.header.stamp = rospy.Time.from_sec(T0 + t + args.camera_info_offset)
        info.header.frame_id = "camera_optical"
        # Recorded a little after their stamps, as a segmentation network would publish them.
        bag.write("/camera/camera_info", info, stamp + rospy.Duration(0.03) + delay)
        bag.write("/camera/instances", image, stamp + rospy.Duration(0.03) + delay)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("out")
    parser.add_argument("--no-tf", action="store_true")
    parser.add_argument("--camera-info-offset", type=float, default=0.0)
    parser.add_argument("--loop", action="store_true")
    args = parser.parse_args()
    x_base, y_base = ground_points_base()
    # lz4 chunks keep the bag small (the masks are mostly zeros) and exercise decompression.
    with rosbag.Bag(args.out, "w", compression="lz4") as bag:
        if not args.no_tf:
            tf = TransformStamped()
            tf.header.stamp = rospy.Time.from_sec(T0)
            tf.header.frame_id = "base_link"
            tf.child_frame_id = "camera_optical"
            tf.transform.translation.x, tf.transform.translation.y, tf.transform.translation.z = CAMERA_XYZ
            q = quaternion_xyzw(r_base_cam())
            (tf.transform.rotation.x, tf.transform.rotation.y, tf.transform.rotation.z,
             tf.transform.rotation.w) = q
            bag.write("/tf_static", TFMessage(transforms=[tf]), tf.header.stamp)
        write_drive(bag, args, x_base, y_base)
        if args.loop:
            write_drive(bag, args, x_base, y_base, record_delay=10.0)


if __name__ == "__main__":
    main()
