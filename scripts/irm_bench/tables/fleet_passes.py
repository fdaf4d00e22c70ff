"""The real-geometry fleet passes (<shared>/data/av2_pit_fleet): each pass mapped alone with
plain IPM and with the full method, the data's class table, scored in the pass's own odom
frame (its ground_truth_odom.json); one row per pass, the worst pass and the mean, then the
fleet's target rows. `--fleet-passes` prints this alone."""
import json
import math

from .. import drives, targets
from ..configs import FULL, IPM, ablation
from ..metrics import before_after, ratio
from ..plan import Request
from ..report import Line, Table, arrow, fmt

TITLE = "Real-geometry fleet passes"
MODES = ("all", "fleet-passes")
METHODS = (("Ours (+PPSR) = config/mapper.yaml", FULL), ("plain IPM", IPM))
GROUP = "real-geometry fleet passes"
TURN_DEG = 45.0  # a pass whose heading spans more than this turns
HEADING_SPAN_M = 5.0  # the heading is that of successive chords this long
# Before -> after columns: (column, key, decimals, suffix of the before key).
CHANGES = [("rotation (deg)", "extrinsic_rot_err_deg", 2, "_initial"),
           ("translation (m)", "extrinsic_trans_err_m", 3, "_initial"),
           ("IPM grid (m)", "ipm_grid_err_m", 3, "_initial"),
           ("pose, odometry -> corrected (m)", "pose_trans_err_m", 3, "_input"),
           ("pose, moving frames (m)", "pose_trans_err_moving_m", 3, "_input")]
HEADER = (["pass", "crossings matched / ceiling", "centre APE (m)", "lane F1 / ceiling",
           "lane APE (m)"] + [c[0] for c in CHANGES])


def requests(ctx):
    if not ctx.fleet:
        return []
    return [Request(p, ablation(c)) for p in drives.fleet_passes(ctx) for _, c in METHODS]


def pass_row(label, m):
    return ([label, crossings_cell(m), fmt(m.get("marking_ape_mean_m")), f1_cell(m),
             fmt(m.get("lane_ape_mean_m"))] +
            [before_after(m, key, digits, suffix) for _, key, digits, suffix in CHANGES])


def _mean(values):
    known = [v for v in values if v is not None]
    return sum(known) / len(known) if known else None


def _worst(rows, score):
    """(label, metrics) of the row with the highest score (None scores left out)."""
    scored = [(score(m), label, m) for label, m in rows if score(m) is not None]
    if not scored:
        return None, {}
    _, label, m = max(scored, key=lambda s: s[0])
    return label, m


def _tagged(text, label):
    return "%s (%s)" % (text, label) if label else text


def crossing_shortfall(m):
    """Minus the share of the view ceiling's crossings matched (None without a ceiling)."""
    reachable = m.get("ceiling_markings_reachable")
    return -(m.get("marking_matched") or 0) / reachable if reachable else None


def f1_shortfall(m):
    """Minus the lane F1 over its ceiling (None when either is missing)."""
    share = ratio(m.get("lane_f1"), m.get("ceiling_lane_f1"))
    return None if share is None else -share


def growth(key, suffix):
    """How much an error grew: after / before for the poses (suffix _input), after - before
    for the extrinsic (None when either is missing)."""
    def score(m):
        after, before = m.get(key), m.get(key + suffix)
        if suffix == "_input":
            return ratio(after, before)
        return None if after is None or before is None else after - before
    return score


def crossings_cell(m):
    return "%s / %s" % (m.get("marking_matched"), m.get("ceiling_markings_reachable"))


def f1_cell(m):
    return "%s / %s" % (fmt(m.get("lane_f1"), 2), fmt(m.get("ceiling_lane_f1"), 2))


def worst_row(rows):
    """Each column's worst pass: fewest crossings and lowest F1 against the ceiling, largest
    APE, largest growth of an error."""
    columns = [(crossing_shortfall, crossings_cell),
               (lambda m: m.get("marking_ape_mean_m"), lambda m: fmt(m.get("marking_ape_mean_m"))),
               (f1_shortfall, f1_cell),
               (lambda m: m.get("lane_ape_mean_m"), lambda m: fmt(m.get("lane_ape_mean_m")))]
    columns += [(growth(key, suffix), lambda m, k=key, d=digits, s=suffix: before_after(m, k, d, s))
                for _, key, digits, suffix in CHANGES]
    cells = ["worst"]
    for score, cell in columns:
        label, m = _worst(rows, score)
        cells.append(_tagged(cell(m), label))
    return cells


def mean_row(rows):
    """Crossings summed over the passes; every other column the mean over the passes."""
    ms = [m for _, m in rows]
    total = lambda key: sum(m.get(key) or 0 for m in ms)
    mean = lambda key: _mean([m.get(key) for m in ms])
    return (["mean (crossings: sum)",
             "%d / %d" % (total("marking_matched"), total("ceiling_markings_reachable")),
             fmt(mean("marking_ape_mean_m")),
             "%s / %s" % (fmt(mean("lane_f1"), 2), fmt(mean("ceiling_lane_f1"), 2)),
             fmt(mean("lane_ape_mean_m"))] +
            [arrow(mean(key + suffix), mean(key), digits) for _, key, digits, suffix in CHANGES])


