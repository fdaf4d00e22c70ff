"""Benchmark table K: real camera images (../shared/data/kitti_onramp), segmented with
segment_bag (../shared/models/road-segmentation-adas-0001) and mapped with the default
config, scored without marking ground truth (kitti_reprojection.py):
- counts: elements mapped, chevron stripes mapped as lanes, duplicate lines, hatched areas
  found, instances dropped by reason (segmentation and mapper);
- leave-out reprojection: the map of the even frames projected into the odd ones and the map
  of the odd frames into the even ones, against their segmented paint (within 30 m);
- poses: the corrected trajectory and the odometry (GPS/INS + 0.3 m / 0.3 deg drift,
  kitti_to_bag.py) against the GPS/INS poses;
- extrinsic: the refined value with its reported sigma, and the two halves of the clip
  mapped apart;
- rate: segmentation (network + instances) on one core, and the mapping.
Skipped with one line when the clip, the model or segment_bag (OpenVINO) is absent.
The table itself is tables/kitti.py; `bash scripts/benchmark.sh --kitti` prints it alone.
"""
import json
import math
import os
import re
import subprocess
import sys

import numpy as np

from . import kitti_reprojection as kr

RANGE_M = 30.0
TOLERANCE_PX = 3.0
LANE_IDS, MARKING_IDS = (1, 2, 3, 4), (10, 11, 12, 13, 14, 20, 21, 22, 23)
HATCH_ID = 30


def run(cmd, log):
    with open(log, "w") as f:
        result = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT)
    if result.returncode != 0:
        sys.exit("benchmark: failed (%d): %s\n  log: %s" % (result.returncode, " ".join(cmd), log))
    return open(log).read()


def inputs(args):
    """(clip, model, segment_bag) or a reason the table is skipped."""
    clip = os.path.join(args.shared, "data", "kitti_onramp")
    model = os.path.join(args.shared, "models", "road-segmentation-adas-0001")
    tool = os.path.join(args.bin, "segment_bag")
    for path, what in ((clip, "the clip"), (model, "the model")):
        if not os.path.isdir(path):
            return "%s is not present (%s)" % (what, path)
    if not os.path.exists(tool):
        return "segment_bag is not built (OpenVINO absent: scripts/setup_openvino.sh)"
    return clip, model, tool


def read_bag_frames(bag_path, mask_topic="/camera/instances"):
    """stamp -> 16UC1 mask (numpy) of a segmented bag, and the camera's K."""
    import rosbag
    masks, K = {}, None
    with rosbag.Bag(bag_path) as bag:
        for topic, msg, _ in bag.read_messages(topics=[mask_topic, "/camera/camera_info"]):
            if topic == mask_topic:
                data = np.frombuffer(msg.data, dtype=">u2" if msg.is_bigendian else "<u2")
                masks[round(msg.header.stamp.to_sec(), 6)] = data.reshape(msg.height, msg.width)
            elif K is None:
                K = np.array(msg.K).reshape(3, 3)
    return masks, K


def split_bag(source, target, keep_stamp):
    """Copies `source` without the camera messages whose stamp keep_stamp refuses."""
    import rosbag
    camera = ("/camera/image_raw", "/camera/camera_info", "/camera/instances",
              "/camera/instances/instances")
    with rosbag.Bag(source) as bag, rosbag.Bag(target, "w") as out:
        for topic, msg, t in bag.read_messages():
            if topic in camera and not keep_stamp(round(msg.header.stamp.to_sec(), 6)):
                continue
            out.write(topic, msg, t)


def map_bag(args, bag, out):
    os.makedirs(out, exist_ok=True)
    run([os.path.join(args.bin, "map_from_bag"), "--bag", bag, "--out", out],
        os.path.join(out, "map.log"))
    return json.load(open(os.path.join(out, "map.json")))


def extrinsic(vmap):
    T = kr.pose(vmap["T_base_cam"]["t"], vmap["T_base_cam"]["q_xyzw"])
    cov = np.array(vmap["T_base_cam_calibration"]["covariance"]).reshape(6, 6)
    sigma_deg = math.degrees(math.sqrt(max(0.0, np.trace(cov[:3, :3]))))
    return T, sigma_deg


