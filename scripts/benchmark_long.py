#!/usr/bin/python3
"""The long-drive benchmark (`bash scripts/benchmark.sh --long`): a 10 km drive without images.

Generates config/scenarios/public_road_long.yaml (public_road x 33, cached in
out/benchmark/drives like the other drives), maps it with the full method (config/mapper.yaml)
through `map_from_bag --stats-out` (per frame: cumulative process CPU and RSS) and prints one
table: CPU ms per frame per tenth of the drive, last / first tenth, peak RSS, RSS growth per
km, map bytes per km, start-up time, time taken, and marking / lane APE per sixth of the
drive (the map and the ground truth cropped to each sixth, then evaluate_map on each; the
cropping is long_drive_split.py). With --publish-stats-out (PublishCostProbe) it also prints
the map publication's CPU per publish at 1, 3 and 10 km (median of the publishes measured
just past each km): the delta and changed markers built from the core's incremental export
as the nodelet does and beside them the old whole-map way (fingerprints of every element),
and the core's export time: ExportChanges and the nodelet's snapshot (ExportSnapshot: what
changed built, the rest shared), beside the snapshot as it was (ExportMap without the lane
topology, every element copied), and the publish's and ExportChanges' median per km. Figures are measured and printed; nothing
is asserted.
"""
import bisect
import csv
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import time

import benchmark
import long_drive_split

SCENARIO = "public_road_long"
STATS_HEADER = ["frame", "stamp", "cpu_s", "rss_kb"]
PUBLISH_HEADER = ["km", "frame", "stamp", "markings", "lanes", "changed_elements",
                  "export_changes_ms", "export_snapshot_ms", "publish_ms", "publish_old_ms",
                  "export_snapshot_old_ms"]
PUBLISH_KMS = (1, 3, 10)
# --instructions: the copies of public_road (0-based, of repeat_count) whose frames callgrind
# counts: one in the first tenth of the drive (not the first copy: its start-up), one in the
# middle, the second-last (the last tenth; the last copy holds the end-of-drive work).
INSTRUCTION_COPIES = (1, 16, 31)
TENTHS = 10
SIXTHS = 6


def children_cpu_s():
    """CPU seconds (user + system) of the waited-for children so far."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def timed(step):
    """Runs `step()`; returns (wall s, children CPU s) it took."""
    wall0, cpu0 = time.time(), children_cpu_s()
    step()
    return time.time() - wall0, children_cpu_s() - cpu0


def require_stats_option(args):
    """Exits with a clear message when this map_from_bag has no --stats-out option."""
    binary = os.path.join(args.bin, "map_from_bag")
    result = subprocess.run([binary, "--help"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True)
    if "--stats-out" not in result.stdout:
        sys.exit("benchmark --long: %s has no --stats-out option (the per-frame CPU / RSS CSV "
                 "`frame,stamp,cpu_s,rss_kb`); build a map_from_bag that has it, then rerun."
                 % binary)


def generate_drive(args, drive):
    """Generates the long drive unless cached; returns (wall s, CPU s) of the last generation."""
    scenario = os.path.join(args.repo, "config", "scenarios", SCENARIO + ".yaml")
    timing_path = os.path.join(drive, "generate_time.json")
    stamp = os.path.join(drive, ".key")  # benchmark.generate rewrites it after generating

    def stamp_time():
        return os.path.getmtime(stamp) if os.path.exists(stamp) else None

    before = stamp_time()
    wall, cpu = timed(lambda: benchmark.generate(args, scenario, drive))
    generated = stamp_time() != before
    print("[benchmark] %s: %s" % (SCENARIO, "generated (%.0f s)" % wall if generated
                                  else "the cached drive"), file=sys.stderr)
    if generated or not os.path.exists(timing_path):
        json.dump({"wall_s": wall, "cpu_s": cpu}, open(timing_path, "w"))
    timing = json.load(open(timing_path))
    return timing["wall_s"], timing["cpu_s"]


def read_stats(path):
    """The --stats-out CSV as a list of (frame, stamp, cpu_s, rss_kb), checked."""
    with open(path) as f:
        rows = list(csv.reader(f))
    if not rows or rows[0] != STATS_HEADER:
        sys.exit("benchmark --long: %s: expected the header %s, got %s"
                 % (path, ",".join(STATS_HEADER), ",".join(rows[0]) if rows else "nothing"))
    stats = [(int(r[0]), float(r[1]), float(r[2]), float(r[3])) for r in rows[1:] if r]
    if len(stats) < 2 * TENTHS:
        sys.exit("benchmark --long: %s: only %d rows" % (path, len(stats)))
    return stats


def cpu_ms_per_frame_by_part(stats, distances_m, total_m, parts):
    """CPU ms per frame in each of `parts` equal distance ranges, from the cpu_s deltas.

    A row's CPU is the cumulative process CPU after its frame, so the cost of a part is the
    CPU at its last row minus the CPU at the last row before it, divided by the frames in
    between (frame numbers, so rows may be sparser than frames); the first row is only the
    baseline (its CPU includes the start-up).
    """
    last_row = [None] * parts
    for i, d in enumerate(distances_m):
        last_row[min(parts - 1, max(0, int(parts * d / total_m)))] = i
    result = []
    previous = 0
    for part in range(parts):
        row = last_row[part]
        if row is None or stats[row][0] <= stats[previous][0]:
            result.append(None)
            continue
        result.append(1e3 * (stats[row][2] - stats[previous][2]) / (stats[row][0] - stats[previous][0]))
        previous = row
    return result


def slope(xs, ys):
    """Least-squares slope of ys over xs."""
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else None


def startup_s(log_path):
    """The `startup_s` map_from_bag's summary prints (None when it does not)."""
    match = re.search(r"startup_s\D{0,3}([0-9.]+)", open(log_path).read())
    return float(match.group(1)) if match else None


