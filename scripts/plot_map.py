#!/usr/bin/python3
"""Plot a vectorized road map, alone or against the ground truth of its drive.

    plot_map.py --map map.json [--ground-truth ground_truth.json] \
        [--metrics metrics.json] --out map.png

Without --ground-truth (a map of a real drive): one top view of the map alone, the lane
splines (solid / dashed by their style), the markings colored by class and the corrected
trajectory, with the element counts and the lane length in the title.

With --ground-truth, one PNG: a top view of the whole drive (ground-truth lanes in gray, mapped splines colored
by their distance to the ground-truth lanes, markings colored by their center error, the
true, odometry and corrected trajectories), zoomed views around individual markings, the
per-marking x/y/z center errors, and the per-frame pose error. The headline metrics go
into the title. With --metrics (written by evaluate_map) the marking matches are those of
the evaluator; without it they are recomputed by the same rule. File formats:
docs/file_formats.md.
"""

import argparse
import json
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.colors import Normalize  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402

MARKING_GATE_M = 2.0
SPLINE_STEP_M = 0.2
LANE_CMAP = "viridis"
MARKING_CMAP = "plasma"
ARROW_SCALE = 5.0  # error arrows in the zoomed views are drawn this many times too long
UNMATCHED_COLORS = {"duplicate": "darkorange", "false_positive": "red"}


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


class TopView:
    """Draws the map and the ground truth into top-view axes."""

    def __init__(self, vmap, gt, metrics):
        self.vmap, self.gt = vmap, gt
        self.errors = marking_errors(vmap, gt, metrics)
        distance = LaneDistance(gt["lanes"])
        self.splines = []
        for lane in vmap["lanes"]:
            samples = catmull_rom(lane["control_points"])
            self.splines.append((samples, distance(samples)))
        lane_errors = np.concatenate([e for _, e in self.splines]) if self.splines else []
        lane_max = np.nanpercentile(lane_errors, 98) if len(lane_errors) else 0.5
        self.lane_norm = Normalize(0.0, max(0.1, float(np.nan_to_num(lane_max, nan=0.5))))
        marking_values = [np.linalg.norm(e) for e, _, _ in self.errors.values() if e is not None]
        self.marking_norm = Normalize(0.0, max([0.1] + marking_values))
        xy = lambda poses: np.array([p["t"][:2] for p in poses]).reshape(-1, 2)
        self.true_xy = xy([f["T_map_base_true"] for f in gt["frames"]])
        self.odom_xy = xy([f["T_map_base_odom"] for f in gt["frames"]])
        self.corrected_xy = xy(vmap.get("trajectory", []))

    def draw(self, ax, detail):
        width = 1.5 if detail else 0.8
        for lane in self.gt["lanes"]:
            p = np.asarray(lane["points"])
            ax.plot(p[:, 0], p[:, 1], color="0.6", lw=0.8 if detail else 0.5, zorder=1,
                    label="ground-truth lane" if lane is self.gt["lanes"][0] else None)
        for samples, errors in self.splines:
            segments = np.stack([samples[:-1, :2], samples[1:, :2]], axis=1)
            lines = LineCollection(segments, cmap=LANE_CMAP, norm=self.lane_norm,
                                   linewidths=2.5 * width, zorder=3)
            lines.set_array(0.5 * (errors[:-1] + errors[1:]))
            ax.add_collection(lines)
        for g in self.gt["markings"]:
            ax.add_patch(Polygon(np.asarray(g["corners"])[:, :2], closed=True, fill=False,
                                 ec="black", lw=0.9 if detail else 0.4, ls="--", zorder=4))
        cmap = plt.get_cmap(MARKING_CMAP)
        for m in self.vmap["markings"]:
            error, verdict, _ = self.errors.get(m["id"], (None, "false_positive", None))
            corners = np.asarray(m["corners"])[:, :2]
            if error is None or verdict != "matched":
                ax.add_patch(Polygon(corners, closed=True, fill=False, lw=1.5 * width, zorder=5,
                                     ec=UNMATCHED_COLORS.get(verdict, "red")))
                continue
            ax.add_patch(Polygon(corners, closed=True, fc=cmap(self.marking_norm(
                np.linalg.norm(error))), ec="k", lw=0.3, alpha=0.9, zorder=5))
            if detail:
                center = corners.mean(axis=0)
                ax.annotate("", xy=center + (ARROW_SCALE - 1) * error[:2],
                            xytext=center - error[:2], zorder=6,
                            arrowprops=dict(arrowstyle="->", color="crimson", lw=1.2))
        ax.plot(self.true_xy[:, 0], self.true_xy[:, 1], "k-", lw=1.0, zorder=2,
                label="true trajectory")
        ax.plot(self.odom_xy[:, 0], self.odom_xy[:, 1], color="darkorange", ls="--", lw=1.0,
                zorder=2, label="odometry (input)")
        if len(self.corrected_xy):
            ax.plot(self.corrected_xy[:, 0], self.corrected_xy[:, 1], color="royalblue", lw=1.0,
                    zorder=2, label="corrected trajectory")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x [m] (map)")
        ax.set_ylabel("y [m] (map)")
        ax.grid(True, lw=0.3, alpha=0.5)


