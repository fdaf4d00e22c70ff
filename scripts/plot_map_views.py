#!/usr/bin/python3
"""plot_map.py's drawing: the top view of a map against its ground truth (TopView), the
choice of the zoomed views, the per-marking error bars, the per-frame pose errors, and the
top view of a map alone."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.colors import Normalize  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402

from plot_map_errors import LaneDistance, catmull_rom, headline, marking_errors  # noqa: E402

LANE_CMAP = "viridis"
MARKING_CMAP = "plasma"
ARROW_SCALE = 5.0  # error arrows in the zoomed views are drawn this many times too long
UNMATCHED_COLORS = {"duplicate": "darkorange", "false_positive": "red"}


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