def pass_metrics(passes, results, config):
    return [(drives.pass_label(p), results[(p.name, config)]) for p in passes]


def per_pass_table(label, rows):
    return Table("Fleet passes, each mapped alone: %s (crossings and lanes against the view's "
                 "ceiling; before -> after)" % label, HEADER,
                 [pass_row(name, m) for name, m in rows] + [worst_row(rows), mean_row(rows)])


def heading_change_deg(frames):
    """How far the true path turns: the range (largest minus smallest) of its heading over
    successive chords of HEADING_SPAN_M, unwrapped (deg, from the positions alone); 0 for a
    path shorter than one chord."""
    points = [f["T_map_base_true"]["t"][:2] for f in frames]
    headings, anchor = [], points[0] if points else None
    for p in points[1:]:
        dx, dy = p[0] - anchor[0], p[1] - anchor[1]
        if math.hypot(dx, dy) >= HEADING_SPAN_M:
            heading = math.atan2(dy, dx)
            if headings:  # unwrap against the previous chord
                heading += 2 * math.pi * round((headings[-1] - heading) / (2 * math.pi))
            headings.append(heading)
            anchor = p
    return math.degrees(max(headings) - min(headings)) if headings else 0.0


def turning(drive):
    with open(drive.ground_truth) as f:
        change = heading_change_deg(json.load(f)["frames"])
    return change > TURN_DEG


# The fleet's target rows (targets.yaml, group GROUP) call these ({@name}).

def _full_rows(scope):
    return pass_metrics(drives.fleet_passes(scope.ctx), scope.results, FULL)


def fleet_crossings(scope):
    rows = _full_rows(scope)
    matched = sum(m.get("marking_matched") or 0 for _, m in rows)
    reachable = sum(m.get("ceiling_markings_reachable") or 0 for _, m in rows)
    label, worst = _worst(rows, lambda m: m.get("marking_ape_mean_m"))
    return "%d / %d (%s); centre APE mean %s m, worst %s" % (
        matched, reachable, fmt(ratio(matched, reachable), 2),
        fmt(_mean([m.get("marking_ape_mean_m") for _, m in rows])),
        _tagged(fmt(worst.get("marking_ape_mean_m")) + " m", label))


def fleet_crossings_covered(scope):
    """The GT markings some pass's view reaches, and of those the ones some pass mapped
    (ids are shared by the passes)."""
    reachable, mapped = set(), set()
    for _, m in _full_rows(scope):
        reachable |= {c["gt_id"] for c in m.get("ceiling_markings", []) if c.get("reachable")}
        mapped |= {g["gt_id"] for g in m.get("gt_markings", []) if g.get("matched")}
    return "%d / %d" % (len(reachable & mapped), len(reachable))


def fleet_lanes(scope):
    rows = _full_rows(scope)
    label, m = _worst(rows, f1_shortfall)
    f1 = _tagged("%s of the ceiling" % fmt(ratio(m.get("lane_f1"), m.get("ceiling_lane_f1")), 2),
                 label)
    label, m = _worst(rows, lambda m: m.get("lane_ape_mean_m"))
    return "F1 %s; lane APE %s" % (f1, _tagged(fmt(m.get("lane_ape_mean_m")) + " m", label))


def fleet_worse(scope):
    rows = _full_rows(scope)
    parts = []
    for name, key in (("IPM grid", "ipm_grid_err_m"), ("rotation", "extrinsic_rot_err_deg"),
                      ("translation", "extrinsic_trans_err_m")):
        worse = [label for label, m in rows if m.get(key) is None or
                 m[key] > m.get(key + "_initial", math.inf)]
        parts.append("%s: %s" % (name, ", ".join(worse) or "none"))
    return "; ".join(parts)


def fleet_turning_rotation(scope):
    passes = [p for p in drives.fleet_passes(scope.ctx) if turning(p)]
    if not passes:
        return "no pass turns more than %.0f deg" % TURN_DEG
    rows = pass_metrics(passes, scope.results, FULL)
    label, m = _worst(rows, lambda m: m.get("extrinsic_rot_err_deg"))
    return "%s; turning: %s" % (_tagged(fmt(m.get("extrinsic_rot_err_deg"), 2), label),
                                ", ".join(name for name, _ in rows))


def fleet_pose_ratio(scope):
    score = growth("pose_trans_err_moving_m", "_input")
    label, m = _worst(_full_rows(scope), score)
    return _tagged(fmt(score(m) if m else None, 2), label)


FUNCTIONS = dict(targets.FUNCTIONS, fleet_crossings=fleet_crossings,
                 fleet_crossings_covered=fleet_crossings_covered, fleet_lanes=fleet_lanes,
                 fleet_worse=fleet_worse, fleet_turning_rotation=fleet_turning_rotation,
                 fleet_pose_ratio=fleet_pose_ratio)


def tables(ctx, results):
    if not ctx.fleet:
        return []
    passes = drives.fleet_passes(ctx)
    if not passes:
        return [Line("%s: %s" % (drives.FLEET, ctx.missing(drives.fleet_folder(ctx))))]
    out = [per_pass_table(label, pass_metrics(passes, results, config))
           for label, config in METHODS]
    goals = targets.group_table(ctx, results, targets.load(), GROUP, FUNCTIONS,
                                "Targets: %s (config/mapper.yaml)" % GROUP)
    return out + ([goals] if goals else [])
