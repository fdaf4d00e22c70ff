"""Tables 1, 1b and 1c: the paper's ablation rows on every drive (accuracy, completeness,
markings found and false, lanes in pieces)."""
from ..configs import ABLATIONS, ablation
from ..metrics import false_positives
from ..plan import Request
from ..report import Table, fmt

TITLE = "Map accuracy per ablation (Tables 1, 1b, 1c)"
MODES = ("all",)


def requests(ctx):
    return [Request(ctx.drive(s), ablation(config)) for s in ctx.scenarios
            for _, config in ABLATIONS]


def accuracy(ctx, results):
    header = ["method"]
    for s in ctx.scenarios:
        header += ["%s marking" % s, "%s lane" % s]
    rows = []
    for label, config in ABLATIONS:
        row = [label]
        for s in ctx.scenarios:
            m = results[(s, config)]
            row += [fmt(m.get("marking_ape_mean_m")) + " +- " + fmt(m.get("marking_ape_std_m")),
                    fmt(m.get("lane_ape_mean_m")) + " +- " + fmt(m.get("lane_ape_std_m"))]
        rows.append(row)
    return Table("Table 1. Map accuracy, APE (m), mean +- std", header, rows)


def completeness(ctx, results):
    rows = []
    for label, config in ABLATIONS:
        for s in ctx.scenarios:
            m = results[(s, config)]
            rows.append([label, s, fmt(m.get("marking_recall"), 2), m.get("marking_duplicates"),
                         fmt(m.get("lane_f1"), 2)])
    return Table("Table 1b. Completeness",
                 ["method", "scenario", "marking recall", "duplicates", "lane F1"], rows)


def found_and_false(ctx, results):
    rows = []
    for label, config in ABLATIONS:
        for s in ctx.scenarios:
            m = results[(s, config)]
            rows.append([label, s, "%s / %s" % (m.get("marking_matched"),
                                                m.get("marking_gt_visible")),
                         false_positives(m), fmt(m.get("lane_precision"), 2),
                         fmt(m.get("lane_recall"), 2),
                         fmt(m.get("lane_splines_per_matched_gt_lane"), 2)])
    return Table("Table 1c. Markings found and false, lanes in pieces", [
        "method", "scenario", "markings matched / visible", "false positives", "lane precision",
        "lane recall", "splines per matched GT line"], rows)


def tables(ctx, results):
    return [accuracy(ctx, results), completeness(ctx, results), found_and_false(ctx, results)]
