"""Scores of a map of a real clip without marking ground truth (irm_bench/kitti.py):
the map projected into frames it was not built from, against their segmented paint; poses
against the GPS/INS truth; the hatched areas the segmentation found. numpy, scipy and PIL
only, no ROS.

Leave-out reprojection, per held-out frame (its pose: the map's corrected trajectory
interpolated at its stamp; the camera: the map's refined extrinsic):
- map: lane splines sampled every 2 cm and marking outlines, projected and drawn 1 px wide,
  the points within range_m (ground distance from base_link) only;
- paint: the frame's mask pixels of the classes the map holds (lanes and markings of the
  class table; hatched areas are not mapped, so not scored), within range_m on the ground;
  lanes are scored at their centerline (the middle of each row's run), as the map holds a
  line, not its width; markings at their outline;
- map -> paint: each map pixel's distance to the nearest paint pixel (any of its width);
  paint -> map: each paint centerline pixel's distance to the nearest map pixel. Medians,
  and the fractions within tolerance_px (precision: map pixels; recall: paint pixels).
"""
import math

import numpy as np
from PIL import Image, ImageDraw
from scipy import ndimage

from plot_map_errors import catmull_rom


def quat_to_rot(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def pose(t, q_xyzw):
    T = np.eye(4)
    T[:3, :3] = quat_to_rot(np.asarray(q_xyzw, dtype=float))
    T[:3, 3] = t
    return T


def read_tum(path):
    """stamp -> 4x4 pose."""
    poses = {}
    for line in open(path):
        v = line.split()
        if len(v) == 8 and not line.startswith("#"):
            poses[float(v[0])] = pose([float(x) for x in v[1:4]], [float(x) for x in v[4:8]])
    return poses


def interpolate_pose(poses, t):
    """The pose at stamp t from a stamp -> pose dict (linear translation, nearest-chord
    rotation blend re-orthonormalized; the frames are 0.1 s apart), None outside."""
    stamps = sorted(poses)
    k = np.searchsorted(stamps, t)
    if k < len(stamps) and abs(stamps[k] - t) < 1e-6:
        return poses[stamps[k]]
    if k == 0 or k == len(stamps):
        return None
    a, b = stamps[k - 1], stamps[k]
    f = (t - a) / (b - a)
    T = (1 - f) * poses[a] + f * poses[b]
    u, _, vt = np.linalg.svd(T[:3, :3])
    T[:3, :3] = u @ vt
    T[3] = [0, 0, 0, 1]
    return T


def rotation_deg(R):
    return math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(R) - 1) / 2))))


def pose_errors(estimate, truth, align_first=False):
    """Mean translation (m) and rotation (deg) error of `estimate` (stamp -> pose) against
    `truth` at the truth's stamps both hold; with align_first, `estimate` moved rigidly so
    that its first pose is the truth's (the error relative to the start of the clip)."""
    trans, rot = [], []
    align = np.eye(4)
    if align_first:
        t0 = min(truth)
        T0 = estimate.get(t0) if t0 in estimate else interpolate_pose(estimate, t0)
        if T0 is not None:
            align = truth[t0] @ np.linalg.inv(T0)
    for t, T_true in truth.items():
        T = estimate.get(t) if t in estimate else interpolate_pose(estimate, t)
        if T is None:
            continue
        T = align @ T
        trans.append(np.linalg.norm(T[:3, 3] - T_true[:3, 3]))
        rot.append(rotation_deg(T[:3, :3].T @ T_true[:3, :3]))
    return (float(np.mean(trans)), float(np.mean(rot))) if trans else (float("nan"),) * 2


def map_points(vmap):
    """Polylines (N x 3, map frame) of the map: lanes sampled every 2 cm, marking outlines."""
    lines = [catmull_rom(lane["control_points"], 0.02) for lane in vmap.get("lanes", [])]
    for marking in vmap.get("markings", []):
        corners = np.asarray(marking["corners"], dtype=float)
        lines.append(np.vstack([corners, corners[:1]]))
    return [line for line in lines if len(line) >= 2]


def ground_range(uv, K, T_base_cam):
    """Ground distance from base_link of pixels uv (N x 2) on base_link's plane z = 0
    (inf above the horizon)."""
    rays = np.linalg.solve(K, np.vstack([uv.T, np.ones(len(uv))]))
    d = T_base_cam[:3, :3] @ rays
    t = T_base_cam[:3, 3]
    out = np.full(len(uv), np.inf)
    down = d[2] < -1e-9
    lam = -t[2] / d[2, down]
    out[down] = np.hypot(t[0] + lam * d[0, down], t[1] + lam * d[1, down])
    return out