def zoom_centers(view, count=3, min_separation_m=20.0):
    """Centers of the zoomed views: markings by decreasing interest (worst matched error,
    unmatched, median, best, the rest), skipping any within min_separation_m of a chosen
    one; else points spread along the trajectory."""
    scored = []
    for m in view.vmap["markings"]:
        error, verdict, _ = view.errors.get(m["id"], (None, "false_positive", None))
        center = np.mean(np.asarray(m["corners"])[:, :2], axis=0)
        if error is not None and verdict == "matched":
            scored.append((np.linalg.norm(error), center, "marking error %.2f m"
                           % np.linalg.norm(error)))
        else:
            scored.append((np.inf, center, verdict.replace("_", " ") + " marking"))
    matched = sorted((s for s in scored if np.isfinite(s[0])), key=lambda t: -t[0])
    unmatched = [s for s in scored if not np.isfinite(s[0])]
    ordered = matched[:1] + unmatched[:1] + matched[len(matched) // 2:len(matched) // 2 + 1] + \
        matched[-1:] + matched + unmatched
    chosen = []
    for _, center, title in ordered:
        if all(np.linalg.norm(center - c) >= min_separation_m for c, _ in chosen):
            chosen.append((center, title))
        if len(chosen) == count:
            return chosen
    xy = view.true_xy if len(view.true_xy) else np.zeros((1, 2))
    for i in np.linspace(0, len(xy) - 1, 4 * count + 2)[1:-1]:
        if len(chosen) < count and all(np.linalg.norm(xy[int(i)] - c) >= min_separation_m
                                       for c, _ in chosen):
            chosen.append((xy[int(i)], "lanes"))
    return chosen


def map_extent(view, margin_m=10.0):
    """x and y limits around the map and the trajectories (not the whole ground truth)."""
    parts = [view.true_xy, view.odom_xy, view.corrected_xy]
    parts += [samples[:, :2] for samples, _ in view.splines]
    parts += [np.asarray(m["corners"])[:, :2] for m in view.vmap["markings"]]
    xy = np.vstack([p for p in parts if len(p)]) if any(len(p) for p in parts) else None
    if xy is None:
        return None
    low, high = xy.min(axis=0) - margin_m, xy.max(axis=0) + margin_m
    return (low[0], high[0]), (low[1], high[1])


def draw_marking_bars(ax, view):
    rows = []
    for m in view.vmap["markings"]:
        error, verdict, gt_id = view.errors.get(m["id"], (None, None, None))
        if error is not None and verdict == "matched":
            rows.append((gt_id, m.get("class_name") or str(m["class_id"]), error))
    if not rows:
        ax.text(0.5, 0.5, "no matched markings", ha="center", va="center",
                transform=ax.transAxes)
        return
    rows.sort(key=lambda r: r[0])
    index = np.arange(len(rows))
    errors = np.array([r[2] for r in rows])
    for k, (axis, color) in enumerate(zip("xyz", ("tab:red", "tab:green", "tab:blue"))):
        ax.bar(index + (k - 1) * 0.27, errors[:, k], 0.27, color=color,
               label="%s error" % axis)
    ax.plot(index, np.linalg.norm(errors, axis=1), "k.", label="|error|")
    ax.axhline(0.0, color="k", lw=0.5)
    step = max(1, len(rows) // 40)
    ax.set_xticks(index[::step])
    ax.set_xticklabels(["%s\n%s" % (r[0], r[1][:14]) for r in rows[::step]], fontsize=6)
    ax.set_xlabel("ground-truth marking id and class")
    ax.set_ylabel("center error (map - truth) [m]")
    ax.set_title("Per-marking center error, map frame axes")
    ax.legend(fontsize=8, ncol=4, loc="best")
    ax.grid(True, axis="y", lw=0.3)


def draw_pose_errors(ax, vmap, gt):
    """Translation error per frame of the odometry and of the map's trajectory (poses
    paired with GT frames by the nearest stamp within 1 ms)."""
    frames = sorted(gt["frames"], key=lambda f: f["stamp"])
    if not frames:
        ax.text(0.5, 0.5, "no ground-truth frames", ha="center", va="center",
                transform=ax.transAxes)
        return
    stamps = np.array([f["stamp"] for f in frames])
    true_t = np.array([f["T_map_base_true"]["t"] for f in frames])
    odom_t = np.array([f["T_map_base_odom"]["t"] for f in frames])
    ax.plot(stamps - stamps[0], np.linalg.norm(odom_t - true_t, axis=1), color="darkorange",
            ls="--", label="odometry (input)")
    poses = vmap.get("trajectory", [])
    if poses:
        pose_stamps = np.array([p["stamp"] for p in poses])
        k = np.clip(np.searchsorted(stamps, pose_stamps), 1, len(stamps) - 1)
        k = np.where(np.abs(stamps[k - 1] - pose_stamps) < np.abs(stamps[k] - pose_stamps),
                     k - 1, k) if len(stamps) > 1 else np.zeros(len(poses), dtype=int)
        paired = np.abs(stamps[k] - pose_stamps) <= 1e-3
        error = np.linalg.norm(np.array([p["t"] for p in poses]) - true_t[k], axis=1)
        ax.plot(pose_stamps[paired] - stamps[0], error[paired], color="royalblue",
                label="corrected")
    ax.set_xlabel("time since the first frame [s]")
    ax.set_ylabel("translation error [m]")
    ax.set_title("Pose error against truth")
    ax.legend(fontsize=8)
    ax.grid(True, lw=0.3)


def plot_map_alone(vmap, metrics, out):
    """The map without ground truth: lanes, markings by class, corrected trajectory."""
    fig, ax = plt.subplots(figsize=(14, 9))
    lane_m = 0.0
    for k, lane in enumerate(vmap["lanes"]):
        samples = catmull_rom(lane["control_points"])
        lane_m += float(np.sum(np.linalg.norm(np.diff(samples, axis=0), axis=1)))
        ax.plot(samples[:, 0], samples[:, 1], color="seagreen", lw=1.5, zorder=3,
                ls="--" if lane.get("style") == "dashed" else "-",
                label="lane spline" if k == 0 else None)
    classes = sorted({m.get("class_name") or str(m["class_id"]) for m in vmap["markings"]})
    cmap = plt.get_cmap("tab10")
    for m in vmap["markings"]:
        name = m.get("class_name") or str(m["class_id"])
        ax.add_patch(Polygon(np.asarray(m["corners"])[:, :2], closed=True, zorder=4,
                             fc=cmap(classes.index(name) % 10), ec="k", lw=0.3, alpha=0.9))
    trajectory = np.array([p["t"][:2] for p in vmap.get("trajectory", [])]).reshape(-1, 2)
    if len(trajectory):
        ax.plot(trajectory[:, 0], trajectory[:, 1], color="royalblue", lw=1.0, zorder=2,
                label="corrected trajectory")
    handles, _ = ax.get_legend_handles_labels()
    handles += [Polygon([[0, 0]], fc=cmap(i % 10), ec="k", lw=0.3, label=name)
                for i, name in enumerate(classes)]
    if handles:
        ax.legend(handles=handles, loc="upper left", fontsize=8)
    ax.autoscale_view()
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m] (map)")
    ax.set_ylabel("y [m] (map)")
    ax.grid(True, lw=0.3, alpha=0.5)
    title = "Map (no ground truth): %d markings, %d lanes, %.3f km of lanes, %d poses" % (
        len(vmap["markings"]), len(vmap["lanes"]), lane_m / 1000.0, len(trajectory))
    if metrics is not None:
        title += "\n" + headline(metrics)
    ax.set_title(title, fontsize=11)
    fig.savefig(out, dpi=110, bbox_inches="tight")
    print("wrote %s" % out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", required=True, help="map JSON (SaveVectorMapJson)")
    parser.add_argument("--ground-truth", help="ground-truth JSON (without it: the map alone)")
    parser.add_argument("--metrics", help="metrics JSON written by evaluate_map --json")
    parser.add_argument("--out", required=True, help="output PNG")
    args = parser.parse_args()
    vmap = load_json(args.map, "map")
    metrics = load_json(args.metrics, "metrics") if args.metrics else None
    if not args.ground_truth:
        plot_map_alone(vmap, metrics, args.out)
        return
    gt = load_json(args.ground_truth, "ground truth")

    view = TopView(vmap, gt, metrics)
    fig = plt.figure(figsize=(17, 14))
    grid = fig.add_gridspec(3, 3, height_ratios=[1.25, 1.0, 0.8], hspace=0.35, wspace=0.25)
    overview = fig.add_subplot(grid[0, :])
    view.draw(overview, detail=False)
    extent = map_extent(view)
    if extent is not None:
        overview.set_xlim(*extent[0])
        overview.set_ylim(*extent[1])
        # A long straight drive would be a hairline at equal scale: stretch y instead.
        spans = [high - low for low, high in extent]
        if max(spans) > 6 * min(spans):
            overview.set_aspect("auto")
            overview.set_ylabel(overview.get_ylabel() + "  (axes not to scale)")
    overview.set_title("Top view: mapped splines colored by lane error, markings by center "
                       "error (outlines: unmatched), dashed black: true markings")
    handles, _ = overview.get_legend_handles_labels()
    handles += [Polygon([[0, 0]], fill=False, ec="black", ls="--", label="true marking"),
                Polygon([[0, 0]], fill=False, ec="darkorange", lw=1.5, label="duplicate marking"),
                Polygon([[0, 0]], fill=False, ec="red", lw=1.5, label="false-positive marking")]
    overview.legend(handles=handles, loc="upper left", fontsize=8)
    for k, (center, title) in enumerate(zoom_centers(view)):
        ax = fig.add_subplot(grid[1, k])
        view.draw(ax, detail=True)
        ax.set_xlim(center[0] - 12, center[0] + 12)
        ax.set_ylim(center[1] - 7, center[1] + 7)
        arrow_note = " (arrow: truth -> map, x%g)" % ARROW_SCALE if "marking" in title else ""
        ax.set_title("Zoom %d: %s%s" % (k + 1, title, arrow_note), fontsize=10)
        overview.add_patch(plt.Rectangle(center - [12, 7], 24, 14, fill=False, ec="crimson",
                                         lw=1.0, zorder=7))
        overview.annotate(str(k + 1), center + [12, 7], color="crimson", fontsize=9)
        ax.text(0.01, 0.97, str(k + 1), transform=ax.transAxes, color="crimson", va="top")
    draw_marking_bars(fig.add_subplot(grid[2, :2]), view)
    draw_pose_errors(fig.add_subplot(grid[2, 2]), vmap, gt)
    for position, norm, cmap, label in ((1.01, view.lane_norm, LANE_CMAP, "lane error [m]"),
                                        (1.08, view.marking_norm, MARKING_CMAP,
                                         "marking center error [m]")):
        fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), label=label,
                     cax=overview.inset_axes([position, 0.0, 0.012, 1.0]))
    name = gt.get("scenario", "")
    fig.suptitle("Map vs ground truth (%s, seed %s)\n%s"
                 % (name, gt.get("seed"), headline(metrics)), fontsize=11)
    fig.savefig(args.out, dpi=110, bbox_inches="tight")
    print("wrote %s" % args.out)


if __name__ == "__main__":
    main()
