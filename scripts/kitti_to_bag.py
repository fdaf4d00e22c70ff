#!/usr/bin/env python3
"""Turns a KITTI odometry folder (image_l/ or image_0/ PNGs, calib.txt, poses.txt) into a bag
the package reads: /camera/image_raw + /camera/camera_info, /odom (the GPS/INS poses with
drift added, as the synthetic drives add it) and /tf_static (the rough extrinsic). Writes
OUT/drive.bag, OUT/ground_truth_tum.txt (the GPS/INS poses of base_link at the image stamps)
and OUT/odometry_tum.txt (what the mapper is fed, at the same stamps). docs/segmentation.md.

base_link: on the road under the camera, x along the travel, z up. Its rotation to cam0 comes
from the GPS/INS trajectory itself: the mean travel direction seen from the camera (x) and
the normal of the plane the trajectory lies in (z); the camera is `--camera-height-m` above
the road. The rough extrinsic on /tf_static is that mount made level (the camera's axis
along x, no roll or pitch): what a user knows of a KITTI car without its calibration files.

Odometry drift: per axis x, y (m) and yaw (rad) an Ornstein-Uhlenbeck process of stationary
std --xy-std-m / --yaw-std-deg and correlation time --tau-s, plus white jitter, applied as
src/sim/vehicle.cpp applies it (yaw about the map's z, x and y added). It starts at zero at
the first pose: an odometry starts where the vehicle is, and its error grows from there.

  python3 scripts/kitti_to_bag.py --kitti ../shared/data/kitti_onramp --out /tmp/kitti
"""
import argparse
import os
import sys

import numpy as np
from PIL import Image as PilImage

import rosbag
import rospy
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, Image
from tf2_msgs.msg import TFMessage


def read_matrices(path, width):
    rows = [np.array([float(v) for v in line.split()[-width:]]) for line in open(path)
            if line.strip()]
    return rows


def rot_to_quat(R):
    """(x, y, z, w) of a rotation matrix."""
    w = np.sqrt(max(0.0, 1.0 + R[0, 0] + R[1, 1] + R[2, 2])) / 2.0
    x = np.sqrt(max(0.0, 1.0 + R[0, 0] - R[1, 1] - R[2, 2])) / 2.0
    y = np.sqrt(max(0.0, 1.0 - R[0, 0] + R[1, 1] - R[2, 2])) / 2.0
    z = np.sqrt(max(0.0, 1.0 - R[0, 0] - R[1, 1] + R[2, 2])) / 2.0
    x = np.copysign(x, R[2, 1] - R[1, 2])
    y = np.copysign(y, R[0, 2] - R[2, 0])
    z = np.copysign(z, R[1, 0] - R[0, 1])
    q = np.array([x, y, z, w])
    return q / np.linalg.norm(q)