def leave_out(args, work, seg_bag, masks, K):
    """Both directions (even -> odd frames, odd -> even), pooled."""
    stamps = sorted(masks)
    frames = []
    for parity in (0, 1):
        built = set(stamps[parity::2])
        out = os.path.join(work, "map_%s" % ("even", "odd")[parity])
        bag = os.path.join(work, "frames_%s.bag" % ("even", "odd")[parity])
        split_bag(seg_bag, bag, lambda s: s in built)
        vmap = map_bag(args, bag, out)
        T_base_cam, _ = extrinsic(vmap)
        trajectory = kr.read_tum(os.path.join(out, "map_trajectory_tum.txt"))
        lines = kr.map_points(vmap)
        for stamp in stamps:
            T_map_base = kr.interpolate_pose(trajectory, stamp)
            if stamp in built or T_map_base is None:
                continue
            mask = masks[stamp]
            drawn = kr.draw_map(lines, T_map_base, T_base_cam, K, (mask.shape[1], mask.shape[0]),
                                RANGE_M)
            area, center = kr.paint_pixels(mask, LANE_IDS, MARKING_IDS, K, T_base_cam, RANGE_M)
            frames.append((drawn, area, center))
    return kr.score_frames(frames, TOLERANCE_PX)


def hatched_ground(masks, K, T_base_cam, trajectory):
    """The map-frame ground points (N x 2) of every hatched-area pixel of the drive (every
    4th pixel, within RANGE_M), on the corrected poses."""
    points = []
    for stamp, mask in masks.items():
        T_map_base = kr.interpolate_pose(trajectory, stamp)
        v, u = np.nonzero(mask // 1000 == HATCH_ID)
        if T_map_base is None or len(u) == 0:
            continue
        uv = np.column_stack([u[::4], v[::4]]).astype(float)
        rays = T_base_cam[:3, :3] @ np.linalg.solve(K, np.vstack([uv.T, np.ones(len(uv))]))
        t = T_base_cam[:3, 3]
        down = rays[2] < -1e-9
        lam = -t[2] / rays[2, down]
        ground = t[:, None] + lam * rays[:, down]
        near = np.hypot(ground[0], ground[1]) <= RANGE_M
        p_map = T_map_base[:3, :3] @ ground[:, near] + T_map_base[:3, 3:4]
        points.append(p_map[:2].T)
    return np.vstack(points) if points else np.zeros((0, 2))


def lanes_in_hatch(vmap, hatch_points, cell_m=0.5):
    """Lanes lying mostly (>= half their samples) on hatched paint: chevron stripes mapped
    as lanes."""
    cells = {tuple(c) for c in np.floor(hatch_points / cell_m).astype(int)}
    count = 0
    for lane in vmap["lanes"]:
        samples = kr.catmull_rom(lane["control_points"], 0.25)[:, :2]
        inside = [tuple(c) in cells for c in np.floor(samples / cell_m).astype(int)]
        count += bool(len(inside)) and np.mean(inside) >= 0.5
    return count


def duplicate_lines(vmap, gap_m=0.5, min_length_m=3.0):
    """Pairs of lanes running within gap_m of each other for min_length_m or more: two splines
    on one painted line."""
    samples = [kr.catmull_rom(lane["control_points"], 0.25)[:, :2] for lane in vmap["lanes"]]
    pairs = 0
    for a in range(len(samples)):
        for b in range(a + 1, len(samples)):
            if len(samples[a]) == 0 or len(samples[b]) == 0:
                continue
            d = np.min(np.linalg.norm(samples[a][:, None] - samples[b][None], axis=2), axis=1)
            pairs += np.sum(d <= gap_m) * 0.25 >= min_length_m
    return int(pairs)


def halves(args, work, seg_bag, masks):
    """The refined rotation of each half of the clip mapped apart: their angle (deg) and the
    3-sigma bound of that difference (the halves' reported sigmas)."""
    stamps = sorted(masks)
    middle = stamps[len(stamps) // 2]
    results = []
    for name, keep in (("first", lambda s: s <= middle), ("second", lambda s: s >= middle)):
        bag = os.path.join(work, "half_%s.bag" % name)
        split_bag(seg_bag, bag, keep)
        results.append(extrinsic(map_bag(args, bag, os.path.join(work, "map_half_" + name))))
    (Ta, sa), (Tb, sb) = results
    return kr.rotation_deg(Ta[:3, :3].T @ Tb[:3, :3]), 3.0 * math.hypot(sa, sb), sa, sb


def segment_line(log, key):
    match = re.search(r"^%s: (.*)$" % key, log, re.M)
    return match.group(1) if match else "-"


def measure(args, out_root):
    """Every figure of the table (a dict), or a string saying why it is skipped."""
    found = inputs(args)
    if isinstance(found, str):
        return found
    clip, model, tool = found
    work = os.path.join(out_root, "kitti")
    drive = os.path.join(work, "drive")
    os.makedirs(drive, exist_ok=True)
    run([sys.executable, os.path.join(args.repo, "scripts", "kitti_to_bag.py"), "--kitti", clip,
         "--out", drive], os.path.join(work, "kitti_to_bag.log"))
    seg_bag = os.path.join(work, "segmented.bag")
    seg_log = run([tool, "--bag", os.path.join(drive, "drive.bag"), "--out", seg_bag, "--model",
                   model], os.path.join(work, "segment_bag.log"))
    masks, K = read_bag_frames(seg_bag)
    vmap = map_bag(args, seg_bag, os.path.join(work, "map"))
    summary = open(os.path.join(work, "map", "summary.txt")).read()
    T_base_cam, sigma_deg = extrinsic(vmap)
    trajectory = kr.read_tum(os.path.join(work, "map", "map_trajectory_tum.txt"))
    truth = kr.read_tum(os.path.join(drive, "ground_truth_tum.txt"))
    hatch = hatched_ground(masks, K, T_base_cam, trajectory)
    rpy = np.degrees(np.array(vmap["T_base_cam_calibration"]["covariance"]).reshape(6, 6)
                     .diagonal()[:3] ** 0.5)
    initial = kr.pose(vmap["T_base_cam_initial"]["t"], vmap["T_base_cam_initial"]["q_xyzw"])
    return {
        "lanes": len(vmap["lanes"]), "markings": len(vmap["markings"]),
        "chevron_lanes": lanes_in_hatch(vmap, hatch), "duplicates": duplicate_lines(vmap),
        "hatched_areas": kr.hatched_areas(hatch),
        "seg_instances": segment_line(seg_log, "instances"),
        "seg_dropped": segment_line(seg_log, "dropped"), "rate": segment_line(seg_log, "rate on one core"),
        "sanity": segment_line(summary, "sanity"), "extraction": segment_line(summary, "extraction"),
        "front_end": segment_line(summary, "front end"),
        "leave_out": leave_out(args, work, seg_bag, masks, K),
        "poses": kr.pose_errors(trajectory, truth),
        "odometry": kr.pose_errors(kr.read_tum(os.path.join(drive, "odometry_tum.txt")), truth),
        "poses_from_start": kr.pose_errors(trajectory, truth, align_first=True),
        "odometry_from_start": kr.pose_errors(
            kr.read_tum(os.path.join(drive, "odometry_tum.txt")), truth, align_first=True),
        "extrinsic_moved_deg": kr.rotation_deg(initial[:3, :3].T @ T_base_cam[:3, :3]),
        "height_m": T_base_cam[2, 3], "sigma_deg": sigma_deg, "sigma_rpy_deg": rpy,
        "halves": halves(args, work, seg_bag, masks),
    }


def f(value, digits=3):
    return "-" if value is None or (isinstance(value, float) and math.isnan(value)) else \
        ("%." + str(digits) + "f") % value
