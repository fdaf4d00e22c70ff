"""The benchmark's per-drive table for the full method and the "Done when" rows of issues
11, 12 and 13 (scripts/benchmark.py calls print_tables with its results).

Results are keyed (drive, config): drives are the scenarios (seed 1), "<scenario>_seed<k>",
"public_road_blobs_1.0", "public_road_noise_<level>", "urban_occluders_labelled" and the real
drive "av2_pit_dev";
configs "ipm", "ours_ppsr" (= config/mapper.yaml) and the other ablations.
"""

SEED_SCENARIOS = ["public_road", "port", "hilly"]
BLOBS = "public_road_blobs_1.0"
URBAN_LABELLED = "urban_occluders_labelled"
CROWN = "public_road_crown"
NOISE = "public_road_noise_0.5"
REAL = "av2_pit_dev"
# The issues' "now" figures (seed 1, docs/benchmark.md of 2026-12-01) the +10 % rows refer to.
ISSUE_MARKING_APE = {"public_road": 0.089, "port": 0.141, "hilly": 0.157}
ISSUE_LANE_APE = {"port": 0.072, "hilly": 0.067}


def false_positives(m):
    """Map markings that match no GT marking and duplicate none (evaluate_map's verdicts)."""
    return sum(1 for x in m.get("markings", []) if x.get("verdict") == "false_positive")


def _arrow(fmt, m, key, digits=3, input_suffix="_initial"):
    return "%s -> %s" % (fmt(m.get(key + input_suffix), digits), fmt(m.get(key), digits))


def _roll_after(m):
    rpy = m.get("extrinsic_rpy_err_deg")
    return abs(rpy[0]) if rpy else None


def _seed_drive(scenario, seed):
    return scenario if seed == 1 else "%s_seed%d" % (scenario, seed)


def _drives(scenarios, results):
    """Every drive mapped with ours_ppsr, in table order."""
    names = list(scenarios)
    for seed in (2, 3):
        names += [_seed_drive(s, seed) for s in SEED_SCENARIOS if s in scenarios]
    names += [BLOBS, NOISE, URBAN_LABELLED, CROWN]
    return [n for n in names if (n, "ours_ppsr") in results]


