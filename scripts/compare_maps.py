#!/usr/bin/python3
"""Compares two maps of the same drive (e.g. one made live by the nodelet, one offline by
map_from_bag) and says whether they agree within tolerances.

usage: compare_maps.py A.json B.json [--gate-m 1.0] [--max-center-mean-m 0.3]
                       [--min-matched 0.7] [--max-lane-mean-m 0.3] [--lane-cover-m 0.5]
                       [--min-lane-cover 0.7] [--max-extrinsic-deg 0.5]
                       [--max-extrinsic-m 0.05] [--max-pose-mean-m 0.3] [--json out.json]

Markings: each marking of one map is matched to the nearest marking of the same class in
the other (center = mean of the 4 corners, xy distance, within --gate-m), both ways; the
maps agree when at least --min-matched of each map's markings are matched and the mean
center distance over the matches is at most --max-center-mean-m.
Lanes: the splines of each map.json are sampled about every 0.5 m (uniform Catmull-Rom,
phantom ends excluded, as docs/file_formats.md defines them); for every sample of one map, the distance to the nearest
sample of the other. The maps agree when the mean distance is at most --max-lane-mean-m
both ways, and at least --min-lane-cover of each map's samples lie within --lane-cover-m
of the other map.
Extrinsic and poses (no association needed, so duplicates in either map cannot hide a
shift): the refined T_base_cam of the two maps may differ by at most --max-extrinsic-deg
and --max-extrinsic-m; the corrected trajectories, matched by stamp (at least 90% of the
shorter one), by at most --max-pose-mean-m of translation on average.
Exit status 0 when the maps agree, 1 when they do not, 2 on bad input.
"""
import argparse
import json
import math
import os
import sys


def quaternion_angle_deg(qa, qb):
    """Angle (deg) of the rotation between two unit quaternions [x, y, z, w]."""
    dot = abs(sum(a * b for a, b in zip(qa, qb)))
    return math.degrees(2.0 * math.acos(min(1.0, dot)))


def spline_samples(control_points, step_m=0.5):
    """(x, y) about every step_m along a uniform Catmull-Rom spline (phantom ends excluded)."""
    samples = []
    for i in range(len(control_points) - 3):
        c0, c1, c2, c3 = (control_points[i + k][:2] for k in range(4))
        count = max(2, int(math.ceil(math.dist(c1, c2) / step_m)) + 1)
        for j in range(0 if i == 0 else 1, count):
            u = j / (count - 1.0)
            samples.append(tuple(
                0.5 * (2 * b + (c - a) * u + (2 * a - 5 * b + 4 * c - d) * u * u +
                       (3 * b - 3 * c + d - a) * u ** 3)
                for a, b, c, d in zip(c0, c1, c2, c3)))
    return samples


def load(path):
    """(markings [(class_id, (x, y))], lane samples [(x, y)], map json) of a map.json."""
    with open(path) as f:
        m = json.load(f)
    markings = []
    for k in m["markings"]:
        xs = [c[0] for c in k["corners"]]
        ys = [c[1] for c in k["corners"]]
        markings.append((k["class_id"], (sum(xs) / 4.0, sum(ys) / 4.0)))
    samples = []
    for lane in m["lanes"]:
        samples.extend(spline_samples(lane["control_points"]))
    return markings, samples, m


def compare_poses(a, b, args, report, failures):
    """Refined extrinsic and corrected trajectory of map jsons a and b."""
    ta, tb = a["T_base_cam"], b["T_base_cam"]
    report["extrinsic_diff_deg"] = quaternion_angle_deg(ta["q_xyzw"], tb["q_xyzw"])
    report["extrinsic_diff_m"] = math.dist(ta["t"], tb["t"])
    if report["extrinsic_diff_deg"] > args.max_extrinsic_deg:
        failures.append("refined extrinsics differ by %.3f deg > %.3f"
                        % (report["extrinsic_diff_deg"], args.max_extrinsic_deg))
    if report["extrinsic_diff_m"] > args.max_extrinsic_m:
        failures.append("refined extrinsics differ by %.3f m > %.3f"
                        % (report["extrinsic_diff_m"], args.max_extrinsic_m))
    poses_b = {round(p["stamp"], 6): p["t"] for p in b.get("trajectory", [])}
    diffs = [math.dist(p["t"], poses_b[round(p["stamp"], 6)]) for p in a.get("trajectory", [])
             if round(p["stamp"], 6) in poses_b]
    shorter = min(len(a.get("trajectory", [])), len(b.get("trajectory", [])))
    report["poses_matched"] = len(diffs)
    report["pose_diff_mean_m"] = sum(diffs) / len(diffs) if diffs else None
    if shorter and len(diffs) < 0.9 * shorter:
        failures.append("only %d of %d poses share a stamp" % (len(diffs), shorter))
    if diffs and report["pose_diff_mean_m"] > args.max_pose_mean_m:
        failures.append("corrected poses differ by %.3f m on average > %.3f"
                        % (report["pose_diff_mean_m"], args.max_pose_mean_m))


def nearest(point, points):
    best = math.inf
    for q in points:
        best = min(best, math.hypot(point[0] - q[0], point[1] - q[1]))
    return best