def quat_to_rot(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def rot_z(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def interpolate(T0, T1, f):
    """SE(3) pose between T0 and T1 (4x4) at fraction f: slerp and linear translation."""
    q0, q1 = rot_to_quat(T0[:3, :3]), rot_to_quat(T1[:3, :3])
    if np.dot(q0, q1) < 0.0:
        q1 = -q1
    angle = np.arccos(min(1.0, abs(np.dot(q0, q1))))
    if angle < 1e-9:
        q = q0
    else:
        q = (np.sin((1 - f) * angle) * q0 + np.sin(f * angle) * q1) / np.sin(angle)
    T = np.eye(4)
    T[:3, :3] = quat_to_rot(q / np.linalg.norm(q))
    T[:3, 3] = (1 - f) * T0[:3, 3] + f * T1[:3, 3]
    return T


def mount_from_trajectory(T_w_cam, height_m):
    """T_base_cam from the trajectory: x = the mean travel direction in the camera frame,
    z = the normal of the trajectory's plane (pointing up, optical -y), base_link under the
    camera on the road."""
    p = np.array([T[:3, 3] for T in T_w_cam])
    travel = []
    for k in range(1, len(p) - 1):
        d = T_w_cam[k][:3, :3].T @ (p[k + 1] - p[k - 1])
        travel.append(d / np.linalg.norm(d))
    forward = np.mean(travel, axis=0)
    forward /= np.linalg.norm(forward)
    centered = p - p.mean(axis=0)
    normal_w = np.linalg.svd(centered)[2][2]
    up = np.mean([T[:3, :3].T @ normal_w for T in T_w_cam], axis=0)
    if up[1] > 0.0:  # optical y points down
        up = -up
    up -= up.dot(forward) * forward
    up /= np.linalg.norm(up)
    left = np.cross(up, forward)
    R_cam_base = np.column_stack([forward, left, up])
    T = np.eye(4)
    T[:3, :3] = R_cam_base.T
    T[:3, 3] = [0.0, 0.0, height_m]
    return T


def level_mount(height_m):
    """The rough extrinsic: optical axis along base x, no roll or pitch."""
    T = np.eye(4)
    T[:3, :3] = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    T[:3, 3] = [0.0, 0.0, height_m]
    return T


class Drift:
    """The synthetic drives' odometry error (src/sim/vehicle.cpp), started at zero."""

    def __init__(self, xy_std, yaw_std, tau, jitter_xy, jitter_yaw, seed):
        self.sigma = np.array([xy_std, xy_std, yaw_std])
        self.tau = tau
        self.jitter = np.array([jitter_xy, jitter_xy, jitter_yaw])
        self.state = np.zeros(3)
        self.rng = np.random.default_rng(seed)

    def next(self, dt):
        a = np.exp(-dt / self.tau)
        self.state = a * self.state + self.sigma * np.sqrt(1 - a * a) * self.rng.normal(size=3)
        return self.state + self.jitter * self.rng.normal(size=3)


def apply_drift(T, e):
    out = T.copy()
    out[:3, :3] = rot_z(e[2]) @ T[:3, :3]
    out[0, 3] += e[0]
    out[1, 3] += e[1]
    return out


def stamp(t):
    return rospy.Time.from_sec(t)


def pose_msg(pose, T):
    q = rot_to_quat(T[:3, :3])
    pose.position.x, pose.position.y, pose.position.z = T[:3, 3]
    pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = q


def tum_line(t, T):
    q = rot_to_quat(T[:3, :3])
    return "%.6f %.6f %.6f %.6f %.9f %.9f %.9f %.9f\n" % ((t,) + tuple(T[:3, 3]) + tuple(q))


def camera_info(P, width, height, t, frame_id):
    msg = CameraInfo()
    msg.header.stamp, msg.header.frame_id = stamp(t), frame_id
    msg.width, msg.height = width, height
    msg.distortion_model = "plumb_bob"
    msg.D = [0.0] * 5
    msg.K = [P[0], P[1], P[2], P[4], P[5], P[6], P[8], P[9], P[10]]
    msg.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    msg.P = list(P)
    return msg


def image_msg(path, t, frame_id):
    pixels = np.asarray(PilImage.open(path).convert("L"))
    msg = Image()
    msg.header.stamp, msg.header.frame_id = stamp(t), frame_id
    msg.height, msg.width = pixels.shape
    msg.encoding, msg.is_bigendian, msg.step = "mono8", 0, pixels.shape[1]
    msg.data = pixels.tobytes()
    return msg, pixels.shape


def odometry_samples(T_base, stamps, args):
    """(t, T_odom_base, T_true) at args.odom_rate_hz from 0.1 s before the first image to
    0.1 s after the last, the truth interpolated between the images."""
    drift = Drift(args.xy_std_m, np.radians(args.yaw_std_deg), args.tau_s, 0.005,
                  np.radians(0.01), args.seed)
    dt = 1.0 / args.odom_rate_hz
    samples = []
    t = stamps[0] - 0.1
    first = True
    while t <= stamps[-1] + 0.1 + 1e-9:
        k = int(np.clip(np.searchsorted(stamps, t) - 1, 0, len(stamps) - 2))
        f = (t - stamps[k]) / (stamps[k + 1] - stamps[k])
        T_true = interpolate(T_base[k], T_base[k + 1], f)  # extrapolates linearly past the ends
        e = np.zeros(3) if first else drift.next(dt)
        first = False
        samples.append((t, apply_drift(T_true, e), T_true))
        t += dt
    return samples


def odometry_at(samples, t):
    """The odometry pose interpolated at stamp t (samples: (t, T_odom_base, T_true))."""
    times = [sample[0] for sample in samples]
    j = int(np.clip(np.searchsorted(times, t) - 1, 0, len(samples) - 2))
    f = (t - times[j]) / (times[j + 1] - times[j])
    return interpolate(samples[j][1], samples[j + 1][1], f)


def odometry_msg(samples, j, frame, child):
    a, b = max(0, j - 1), min(len(samples) - 1, j + 1)
    t, T, _ = samples[j]
    msg = Odometry()
    msg.header.stamp, msg.header.frame_id, msg.child_frame_id = stamp(t), frame, child
    pose_msg(msg.pose.pose, T)
    span = samples[b][0] - samples[a][0]
    v = T[:3, :3].T @ (samples[b][1][:3, 3] - samples[a][1][:3, 3]) / span
    msg.twist.twist.linear.x, msg.twist.twist.linear.y, msg.twist.twist.linear.z = v
    return msg


def static_tf(T, parent, child, t):
    msg = TransformStamped()
    msg.header.stamp, msg.header.frame_id, msg.child_frame_id = stamp(t), parent, child
    q = rot_to_quat(T[:3, :3])
    msg.transform.translation.x, msg.transform.translation.y, msg.transform.translation.z = T[:3, 3]
    r = msg.transform.rotation
    r.x, r.y, r.z, r.w = q
    return TFMessage([msg])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--kitti", required=True, help="folder with image_l/ (or image_0/), calib.txt, poses.txt")
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--seed", type=int, default=1, help="drift seed (default 1)")
    parser.add_argument("--xy-std-m", type=float, default=0.3)
    parser.add_argument("--yaw-std-deg", type=float, default=0.3)
    parser.add_argument("--tau-s", type=float, default=4.0, help="drift correlation time")
    parser.add_argument("--odom-rate-hz", type=float, default=50.0)
    parser.add_argument("--frame-period-s", type=float, default=0.1036,
                        help="image spacing (KITTI's cameras: about 10 Hz)")
    parser.add_argument("--camera-height-m", type=float, default=1.65)
    parser.add_argument("--first", type=int, default=0, help="first frame index")
    parser.add_argument("--count", type=int, default=0, help="frames (0: all)")
    args = parser.parse_args()

    images_dir = next((os.path.join(args.kitti, d) for d in ("image_l", "image_0")
                       if os.path.isdir(os.path.join(args.kitti, d))), None)
    if images_dir is None:
        sys.exit("kitti_to_bag: no image_l/ or image_0/ in %s" % args.kitti)
    P0 = read_matrices(os.path.join(args.kitti, "calib.txt"), 12)[0]
    poses = read_matrices(os.path.join(args.kitti, "poses.txt"), 12)
    images = sorted(f for f in os.listdir(images_dir) if f.endswith(".png"))
    n = min(len(images), len(poses))
    last = n if args.count <= 0 else min(n, args.first + args.count)
    images, poses = images[args.first:last], poses[args.first:last]
    if len(images) < 3:
        sys.exit("kitti_to_bag: fewer than 3 frames with both an image and a pose")
    T_w_cam = []
    for row in poses:
        T = np.eye(4)
        T[:3, :4] = row.reshape(3, 4)
        T_w_cam.append(T)
    T_base_cam = mount_from_trajectory(T_w_cam, args.camera_height_m)
    T_cam_base = np.linalg.inv(T_base_cam)
    T_w_base = [T @ T_cam_base for T in T_w_cam]
    T_base0_w = np.linalg.inv(T_w_base[0])
    T_base = [T_base0_w @ T for T in T_w_base]
    stamps = 1000.0 + args.frame_period_s * np.arange(len(images))

    os.makedirs(args.out, exist_ok=True)
    samples = odometry_samples(T_base, stamps, args)
    with open(os.path.join(args.out, "ground_truth_tum.txt"), "w") as truth, \
         open(os.path.join(args.out, "odometry_tum.txt"), "w") as odom:
        for t, T in zip(stamps, T_base):
            truth.write(tum_line(t, T))
            odom.write(tum_line(t, odometry_at(samples, t)))
    with open(os.path.join(args.out, "mount_from_trajectory.txt"), "w") as f:
        f.write("# T_base_cam (4x4) derived from the GPS/INS trajectory (kitti_to_bag.py)\n")
        np.savetxt(f, T_base_cam)

    bag = rosbag.Bag(os.path.join(args.out, "drive.bag"), "w")
    try:
        bag.write("/tf_static", static_tf(level_mount(args.camera_height_m), "base_link",
                                          "camera_optical", samples[0][0]), stamp(samples[0][0]))
        events = [(t, 0, j) for j, (t, _, _) in enumerate(samples)]
        events += [(t, 1, k) for k, t in enumerate(stamps)]
        for t, kind, index in sorted(events):
            if kind == 0:
                bag.write("/odom", odometry_msg(samples, index, "odom", "base_link"), stamp(t))
                continue
            image, shape = image_msg(os.path.join(images_dir, images[index]), t, "camera_optical")
            bag.write("/camera/camera_info", camera_info(P0, shape[1], shape[0], t, "camera_optical"),
                      stamp(t))
            bag.write("/camera/image_raw", image, stamp(t))
    finally:
        bag.close()
    print("kitti_to_bag: %d frames, %d odometry messages -> %s" %
          (len(images), len(samples), os.path.join(args.out, "drive.bag")))


if __name__ == "__main__":
    main()