def print_tables(scenarios, results, table, fmt, real_absent=False):
    """Table 5 (Ours +PPSR on every drive) and the issue rows; `real_absent`: the real drive
    was asked for but its folder is not there."""
    ours = lambda drive: results[(drive, "ours_ppsr")]
    rows = []
    for d in _drives(scenarios, results):
        m = ours(d)
        ipm = results.get((d, "ipm"), {})
        rows.append([d + (" (told the noise)" if d == NOISE else ""),
                     fmt(m.get("marking_ape_mean_m")), fmt(ipm.get("marking_ape_mean_m")),
                     fmt(m.get("lane_ape_mean_m")), fmt(m.get("marking_recall"), 2),
                     false_positives(m), fmt(m.get("lane_f1"), 2),
                     fmt(m.get("lane_splines_per_matched_gt_lane"), 2),
                     _arrow(fmt, m, "extrinsic_rot_err_deg"), fmt(_roll_after(m)),
                     _arrow(fmt, m, "extrinsic_trans_err_m"), _arrow(fmt, m, "ipm_grid_err_m"),
                     _arrow(fmt, m, "pose_trans_err_m", input_suffix="_input"),
                     _arrow(fmt, m, "pose_yaw_err_deg", input_suffix="_input")])
    table("Table 5. Ours (+PPSR) = config/mapper.yaml on every drive (before -> after)", [
        "drive", "marking APE", "IPM marking APE", "lane APE", "marking recall",
        "false positives", "lane F1", "splines per matched GT line", "rot (deg)",
        "roll after (deg)", "trans (m)", "IPM grid (m)", "pose trans (m)", "pose yaw (deg)"], rows)

    rows = []
    for d in _drives(scenarios, results):
        m = ours(d)
        rows.append([d, "%s / %s" % (m.get("lanelet_map_total"), m.get("lanelet_gt_total")),
                     fmt(m.get("lanelet_recall"), 2), fmt(m.get("lanelet_precision"), 2),
                     fmt(m.get("lanelets_per_covered_gt_lanelet"), 2)])
    table("Table 5b. Lanelets of the mapped lines (what the Lanelet2 export holds) against those of "
          "the GT lines, by centerline length", [
              "drive", "lanelets map / GT", "lanelet recall", "lanelet precision",
              "lanelets per covered GT lanelet"], rows)

    rows = []
    for d in _drives(scenarios, results):
        m = ours(d)
        if m.get("ceiling_lane_f1") is None and m.get("ceiling_marking_recall") is None:
            continue
        rows.append([d, "%s / %s" % (m.get("marking_matched"), m.get("marking_gt_visible")),
                     "%s / %s" % (m.get("ceiling_markings_reachable"), m.get("marking_gt_visible")),
                     "%s / %s" % (m.get("lane_gt_matched"), m.get("lane_gt_total")),
                     "%s / %s" % (m.get("ceiling_lanes_reachable"), m.get("lane_gt_total")),
                     "%s / %s" % (fmt(m.get("lane_f1"), 2), fmt(m.get("ceiling_lane_f1"), 2)),
                     "%s / %s, %s" % (m.get("seen_part_matched"), m.get("seen_part_gt"),
                                      fmt(m.get("seen_part_ape_mean_m")))])
    table("Table 5c. The view's ceiling: what a map of exactly the road in view (within "
          "ipm.max_range_m of a true pose, through the true extrinsic) would score; GT only, "
          "eval/view_ceiling.h. Last column: map markings on the seen part of their marking", [
              "drive", "markings matched / GT", "reachable / GT", "GT lines matched / all",
              "reachable / all", "lane F1 / ceiling", "on seen part / seen, APE (m)"], rows)

    rows = []
    for d in _drives(scenarios, results):
        m = ours(d)
        length = m.get("lane_km")
        rows.append([d, "%s / %s" % (fmt(m.get("lane_unmeasured_length_m"), 1),
                                     fmt(None if length is None else 1000.0 * length, 0)),
                     fmt(m.get("lane_ape_unmeasured_mean_m")),
                     fmt(m.get("lane_ape_measured_mean_m"))])
    table("Table 5d. Lane stretches a join laid across a gap in the line's observations (map.json "
          "`unmeasured`: no pixel measured them), and the lane APE there and elsewhere", [
              "drive", "laid / mapped length (m)", "lane APE laid (m)", "lane APE measured (m)"],
          rows)

    def held(d, key, what=""):
        """' (<what>with the true extrinsic held: x)': the figure a perfect calibration gives
        (Table 3c)."""
        h = results.get((d, "true_extrinsic_held"))
        if h is None or h.get(key) is None:
            return ""
        return " (%swith the true extrinsic held: %s)" % (what, fmt(h[key]))

    def ceiling(m, reachable_key, total_key):
        """' (view ceiling r / n)' when the drive's view caps the figure below its total."""
        if m.get(reachable_key) is None or m.get(reachable_key) == m.get(total_key):
            return ""
        return " (view ceiling %s / %s)" % (m.get(reachable_key), m.get(total_key))

    def seeds(key, digits=3):
        """Per scenario: seeds 1-3 of `key`, and their mean (a single seed's figure moves by
        about 0.01 m with the noise drawn alone: docs/benchmark.md, tenth wave)."""
        out = {}
        for s in SEED_SCENARIOS:
            if s not in scenarios:
                continue
            values = [ours(_seed_drive(s, k)).get(key) for k in (1, 2, 3)
                      if (_seed_drive(s, k), "ours_ppsr") in results]
            text = " / ".join(fmt(v, digits) for v in values)
            known = [v for v in values if v is not None]
            if len(known) > 1:
                text += " (mean %s)" % fmt(sum(known) / len(known), digits)
            out[s] = text
        return out
    rows = []
    if REAL in scenarios:
        m = ours(REAL)
        rows += [[REAL, "crossing recall", "%s / %s%s" % (
                     m.get("marking_matched"), m.get("marking_gt_visible"),
                     ceiling(m, "ceiling_markings_reachable",
                             "marking_gt_visible")), ">= 3 / 4"],
                 [REAL, "crossing center APE (m)", fmt(m.get("marking_ape_mean_m")), "<= 0.30"]]
    elif real_absent:
        rows.append([REAL, "crossing recall / center APE", "skipped: not present", ""])
    if "urban" in scenarios:
        m, ipm = ours("urban"), results[("urban", "ipm")]
        ratio = (ipm["marking_ape_mean_m"] / m["marking_ape_mean_m"]
                 if m.get("marking_ape_mean_m") and ipm.get("marking_ape_mean_m") else None)
        rows += [["urban", "marking recall / false positives",
                  "%s / %d" % (fmt(m.get("marking_recall"), 2), false_positives(m)), ">= 0.95 / 0"],
                 ["urban", "marking APE (m), IPM / Ours", "%s (IPM %s, %sx)%s" % (
                     fmt(m.get("marking_ape_mean_m")), fmt(ipm.get("marking_ape_mean_m")),
                     fmt(ratio, 1), held("urban", "marking_ape_mean_m")),
                  "<= 0.15 and >= 4x below IPM"]]
    if (URBAN_LABELLED, "ours_ppsr") in results:
        m = ours(URBAN_LABELLED)
        rows.append(["urban, vehicles labelled", "marking recall / FP / APE (m)",
                     "%s / %d / %s" % (fmt(m.get("marking_recall"), 2), false_positives(m),
                                       fmt(m.get("marking_ape_mean_m"))),
                     "no target: what urban's unseen occluders cost"])
    if (BLOBS, "ours_ppsr") in results:
        m = ours(BLOBS)
        rows.append(["public_road + 1 blob / frame", "false-positive markings / roll error (deg)",
                     "%d / %s" % (false_positives(m), fmt(_roll_after(m))), "0 / <= 0.10"])
    for s, values in seeds("marking_ape_mean_m").items():
        rows.append([s + " seeds 1-3", "marking APE (m)", values,
                     "no worse than +10 %% (issue: %.3f, seed 1)" % ISSUE_MARKING_APE[s]])
    if "hilly" in scenarios:
        copies = " / ".join(str(false_positives(ours(_seed_drive("hilly", k)))) for k in (1, 2, 3)
                            if (_seed_drive("hilly", k), "ours_ppsr") in results)
        rows.append(["hilly seeds 1-3", "false positives (false copies)", copies, "0"])
    table("Issue 11 (markings), Done-when rows, config/mapper.yaml", ["drive", "figure", "now",
                                                                     "target"], rows)

    rows = []
    if "public_road" in scenarios:
        m = ours("public_road")
        rows.append(["public_road seed 1", "splines per matched line / lane APE (m)", "%s / %s" % (
            fmt(m.get("lane_splines_per_matched_gt_lane"), 2), fmt(m.get("lane_ape_mean_m"))),
            "<= 1.1 / <= 0.045"])
    rows.append(["10 km drive", "splines per matched line / lane APE", "bash scripts/benchmark.sh --long",
                 "<= 1.2 / <= 0.06"])
    if "curvy" in scenarios:
        m = ours("curvy")
        rows.append(["curvy (arcs R 30-60 m)", "lane F1 / splines per line / lane APE (m)",
                     "%s / %s / %s" % (fmt(m.get("lane_f1"), 2),
                                       fmt(m.get("lane_splines_per_matched_gt_lane"), 2),
                                       fmt(m.get("lane_ape_mean_m"))), "1.0 / <= 1.2 / <= 0.06"])
    if (NOISE, "ours_ppsr") in results:
        rows.append(["0.5 m / 0.5 deg odometry", "splines per matched line",
                     fmt(ours(NOISE).get("lane_splines_per_matched_gt_lane"), 2), "<= 1.3"])
    if REAL in scenarios:
        m = ours(REAL)
        cap = ("" if m.get("ceiling_lane_f1") in (None, 1.0) else
               " (view ceiling F1 %s: %s of %s lines)" % (fmt(m.get("ceiling_lane_f1"), 2),
                                                          m.get("ceiling_lanes_reachable"),
                                                          m.get("lane_gt_total")))
        rows.append([REAL, "lane F1 / lane APE (m)", "%s / %s%s%s" % (
            fmt(m.get("lane_f1"), 2), fmt(m.get("lane_ape_mean_m")), cap,
            held(REAL, "lane_ape_mean_m")), ">= 0.9 / <= 0.10"])
    for s, values in seeds("lane_ape_mean_m").items():
        if s == "public_road":
            rows.append([s + " seeds 1-3", "lane APE (m)", values,
                         "no target: how far the seed-1 row moves with the seed"])
        if s in ISSUE_LANE_APE:
            rows.append([s + " seeds 1-3", "lane APE (m)", values,
                         "no worse than +10 %% (issue: %.3f, seed 1)" % ISSUE_LANE_APE[s]])
    order = []
    for s in scenarios:
        lane = [results[(s, c)].get("lane_ape_mean_m") for c in
                ("ours_ppsr", "ours_psr", "ours_ps", "ours_minus")]
        if None not in lane:
            order.append("%s %s" % (s, "yes" if lane == sorted(lane) else "no"))
    rows.append(["every drive", "lane APE order PPSR <= PSR <= +PS <= (-)", ", ".join(order),
                 "holds"])
    table("Issue 12 (lanes), Done-when rows, config/mapper.yaml", ["drive", "figure", "now",
                                                                  "target"], rows)

    rows = []
    drives = [d for d in _drives(scenarios, results)
              if d not in (BLOBS, NOISE, URBAN_LABELLED, CROWN)]
    worse = lambda d, key, slack: (ours(d).get(key) is None or ours(d).get(key) >
                                   ours(d).get(key + "_initial") + slack)
    worse_grid = [d for d in drives if worse(d, "ipm_grid_err_m", 0.0)]
    worse_trans = [d for d in drives if worse(d, "extrinsic_trans_err_m", 0.005)]
    rows.append(["%d benchmark drives" % len(drives), "IPM grid error after > before on",
                 ", ".join(worse_grid) or "none", "none"])
    rows.append(["%d benchmark drives" % len(drives), "translation after > before + 0.005 m on",
                 ", ".join(worse_trans) or "none", "none"])
    for s, values in seeds("ipm_grid_err_m").items():
        if s in ("public_road", "port"):
            rows.append([s + " seeds 1-3", "IPM grid error after (m)", values, "<= 0.05"])
    if "hilly" in scenarios:
        rows.append(["hilly seed 1", "rotation error after (deg)",
                     fmt(ours("hilly").get("extrinsic_rot_err_deg")), "<= 0.15"])
    if (NOISE, "ours_ppsr") in results:
        m = ours(NOISE)
        rows.append(["0.5 m / 0.5 deg odometry, told", "marking APE (m) / corrected yaw (deg)",
                     "%s / %s (input %s)" % (fmt(m.get("marking_ape_mean_m")),
                                             fmt(m.get("pose_yaw_err_deg")),
                                             fmt(m.get("pose_yaw_err_deg_input"))),
                     "<= 0.20 / below the input"])
    if REAL in scenarios:
        m = ours(REAL)
        rows.append([REAL, "rotation (deg) / IPM grid (m) / pose error (m)", "%s / %s / %s%s" % (
            fmt(m.get("extrinsic_rot_err_deg")), fmt(m.get("ipm_grid_err_m")),
            fmt(m.get("pose_trans_err_m")), held(REAL, "pose_trans_err_m", "pose ")),
            "<= 0.30 / <= 0.30 / <= 0.12"])
    rows.append(["live nodelet", "~corrected_odom error vs input",
                 "rostest test_mapper_poses.py (bound 0.62x)",
                 "<= 0.6x the input's"])
    table("Issue 13 (calibration, poses), Done-when rows, config/mapper.yaml",
          ["drive", "figure", "now", "target"], rows)