def match_markings(a, b, gate):
    """Distances of the markings of a matched in b (same class, nearest within the gate)."""
    distances = []
    for class_id, center in a:
        candidates = [c for k, c in b if k == class_id]
        d = nearest(center, candidates) if candidates else math.inf
        if d <= gate:
            distances.append(d)
    return distances


def lane_stats(a, b, cover_m):
    """(mean nearest distance, fraction within cover_m) of samples a against samples b."""
    if not a:
        return None, None
    if not b:
        return math.inf, 0.0
    distances = [nearest(p, b) for p in a]
    return sum(distances) / len(distances), sum(d <= cover_m for d in distances) / len(distances)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("a")
    parser.add_argument("b")
    parser.add_argument("--gate-m", type=float, default=1.0)
    parser.add_argument("--max-center-mean-m", type=float, default=0.3)
    parser.add_argument("--min-matched", type=float, default=0.7)
    parser.add_argument("--max-lane-mean-m", type=float, default=0.3)
    parser.add_argument("--lane-cover-m", type=float, default=0.5)
    parser.add_argument("--min-lane-cover", type=float, default=0.7)
    parser.add_argument("--max-extrinsic-deg", type=float, default=0.5)
    parser.add_argument("--max-extrinsic-m", type=float, default=0.05)
    parser.add_argument("--max-pose-mean-m", type=float, default=0.3)
    parser.add_argument("--json")
    args = parser.parse_args()
    try:
        markings_a, lanes_a, json_a = load(args.a)
        markings_b, lanes_b, json_b = load(args.b)
    except (OSError, ValueError, KeyError) as e:
        print("compare_maps: error: %s" % e, file=sys.stderr)
        return 2

    report = {"a": args.a, "b": args.b, "markings_a": len(markings_a),
              "markings_b": len(markings_b), "lane_samples_a": len(lanes_a),
              "lane_samples_b": len(lanes_b)}
    failures = []
    ab = match_markings(markings_a, markings_b, args.gate_m)
    ba = match_markings(markings_b, markings_a, args.gate_m)
    report["markings_matched_a"] = len(ab) / len(markings_a) if markings_a else None
    report["markings_matched_b"] = len(ba) / len(markings_b) if markings_b else None
    both = ab + ba
    report["marking_center_mean_m"] = sum(both) / len(both) if both else None
    report["marking_center_max_m"] = max(both) if both else None
    if bool(markings_a) != bool(markings_b):
        failures.append("one map has markings, the other none")
    for key in ("markings_matched_a", "markings_matched_b"):
        if report[key] is not None and report[key] < args.min_matched:
            failures.append("%s %.2f < %.2f" % (key, report[key], args.min_matched))
    if both and report["marking_center_mean_m"] > args.max_center_mean_m:
        failures.append("marking center mean %.3f m > %.3f m"
                        % (report["marking_center_mean_m"], args.max_center_mean_m))

    for name, x, y in (("a", lanes_a, lanes_b), ("b", lanes_b, lanes_a)):
        mean, cover = lane_stats(x, y, args.lane_cover_m)
        report["lane_mean_m_" + name] = mean
        report["lane_cover_" + name] = cover
        if mean is None:
            continue
        if mean > args.max_lane_mean_m:
            failures.append("lane samples of %s: mean distance %.3f m > %.3f m"
                            % (name, mean, args.max_lane_mean_m))
        if cover < args.min_lane_cover:
            failures.append("lane samples of %s: %.2f within %.2f m < %.2f"
                            % (name, cover, args.lane_cover_m, args.min_lane_cover))
    if bool(lanes_a) != bool(lanes_b):
        failures.append("one map has lanes, the other none")
    compare_poses(json_a, json_b, args, report, failures)
    report["agree"] = not failures
    report["failures"] = failures

    def fmt(v, unit=""):
        return "n/a" if v is None else ("%.3f%s" % (v, unit))
    print("markings: %d vs %d; matched %s / %s; center distance mean %s, max %s"
          % (len(markings_a), len(markings_b), fmt(report["markings_matched_a"]),
             fmt(report["markings_matched_b"]), fmt(report["marking_center_mean_m"], " m"),
             fmt(report["marking_center_max_m"], " m")))
    print("lanes: %d vs %d samples; mean distance %s / %s; within %.2f m %s / %s"
          % (len(lanes_a), len(lanes_b), fmt(report["lane_mean_m_a"], " m"),
             fmt(report["lane_mean_m_b"], " m"), args.lane_cover_m,
             fmt(report["lane_cover_a"]), fmt(report["lane_cover_b"])))
    print("extrinsic: %s, %s apart; poses: %d share a stamp, %s apart on average"
          % (fmt(report["extrinsic_diff_deg"], " deg"), fmt(report["extrinsic_diff_m"], " m"),
             report["poses_matched"], fmt(report["pose_diff_mean_m"], " m")))
    print("maps agree" if not failures else "maps differ: " + "; ".join(failures))
    if args.json:
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
        with open(args.json, "w") as f:
            json.dump(report, f, indent=1)
    return 0 if not failures else 1


if __name__ == "__main__":
    sys.exit(main())
