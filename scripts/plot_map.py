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

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402

from plot_map_errors import headline, load_json  # noqa: E402
from plot_map_views import (ARROW_SCALE, LANE_CMAP, MARKING_CMAP, TopView,  # noqa: E402
                            draw_marking_bars, draw_pose_errors, map_extent, plot_map_alone,
                            zoom_centers)


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