def map_drive(args, drive, out):
    """Maps the drive with config/mapper.yaml and --stats-out; returns (wall s, CPU s)."""
    os.makedirs(out, exist_ok=True)
    return timed(lambda: benchmark.run(
        [os.path.join(args.bin, "map_from_bag"), "--bag", os.path.join(drive, "drive.bag"),
         "--config", os.path.join(args.repo, "config", "mapper.yaml"), "--out", out,
         "--stats-out", os.path.join(out, "stats.csv"),
         "--publish-stats-out", os.path.join(out, "publish.csv")], os.path.join(out, "map.log")))


def read_publish_stats(path):
    """The --publish-stats-out CSV as a list of dicts (None when the file is absent)."""
    if not os.path.exists(path):
        return None
    with open(path) as f:
        rows = list(csv.reader(f))
    if not rows or rows[0] != PUBLISH_HEADER:
        sys.exit("benchmark --long: %s: expected the header %s" % (path, ",".join(PUBLISH_HEADER)))
    return [dict(zip(PUBLISH_HEADER, map(float, r))) for r in rows[1:] if r]


def median(values):
    """The median of `values` (None when empty)."""
    values = sorted(values)
    n = len(values)
    if n == 0:
        return None
    return values[n // 2] if n % 2 else 0.5 * (values[n // 2 - 1] + values[n // 2])


def publish_rows(publish):
    """Table rows: the publication's CPU per publish near 1, 3 and 10 km (those the drive
    reached: its last whole km stands in for a larger one)."""
    if not publish:
        return []
    reached = int(max(r["km"] for r in publish))
    kms = sorted({min(km, reached) for km in PUBLISH_KMS if min(km, reached) >= 1})
    parts = {km: [r for r in publish if int(r["km"]) == km] for km in kms}
    fmt = benchmark.fmt

    def column(key):
        return " / ".join(fmt(median([r[key] for r in parts[km]]), 3) for km in kms)

    def per_km(key):
        every = sorted({int(r["km"]) for r in publish})
        return " ".join(fmt(median([r[key] for r in publish if int(r["km"]) == km]), 3)
                        for km in every)

    label = "/".join(str(km) for km in kms)
    counts = " / ".join(str(len(parts[km])) for km in kms)
    elements = " / ".join(fmt(median([r["markings"] + r["lanes"] for r in parts[km]]), 0)
                          for km in kms)
    return [["publish CPU per publish at %s km (delta + markers)" % label,
             "%s ms (old whole-map way %s ms)" % (column("publish_ms"), column("publish_old_ms"))],
            ["core export per publish at %s km: ExportChanges / snapshot" % label,
             "%s ms / %s ms (whole-copy snapshot %s ms)" % (
                 column("export_changes_ms"), column("export_snapshot_ms"),
                 column("export_snapshot_old_ms"))],
            ["publishes measured / map elements at %s km" % label, "%s / %s" % (counts, elements)],
            ["publish / ExportChanges CPU, median per km (1, 2, ...)",
             "%s ms / %s ms" % (per_km("publish_ms"), per_km("export_changes_ms"))]]


def evaluate(args, map_path, gt_path, metrics_path):
    """evaluate_map on one map / ground-truth pair; returns the metrics."""
    benchmark.run([os.path.join(args.bin, "evaluate_map"), "--map", map_path, "--ground-truth",
                   gt_path, "--json", metrics_path], metrics_path + ".log")
    return json.load(open(metrics_path))


def evaluate_sixths(args, split, out):
    """Marking / lane APE and marking recall of the map restricted to each sixth."""
    rows = []
    for part, (d0, d1) in enumerate(long_drive_split.equal_parts(split.index.total_m, SIXTHS)):
        base = os.path.join(out, "sixth_%d" % (part + 1))
        json.dump(split.ground_truth_part(d0, d1), open(base + "_ground_truth.json", "w"))
        json.dump(split.map_part(d0, d1), open(base + "_map.json", "w"))
        m = evaluate(args, base + "_map.json", base + "_ground_truth.json", base + "_metrics.json")
        inside = split.marking_ids_inside(d0, d1)
        visible = [g for g in m.get("gt_markings", [])
                   if g["gt_id"] in inside and g["visible_frames"] > 0]
        matched = sum(1 for g in visible if g["matched"])
        rows.append((d0, d1, m.get("marking_ape_mean_m"), m.get("lane_ape_mean_m"),
                     matched / len(visible) if visible else None))
    return rows


def repeat_count(args):
    """The long scenario's repeat_count (copies of public_road's route)."""
    text = open(os.path.join(args.repo, "config", "scenarios", SCENARIO + ".yaml")).read()
    match = re.search(r"^repeat_count:\s*(\d+)", text, re.M)
    if not match:
        sys.exit("benchmark --long: %s.yaml has no repeat_count" % SCENARIO)
    return int(match.group(1))


def copy_spans(index, copies, count):
    """Stamp spans "t0:t1" of whole copies of the route, by distance driven: copy k is the
    distance range [k, k + 1) * total / count; t0 and t1 are the stamps of the first frames
    at or past its two ends (map_from_bag counts the frames after t0 up to t1)."""
    spans = []
    for k in copies:
        ends = [min(len(index.stamps) - 1, bisect.bisect_left(index.distance_m, d))
                for d in (k * index.total_m / count, (k + 1) * index.total_m / count)]
        spans.append("%.6f:%.6f" % (index.stamps[ends[0]], index.stamps[ends[1]]))
    return spans


def read_callgrind_dumps(folder):
    """(span, frames, instructions) of each callgrind dump map_from_bag --callgrind-spans
    wrote: its `desc: Trigger: Client Request: span <k> frames <n> ...` line and its
    `totals:` line (instructions, Ir: the sum of the dump's cost lines; its `summary:` line is
    not used, callgrind derives it by subtraction, which CALLGRIND_ZERO_STATS upsets), sorted
    by span."""
    result = []
    for name in sorted(os.listdir(folder)):
        if not name.startswith("callgrind.out"):
            continue
        text = open(os.path.join(folder, name), errors="replace").read()
        trigger = re.search(r"^desc: Trigger: Client Request: span (\d+) frames (\d+)", text, re.M)
        total = re.search(r"^totals:\s*(\d+)", text, re.M)
        if trigger and total:
            result.append((int(trigger.group(1)), int(trigger.group(2)), int(total.group(1))))
    return sorted(result)


def instruction_rows(args, drive, out_root):
    """Instructions per frame of INSTRUCTION_COPIES, counted by callgrind (map_from_bag
    --callgrind-spans under valgrind --tool=callgrind --instr-atstart=no): a cost figure the
    machine's load does not move, beside the CPU seconds per tenth. Table rows."""
    if not shutil.which("valgrind"):
        sys.exit("benchmark --long --instructions: valgrind is not installed "
                 "(apt-get install valgrind; scripts/setup.sh installs it)")
    out = os.path.join(out_root, "maps", SCENARIO, "callgrind")
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    gt = json.load(open(os.path.join(drive, "ground_truth.json")))
    index = long_drive_split.DriveIndex(gt["frames"])
    count = repeat_count(args)
    spans = copy_spans(index, INSTRUCTION_COPIES, count)
    print("[benchmark] %s: counting instructions of copies %s under callgrind (slow: valgrind "
          "runs map_from_bag 20-30x slower than natively, hours for the 10 km drive)"
          % (SCENARIO, ", ".join(str(k + 1) for k in INSTRUCTION_COPIES)), file=sys.stderr)
    wall, _ = timed(lambda: benchmark.run(
        ["valgrind", "--tool=callgrind", "--instr-atstart=no",
         "--callgrind-out-file=" + os.path.join(out, "callgrind.out.%p"),
         os.path.join(args.bin, "map_from_bag"), "--bag", os.path.join(drive, "drive.bag"),
         "--config", os.path.join(args.repo, "config", "mapper.yaml"), "--out", out,
         "--callgrind-spans", ",".join(spans)], os.path.join(out, "map.log")))
    dumps = read_callgrind_dumps(out)
    if len(dumps) != len(spans) or any(frames == 0 for _, frames, _ in dumps):
        sys.exit("benchmark --long --instructions: expected %d callgrind dumps with frames in %s, "
                 "found %s" % (len(spans), out, dumps))
    per_frame = [instructions / frames / 1e6 for _, frames, instructions in dumps]
    km = [index.distance_m[bisect.bisect_left(index.stamps, float(s.split(":")[0]))] / 1e3 +
          index.total_m / count / 2e3 for s in spans]
    fmt = benchmark.fmt
    return [["instructions / frame, copies %s at %s km (callgrind, %s frames)" % (
                 " / ".join(str(k + 1) for k in INSTRUCTION_COPIES),
                 " / ".join(fmt(d, 1) for d in km),
                 " / ".join(str(frames) for _, frames, _ in dumps)),
             "%s M (valgrind run %.0f s)" % (" / ".join(fmt(x, 1) for x in per_frame), wall)],
            ["instructions / frame, last copy counted / first", fmt(per_frame[-1] / per_frame[0], 2)]]


def main(args, out_root):
    """The long-drive benchmark; prints its table."""
    require_stats_option(args)
    drive = os.path.join(out_root, "drives", SCENARIO)
    out = os.path.join(out_root, "maps", SCENARIO, "mapper")
    print("[benchmark] %s: generating unless cached (the scenario and the generator's build)"
          % SCENARIO, file=sys.stderr)
    gen_wall, gen_cpu = generate_drive(args, drive)
    print("[benchmark] %s: mapping (config/mapper.yaml)" % SCENARIO, file=sys.stderr)
    map_wall, map_cpu = map_drive(args, drive, out)
    extra = instruction_rows(args, drive, out_root) if args.instructions else []
    report(args, drive, out, (gen_wall, gen_cpu), (map_wall, map_cpu), extra)


def report(args, drive, out, generate_time, map_time, extra_rows=()):
    """Evaluates a mapped long drive (map.json, stats.csv, map.log in `out`); prints the table."""
    (gen_wall, gen_cpu), (map_wall, map_cpu) = generate_time, map_time
    print("[benchmark] %s: evaluating" % SCENARIO, file=sys.stderr)
    gt_path = os.path.join(drive, "ground_truth.json")
    map_path = os.path.join(out, "map.json")
    whole = evaluate(args, map_path, gt_path, os.path.join(out, "metrics.json"))
    gt = json.load(open(gt_path))
    split = long_drive_split.DriveSplit(gt, json.load(open(map_path)))
    index = split.index
    stats = read_stats(os.path.join(out, "stats.csv"))
    distances = [index.distance_at_stamp(row[1]) for row in stats]
    total_km = index.total_m / 1e3
    tenths = cpu_ms_per_frame_by_part(stats, distances, index.total_m, TENTHS)
    sixths = evaluate_sixths(args, split, out)
    fmt = benchmark.fmt

    rows = [["drive", "%.2f km, %d frames, no images" % (total_km, len(gt["frames"]))],
            ["generate (wall / CPU)", "%s s / %s s" % (fmt(gen_wall, 1), fmt(gen_cpu, 1))],
            ["map_from_bag (wall / CPU)", "%s s / %s s" % (fmt(map_wall, 1), fmt(map_cpu, 1))],
            ["start-up", "%s s" % fmt(startup_s(os.path.join(out, "map.log")), 2)]]
    for k, ms in enumerate(tenths):
        rows.append(["CPU ms / frame, tenth %d (%.1f-%.1f km)"
                     % (k + 1, k * total_km / TENTHS, (k + 1) * total_km / TENTHS), fmt(ms, 2)])
    ratio = tenths[-1] / tenths[0] if tenths[0] and tenths[-1] is not None else None
    rows.append(["CPU last tenth / first tenth", fmt(ratio, 2)])
    rows += list(extra_rows)
    rss_mb = [row[3] / 1024.0 for row in stats]
    rows.append(["peak RSS", "%s MB" % fmt(max(rss_mb), 1)])
    growth = slope([d / 1e3 for d in distances], rss_mb)
    rows.append(["RSS growth (least squares over distance)", "%s MB/km" % fmt(growth, 2)])
    map_bytes = os.path.getsize(map_path)
    rows.append(["map bytes / km of drive", "%s (map.json %.2f MB)"
                 % (fmt(map_bytes / total_km, 0), map_bytes / 1e6)])
    rows.append(["map bytes / km of lane", fmt(whole.get("map_bytes_per_km"), 0)])
    md = split.map.get("metadata", {})
    rows.append(["front end p50 / p95 (whole drive)", "%s / %s ms" % (
        fmt(md.get("frontend_time_p50_ms"), 2), fmt(md.get("frontend_time_p95_ms"), 2))])
    solve = [1e3 * md[k] if k in md else None
             for k in ("backend_solve_time_p50_s", "backend_solve_time_p95_s")]
    rows.append(["window solve p50 / p95 (whole drive)", "%s / %s ms, %s solves" % (
        fmt(solve[0], 1), fmt(solve[1], 1), md.get("backend_solves", "-"))])
    rows.append(["marking / lane APE, whole drive", "%s / %s m" % (
        fmt(whole.get("marking_ape_mean_m")), fmt(whole.get("lane_ape_mean_m")))])
    rows.append(["splines per matched GT line / lane F1, whole drive", "%s / %s" % (
        fmt(whole.get("lane_splines_per_matched_gt_lane"), 2), fmt(whole.get("lane_f1"), 2))])
    for k, (d0, d1, marking, lane, recall) in enumerate(sixths):
        rows.append(["marking / lane APE, sixth %d (%.1f-%.1f km)" % (k + 1, d0 / 1e3, d1 / 1e3),
                     "%s / %s m (marking recall %s)" % (fmt(marking), fmt(lane), fmt(recall, 2))])
    rows += publish_rows(read_publish_stats(os.path.join(out, "publish.csv")))
    benchmark.table("Long drive: %s, config/mapper.yaml, seed 1" % SCENARIO,
                    ["quantity", "value"], rows)
    json.dump({"rows": rows}, open(os.path.join(out, "long_results.json"), "w"), indent=1)
    print("\n[benchmark] long-drive outputs: %s" % out)
