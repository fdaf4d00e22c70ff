"""Tables 5, 5b, 5c and 5d: the full method (config/mapper.yaml) on every drive: its figures
before -> after, the lanelets of its lines, the view's ceiling, and the lane stretches a join
laid across a gap."""
from .. import drives
from ..configs import FULL, IPM, ablation, noise_told
from ..metrics import before_after, false_positives, roll_after
from ..plan import Request
from ..report import Table, fmt

TITLE = "The full method on every drive (Tables 5, 5b, 5c, 5d)"
MODES = ("all",)
NOISE = drives.noise_name(0.5)


def requests(ctx):
    names = list(ctx.scenarios) + ctx.seed_drives() + ctx.variant_drives()
    out = [Request(ctx.drive(d), ablation(c)) for d in names for c in (IPM, FULL)]
    if ctx.extra:
        out.append(Request(drives.noise(ctx, 0.5), noise_told(0.5)))
    return out


def drives_of(ctx, results):
    """Every drive mapped with the full method, in table order: the scenarios, seeds 2 and 3,
    then the variant drives."""
    names = list(ctx.scenarios)
    for seed in drives.SEEDS[1:]:
        names += ["%s_seed%d" % (s, seed) for s in drives.SEED_SCENARIOS if s in ctx.scenarios]
    names += [drives.BLOBS, NOISE, drives.URBAN_LABELLED, drives.CROWN]
    return [n for n in names if (n, FULL) in results]


def per_drive(ctx, results):
    rows = []
    for d in drives_of(ctx, results):
        m, ipm = results[(d, FULL)], results.get((d, IPM), {})
        rows.append([d + (" (told the noise)" if d == NOISE else ""),
                     fmt(m.get("marking_ape_mean_m")), fmt(ipm.get("marking_ape_mean_m")),
                     fmt(m.get("lane_ape_mean_m")), fmt(m.get("marking_recall"), 2),
                     false_positives(m), fmt(m.get("lane_f1"), 2),
                     fmt(m.get("lane_splines_per_matched_gt_lane"), 2),
                     before_after(m, "extrinsic_rot_err_deg"), fmt(roll_after(m)),
                     before_after(m, "extrinsic_trans_err_m"), before_after(m, "ipm_grid_err_m"),
                     before_after(m, "pose_trans_err_m", input_suffix="_input"),
                     before_after(m, "pose_yaw_err_deg", input_suffix="_input")])
    return Table("Table 5. Ours (+PPSR) = config/mapper.yaml on every drive (before -> after)", [
        "drive", "marking APE", "IPM marking APE", "lane APE", "marking recall",
        "false positives", "lane F1", "splines per matched GT line", "rot (deg)",
        "roll after (deg)", "trans (m)", "IPM grid (m)", "pose trans (m)", "pose yaw (deg)"], rows)


def lanelets(ctx, results):
    rows = []
    for d in drives_of(ctx, results):
        m = results[(d, FULL)]
        rows.append([d, "%s / %s" % (m.get("lanelet_map_total"), m.get("lanelet_gt_total")),
                     fmt(m.get("lanelet_recall"), 2), fmt(m.get("lanelet_precision"), 2),
                     fmt(m.get("lanelets_per_covered_gt_lanelet"), 2)])
    return Table("Table 5b. Lanelets of the mapped lines (what the Lanelet2 export holds) against "
                 "those of the GT lines, by centerline length", [
                     "drive", "lanelets map / GT", "lanelet recall", "lanelet precision",
                     "lanelets per covered GT lanelet"], rows)


def ceiling(ctx, results):
    rows = []
    for d in drives_of(ctx, results):
        m = results[(d, FULL)]
        if m.get("ceiling_lane_f1") is None and m.get("ceiling_marking_recall") is None:
            continue
        rows.append([d, "%s / %s" % (m.get("marking_matched"), m.get("marking_gt_visible")),
                     "%s / %s" % (m.get("ceiling_markings_reachable"), m.get("marking_gt_visible")),
                     "%s / %s" % (m.get("lane_gt_matched"), m.get("lane_gt_total")),
                     "%s / %s" % (m.get("ceiling_lanes_reachable"), m.get("lane_gt_total")),
                     "%s / %s" % (fmt(m.get("lane_f1"), 2), fmt(m.get("ceiling_lane_f1"), 2)),
                     "%s / %s, %s" % (m.get("seen_part_matched"), m.get("seen_part_gt"),
                                      fmt(m.get("seen_part_ape_mean_m")))])
    return Table("Table 5c. The view's ceiling: what a map of exactly the road in view (within "
                 "ipm.max_range_m of a true pose, through the true extrinsic) would score; GT "
                 "only, eval/view_ceiling.h. Last column: map markings on the seen part of their "
                 "marking", [
                     "drive", "markings matched / GT", "reachable / GT", "GT lines matched / all",
                     "reachable / all", "lane F1 / ceiling", "on seen part / seen, APE (m)"], rows)


def laid(ctx, results):
    rows = []
    for d in drives_of(ctx, results):
        m = results[(d, FULL)]
        length = m.get("lane_km")
        rows.append([d, "%s / %s" % (fmt(m.get("lane_unmeasured_length_m"), 1),
                                     fmt(None if length is None else 1000.0 * length, 0)),
                     fmt(m.get("lane_ape_unmeasured_mean_m")),
                     fmt(m.get("lane_ape_measured_mean_m"))])
    return Table("Table 5d. Lane stretches a join laid across a gap in the line's observations "
                 "(map.json `unmeasured`: no pixel measured them), and the lane APE there and "
                 "elsewhere", ["drive", "laid / mapped length (m)", "lane APE laid (m)",
                               "lane APE measured (m)"], rows)


def tables(ctx, results):
    if not ctx.extra:
        return []
    return [per_drive(ctx, results), lanelets(ctx, results), ceiling(ctx, results),
            laid(ctx, results)]
