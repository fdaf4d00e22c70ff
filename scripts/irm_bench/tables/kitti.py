"""Table K (`--kitti`, and in a whole run): real camera images, ../shared/data/kitti_onramp
segmented with segment_bag and mapped with the default config, scored without marking ground
truth (irm_bench/kitti.py, its arithmetic in irm_bench/kitti_reprojection.py)."""
import os

from .. import kitti
from ..report import Line, Table

TITLE = "Real camera images (Table K, `--kitti`)"
MODES = ("all", "kitti")
f = kitti.f


def requests(ctx):
    return []  # segmented and mapped here: a pipeline of its own


def rows(m):
    lo, (pose_t, pose_r), (odom_t, odom_r) = m["leave_out"], m["poses"], m["odometry"]
    angle, bound, sa, sb = m["halves"]
    start_t, start_r = m["poses_from_start"]
    odom_start_t, odom_start_r = m["odometry_from_start"]
    return [
        ["elements mapped", "%d lanes, %d markings" % (m["lanes"], m["markings"]), ""],
        ["chevron stripes mapped as lanes", m["chevron_lanes"], "0"],
        ["duplicate lines (two splines on one painted line)", m["duplicates"], "0"],
        ["hatched areas found (left out of the map)", m["hatched_areas"], ""],
        ["leave-out median px: map -> paint / paint -> map (30 m)",
         "%s / %s" % (f(lo["map_to_paint_median_px"], 2), f(lo["paint_to_map_median_px"], 2)),
         "<= 2 / <= 3"],
        ["paint pixels within 3 px: precision / recall (30 m)",
         "%s / %s" % (f(lo["precision"]), f(lo["recall"])), ">= 0.9 / >= 0.8"],
        ["poses vs GPS/INS: corrected / odometry, m (deg)",
         "%s (%s) / %s (%s) = %sx" % (f(pose_t), f(pose_r), f(odom_t), f(odom_r),
                                      f(pose_t / odom_t, 2)), "<= 0.6x"],
        ["... both aligned at the first frame (what a map can correct)",
         "%s (%s) / %s (%s) = %sx" % (f(start_t), f(start_r), f(odom_start_t), f(odom_start_r),
                                      f(start_t / odom_start_t, 2)), ""],
        ["extrinsic: moved from the level 1.65 m prior, height",
         "%s deg, %s m" % (f(m["extrinsic_moved_deg"], 2), f(m["height_m"], 3)), ""],
        ["extrinsic: reported sigma roll/pitch/yaw (deg)",
         "/".join(f(s, 2) for s in m["sigma_rpy_deg"]), ""],
        ["extrinsic: halves apart (3 sigma of the halves)",
         "%s deg (%s; sigmas %s, %s)" % (f(angle, 2), f(bound, 2), f(sa, 2), f(sb, 2)),
         "<= 0.3 deg and <= 3 sigma"],
        ["segmentation rate", m["rate"], ">= 10 frames/s or skip policy"],
        ["mapping front end", m["front_end"], ""],
        ["segmentation instances", m["seg_instances"], ""],
        ["segmentation dropped", m["seg_dropped"], ""],
        ["mapper extraction", m["extraction"], ""],
        ["mapper sanity", m["sanity"], ""],
        ["leave-out pixels scored (map / paint)",
         "%d / %d" % (lo["map_pixels"], lo["paint_pixels"]), ""],
    ]


def tables(ctx, results):
    m = kitti.measure(ctx, ctx.out)
    title = ("Table K. Real camera images: kitti_onramp (51 KITTI frames), segment_bag + "
             "map_from_bag, default configs")
    if isinstance(m, str):
        return [Line("%s\nskipped: %s" % (title, m))]
    return [Table(title, ["figure", "value", "target"], rows(m))]