def draw_map(lines, T_map_base, T_base_cam, K, size, range_m):
    """The map's pixels in one frame (bool image): each polyline's points within range_m of
    base_link, in front of the camera, projected and drawn 1 px wide."""
    width, height = size
    canvas = Image.new("L", size, 0)
    draw = ImageDraw.Draw(canvas)
    T_base_map = np.linalg.inv(T_map_base)
    T_cam_base = np.linalg.inv(T_base_cam)
    for line in lines:
        p_base = (T_base_map[:3, :3] @ line.T).T + T_base_map[:3, 3]
        keep = np.hypot(p_base[:, 0], p_base[:, 1]) <= range_m
        p_cam = (T_cam_base[:3, :3] @ p_base.T).T + T_cam_base[:3, 3]
        keep &= p_cam[:, 2] > 0.5
        uv = (K @ p_cam.T).T
        uv = uv[:, :2] / np.maximum(uv[:, 2:3], 1e-9)
        # Runs of consecutive kept points, drawn as polylines.
        start = None
        for i in range(len(uv) + 1):
            if i < len(uv) and keep[i]:
                start = i if start is None else start
                continue
            if start is not None and i - start >= 2:
                draw.line([tuple(p) for p in uv[start:i]], fill=255, width=1)
            elif start is not None:
                draw.point(tuple(uv[start]), fill=255)
            start = None
    return np.asarray(canvas) > 0


def paint_pixels(mask, lane_ids, marking_ids, K, T_base_cam, range_m):
    """(paint area, paint centerline) bool images of a 16UC1 mask: lane and marking instances
    within range_m on the ground; lanes by their rows' run centers, markings by outline."""
    classes = mask // 1000
    area = np.isin(classes, list(lane_ids) + list(marking_ids)) & (mask >= 1000)
    v, u = np.nonzero(area)
    if len(u):
        far = ground_range(np.column_stack([u, v]).astype(float), K, T_base_cam) > range_m
        area[v[far], u[far]] = False
    center = np.zeros_like(area)
    lanes = area & np.isin(classes, list(lane_ids))
    for row in np.nonzero(lanes.any(axis=1))[0]:
        values = np.where(lanes[row], mask[row], 0)
        edges = np.flatnonzero(np.diff(np.concatenate([[0], values, [0]])) != 0)
        for a, b in zip(edges[::2], edges[1::2]):
            center[row, (a + b - 1) // 2] = True
    markings = area & np.isin(classes, list(marking_ids))
    center |= markings & ~ndimage.binary_erosion(markings)
    return area, center


def score_frames(frames, tolerance_px):
    """Leave-out scores over frames: a list of (map bool image, paint area, paint center)."""
    to_paint, to_map = [], []
    for drawn, area, center in frames:
        if area.any() and drawn.any():
            to_paint.append(ndimage.distance_transform_edt(~area)[drawn])
            to_map.append(ndimage.distance_transform_edt(~drawn)[center])
        elif center.any():  # paint and no map in view: every paint pixel missed
            to_map.append(np.full(int(center.sum()), np.inf))
    d_paint = np.concatenate(to_paint) if to_paint else np.zeros(0)
    d_map = np.concatenate(to_map) if to_map else np.zeros(0)
    nan = float("nan")
    return {
        "map_to_paint_median_px": float(np.median(d_paint)) if len(d_paint) else nan,
        "paint_to_map_median_px": float(np.median(d_map)) if len(d_map) else nan,
        "precision": float(np.mean(d_paint <= tolerance_px)) if len(d_paint) else nan,
        "recall": float(np.mean(d_map <= tolerance_px)) if len(d_map) else nan,
        "map_pixels": int(len(d_paint)), "paint_pixels": int(len(d_map)),
    }


def hatched_areas(ground_points_map, cell_m=1.0):
    """Distinct hatched areas: the 8-connected groups of occupied cell_m cells of all hatched
    points (N x 2, map frame) of the drive."""
    if len(ground_points_map) == 0:
        return 0
    cells = np.floor(np.asarray(ground_points_map) / cell_m).astype(int)
    cells -= cells.min(axis=0)
    grid = np.zeros(cells.max(axis=0) + 1, dtype=bool)
    grid[cells[:, 0], cells[:, 1]] = True
    grid = ndimage.binary_closing(grid, iterations=2)
    return int(ndimage.label(grid, structure=np.ones((3, 3)))[1])
