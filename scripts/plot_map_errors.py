#!/usr/bin/python3
"""plot_map.py's arithmetic: reading its inputs, sampling the lane splines, the distance of
points to the ground-truth lanes, the marking matches and errors, and the headline line
(evaluate_map's rules; docs/file_formats.md for the inputs)."""
import json
import math
import sys

import numpy as np

MARKING_GATE_M = 2.0
SPLINE_STEP_M = 0.2


def load_json(path, what):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        sys.exit("plot_map.py: error: cannot read %s %s: %s" % (what, path, e))


def catmull_rom(control_points, step_m=SPLINE_STEP_M):
    """Samples a uniform Catmull-Rom spline (phantom ends excluded) about every step_m."""
    c = np.asarray(control_points, dtype=float)
    pieces = []
    for i in range(len(c) - 3):
        c0, c1, c2, c3 = c[i], c[i + 1], c[i + 2], c[i + 3]
        count = max(2, int(math.ceil(np.linalg.norm(c2 - c1) / step_m)) + 1)
        u = np.linspace(0.0, 1.0, count)[:, None]
        a1 = c2 - c0
        a2 = 2 * c0 - 5 * c1 + 4 * c2 - c3
        a3 = 3 * (c1 - c2) + c3 - c0
        points = 0.5 * (2 * c1 + (a1 + (a2 + a3 * u) * u) * u)
        pieces.append(points if i == 0 else points[1:])
    return np.vstack(pieces) if pieces else np.zeros((0, 3))


class LaneDistance:
    """Distance from points to the ground-truth lane polylines: the nearest GT point (exact,
    through a grid of CELL_M cells), then the two segments next to it. numpy only."""

    CELL_M = 2.0

    def __init__(self, gt_lanes):
        points, lane_of = [], []
        for index, lane in enumerate(gt_lanes):
            points.append(np.asarray(lane["points"], dtype=float))
            lane_of.append(np.full(len(lane["points"]), index))
        self.points = np.vstack(points) if points else np.zeros((0, 3))
        self.lane_of = np.concatenate(lane_of) if lane_of else np.zeros(0, dtype=int)
        self.cells = {}
        for i, key in enumerate(map(tuple, np.floor(self.points[:, :2] / self.CELL_M).astype(int))):
            self.cells.setdefault(key, []).append(i)

    def nearest(self, queries):
        """Index of and distance to the nearest GT point of each query."""
        best = np.full(len(queries), np.inf)
        index = np.zeros(len(queries), dtype=int)
        keys = np.floor(queries[:, :2] / self.CELL_M).astype(int)
        groups = {}
        for q, key in enumerate(map(tuple, keys)):
            groups.setdefault(key, []).append(q)
        for (cx, cy), members in groups.items():
            candidates = [i for dx in (-1, 0, 1) for dy in (-1, 0, 1)
                          for i in self.cells.get((cx + dx, cy + dy), [])]
            if not candidates:
                continue
            candidates = np.asarray(candidates)
            d = np.linalg.norm(queries[members][:, None, :] - self.points[candidates][None], axis=2)
            best[members] = d.min(axis=1)
            index[members] = candidates[d.argmin(axis=1)]
        # Beyond one cell, a closer point may lie outside the 3 x 3 block: search everything.
        for q in np.nonzero(best > self.CELL_M)[0]:
            d = np.linalg.norm(self.points - queries[q], axis=1)
            index[q], best[q] = d.argmin(), d.min()
        return index, best

    def __call__(self, queries):
        if len(self.points) == 0 or len(queries) == 0:
            return np.full(len(queries), np.nan)
        j, best = self.nearest(queries)
        for neighbor in (j - 1, j + 1):
            neighbor = np.clip(neighbor, 0, len(self.points) - 1)
            same = self.lane_of[neighbor] == self.lane_of[j]
            a, b = self.points[j], self.points[neighbor]
            ab = b - a
            length2 = np.maximum((ab * ab).sum(axis=1), 1e-12)
            t = np.clip(((queries - a) * ab).sum(axis=1) / length2, 0.0, 1.0)
            distance = np.linalg.norm(a + t[:, None] * ab - queries, axis=1)
            best = np.where(same, np.minimum(best, distance), best)
        return best


def marking_errors(vmap, gt, metrics):
    """Per map marking: (center error vector or None, verdict, matched GT id)."""
    if metrics is not None and "markings" in metrics:
        result = {}
        for m in metrics["markings"]:
            error = m["center_err_xyz_m"]
            error = None if error[0] is None else np.asarray(error)
            result[m["map_id"]] = (error, m["verdict"], m["gt_id"])
        return result
    # The evaluator's rule (docs/file_formats.md): same class, centers within the gate,
    # one-to-one by increasing distance; in-gate leftovers of a matched GT are duplicates.
    gt_centers = [np.mean(g["corners"], axis=0) for g in gt["markings"]]
    map_centers = [np.mean(m["corners"], axis=0) for m in vmap["markings"]]
    pairs = sorted((np.linalg.norm(mc - gc), i, j)
                   for i, (m, mc) in enumerate(zip(vmap["markings"], map_centers))
                   for j, (g, gc) in enumerate(zip(gt["markings"], gt_centers))
                   if m["class_id"] == g["class_id"] and np.linalg.norm(mc - gc) <= MARKING_GATE_M)
    result, gt_taken = {}, set()
    for _, i, j in pairs:
        map_id = vmap["markings"][i]["id"]
        if map_id not in result and j not in gt_taken:
            gt_taken.add(j)
            result[map_id] = (map_centers[i] - gt_centers[j], "matched", gt["markings"][j]["id"])
    for _, i, j in pairs:
        map_id = vmap["markings"][i]["id"]
        if map_id not in result and j in gt_taken:
            result[map_id] = (None, "duplicate", gt["markings"][j]["id"])
    for m in vmap["markings"]:
        result.setdefault(m["id"], (None, "false_positive", None))
    return result


def fmt(value, spec):
    return "n/a" if value is None else format(value, spec)


def headline(metrics):
    if metrics is None:
        return "(run evaluate_map and pass --metrics for the headline metrics)"
    m = metrics
    return (
        "markings: APE %s +- %s m, recall %s, dup %s   |   lanes: APE %s +- %s m, F1 %s\n"
        "extrinsic: %s deg / %s m (initial %s deg / %s m), IPM grid %s m (initial %s m)   |   "
        "poses: %s m / %s deg (odometry %s m / %s deg)"
        % (fmt(m.get("marking_ape_mean_m"), ".3f"), fmt(m.get("marking_ape_std_m"), ".3f"),
           fmt(m.get("marking_recall"), ".2f"), m.get("marking_duplicates"),
           fmt(m.get("lane_ape_mean_m"), ".3f"), fmt(m.get("lane_ape_std_m"), ".3f"),
           fmt(m.get("lane_f1"), ".2f"), fmt(m.get("extrinsic_rot_err_deg"), ".2f"),
           fmt(m.get("extrinsic_trans_err_m"), ".3f"),
           fmt(m.get("extrinsic_rot_err_deg_initial"), ".2f"),
           fmt(m.get("extrinsic_trans_err_m_initial"), ".3f"), fmt(m.get("ipm_grid_err_m"), ".3f"),
           fmt(m.get("ipm_grid_err_m_initial"), ".3f"), fmt(m.get("pose_trans_err_m"), ".3f"),
           fmt(m.get("pose_rot_err_deg"), ".2f"), fmt(m.get("pose_trans_err_m_input"), ".3f"),
           fmt(m.get("pose_rot_err_deg_input"), ".2f")))
