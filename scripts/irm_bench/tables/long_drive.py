"""The long drive (`--long`): config/scenarios/public_road_long.yaml (public_road x 33, about
10 km, no camera images) mapped with the full method through `map_from_bag --stats-out`: CPU
ms per frame per tenth of the drive, peak RSS and its growth per km, map bytes per km,
start-up, marking / lane APE per sixth (long_split.py), the map publication's CPU per publish
at 1, 3 and 10 km (with --publish-stats-out), the unload after the whole drive
(ros_test_long_drive_unload) and, with --instructions, instructions per frame (callgrind)."""
import bisect
import json
import os
import resource
import shutil
import subprocess
import sys
import time

from .. import drives, long_split, long_stats, unload
from ..report import Line, Table, fmt
from ..runners import BenchmarkError, evaluate, load_yaml, run

TITLE = "Long drive (`--long`)"
MODES = ("long",)
TENTHS = 10
SIXTHS = 6
PUBLISH_KMS = (1, 3, 10)
# --instructions: the copies of public_road (0-based, of repeat_count) whose frames callgrind
# counts: one in the first tenth of the drive (not the first copy: its start-up), one in the
# middle, the second-last (the last tenth; the last copy holds the end-of-drive work).
INSTRUCTION_COPIES = (1, 16, 31)


def requests(ctx):
    return []  # mapped here, with the per-frame statistics on


def children_cpu_s():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def timed(step):
    """Runs `step()`; returns (wall s, CPU s of the children it waited for)."""
    wall0, cpu0 = time.time(), children_cpu_s()
    step()
    return time.time() - wall0, children_cpu_s() - cpu0


def map_from_bag_options(ctx):
    """map_from_bag's --help; an error when it has no --stats-out."""
    binary = os.path.join(ctx.bin, "map_from_bag")
    result = subprocess.run([binary, "--help"], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    if "--stats-out" not in result.stdout:
        raise BenchmarkError("%s has no --stats-out option (the per-frame CPU / RSS CSV "
                             "`frame,stamp,cpu_s,rss_kb`); build one that has it, then rerun"
                             % binary)
    return result.stdout


def generate_drive(ctx, drive):
    """Generates the long drive unless cached; (wall s, CPU s) of its last generation."""
    timing_path = os.path.join(drive.folder, "generate_time.json")
    generated = []
    wall, cpu = timed(lambda: generated.append(drive.prepare(ctx.bin)))
    print("[benchmark] %s: %s" % (drives.LONG, "generated (%.0f s)" % wall if generated[0]
                                  else "the cached drive"), file=sys.stderr)
    if generated[0] or not os.path.exists(timing_path):
        with open(timing_path, "w") as f:
            json.dump({"wall_s": wall, "cpu_s": cpu}, f)
    with open(timing_path) as f:
        timing = json.load(f)
    return timing["wall_s"], timing["cpu_s"]


def map_drive(ctx, drive, out, help_text):
    """Maps the drive with config/mapper.yaml and --stats-out; returns (wall s, CPU s)."""
    os.makedirs(out, exist_ok=True)
    command = [os.path.join(ctx.bin, "map_from_bag"), "--bag", drive.bag, "--config",
               os.path.join(ctx.repo, "config", "mapper.yaml"), "--out", out,
               "--stats-out", os.path.join(out, "stats.csv")]
    if "--publish-stats-out" in help_text:
        command += ["--publish-stats-out", os.path.join(out, "publish.csv")]
    return run(command, os.path.join(out, "map.log"))


def publish_rows(publish):
    """The publication's CPU per publish near 1, 3 and 10 km (those the drive reached: its
    last whole km stands in for a larger one)."""
    if not publish:
        return []
    reached = int(max(r["km"] for r in publish))
    kms = sorted({min(km, reached) for km in PUBLISH_KMS if min(km, reached) >= 1})
    parts = {km: [r for r in publish if int(r["km"]) == km] for km in kms}

    def column(key):
        return " / ".join(fmt(long_stats.median([r[key] for r in parts[km]]), 3) for km in kms)

    def per_km(key):
        every = sorted({int(r["km"]) for r in publish})
        return " ".join(fmt(long_stats.median([r[key] for r in publish if int(r["km"]) == km]),
                            3) for km in every)

    label = "/".join(str(km) for km in kms)
    counts = " / ".join(str(len(parts[km])) for km in kms)
    elements = " / ".join(fmt(long_stats.median([r["markings"] + r["lanes"] for r in parts[km]]),
                              0) for km in kms)
    return [["publish CPU per publish at %s km (delta + markers)" % label,
             "%s ms" % column("publish_ms")],
            ["core export per publish at %s km: ExportChanges / snapshot" % label,
             "%s ms / %s ms" % (column("export_changes_ms"), column("export_snapshot_ms"))],
            ["publishes measured / map elements at %s km" % label, "%s / %s" % (counts, elements)],
            ["publish / ExportChanges CPU, median per km (1, 2, ...)",
             "%s ms / %s ms" % (per_km("publish_ms"), per_km("export_changes_ms"))]]


def evaluate_sixths(ctx, split, out):
    """Marking / lane APE and marking recall of the map restricted to each sixth."""
    rows = []
    for part, (d0, d1) in enumerate(long_split.equal_parts(split.index.total_m, SIXTHS)):
        base = os.path.join(out, "sixth_%d" % (part + 1))
        with open(base + "_ground_truth.json", "w") as f:
            json.dump(split.ground_truth_part(d0, d1), f)
        with open(base + "_map.json", "w") as f:
            json.dump(split.map_part(d0, d1), f)
        m = evaluate(ctx.bin, base + "_map.json", base + "_ground_truth.json",
                     base + "_metrics.json")
        inside = split.marking_ids_inside(d0, d1)
        visible = [g for g in m.get("gt_markings", [])
                   if g["gt_id"] in inside and g["visible_frames"] > 0]
        matched = sum(1 for g in visible if g["matched"])
        rows.append((d0, d1, m.get("marking_ape_mean_m"), m.get("lane_ape_mean_m"),
                     matched / len(visible) if visible else None))
    return rows


def instruction_rows(ctx, drive):
    """Instructions per frame of INSTRUCTION_COPIES counted by callgrind (map_from_bag
    --callgrind-spans under valgrind --tool=callgrind --instr-atstart=no): a cost the
    machine's load does not move."""
    if not shutil.which("valgrind"):
        raise BenchmarkError("--instructions: valgrind is not installed (apt-get install "
                             "valgrind; scripts/setup.sh installs it)")
    out = os.path.join(ctx.out, "maps", drives.LONG, "callgrind")
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    with open(drive.ground_truth) as f:
        index = long_split.DriveIndex(json.load(f)["frames"])
    count = load_yaml(drive.scenario).get("repeat_count")
    if not isinstance(count, int):
        raise BenchmarkError("%s has no repeat_count" % drive.scenario)
    spans = long_stats.copy_spans(index, INSTRUCTION_COPIES, count)
    print("[benchmark] %s: counting instructions of copies %s under callgrind (hours: valgrind "
          "runs map_from_bag 20-30x slower than natively)" % (
              drives.LONG, ", ".join(str(k + 1) for k in INSTRUCTION_COPIES)), file=sys.stderr)
    wall, _ = run(["valgrind", "--tool=callgrind", "--instr-atstart=no",
                   "--callgrind-out-file=" + os.path.join(out, "callgrind.out.%p"),
                   os.path.join(ctx.bin, "map_from_bag"), "--bag", drive.bag, "--config",
                   os.path.join(ctx.repo, "config", "mapper.yaml"), "--out", out,
                   "--callgrind-spans", ",".join(spans)], os.path.join(out, "map.log"))
    dumps = long_stats.read_callgrind_dumps(out)
    if len(dumps) != len(spans) or any(frames == 0 for _, frames, _ in dumps):
        raise BenchmarkError("--instructions: expected %d callgrind dumps with frames in %s, "
                             "found %s" % (len(spans), out, dumps))
    per_frame = [instructions / frames / 1e6 for _, frames, instructions in dumps]
    km = [index.distance_m[bisect.bisect_left(index.stamps, float(s.split(":")[0]))] / 1e3 +
          index.total_m / count / 2e3 for s in spans]
    return [["instructions / frame, copies %s at %s km (callgrind, %s frames)" % (
                 " / ".join(str(k + 1) for k in INSTRUCTION_COPIES),
                 " / ".join(fmt(d, 1) for d in km),
                 " / ".join(str(frames) for _, frames, _ in dumps)),
             "%s M (valgrind run %.0f s)" % (" / ".join(fmt(x, 1) for x in per_frame), wall)],
            ["instructions / frame, last copy counted / first",
             fmt(per_frame[-1] / per_frame[0], 2)]]


def report_rows(ctx, drive, out, generate_time, map_time):
    """The table's rows of a mapped long drive (map.json, stats.csv, map.log in `out`)."""
    print("[benchmark] %s: evaluating" % drives.LONG, file=sys.stderr)
    map_path = os.path.join(out, "map.json")
    whole = evaluate(ctx.bin, map_path, drive.ground_truth, os.path.join(out, "metrics.json"))
    with open(drive.ground_truth) as f:
        gt = json.load(f)
    with open(map_path) as f:
        split = long_split.DriveSplit(gt, json.load(f))
    index = split.index
    stats = long_stats.read_stats(os.path.join(out, "stats.csv"))
    distances = [index.distance_at_stamp(row[1]) for row in stats]
    total_km = index.total_m / 1e3
    tenths = long_stats.cpu_ms_per_frame_by_part(stats, distances, index.total_m, TENTHS)
    (gen_wall, gen_cpu), (map_wall, map_cpu) = generate_time, map_time
    rows = [["drive", "%.2f km, %d frames, no images" % (total_km, len(gt["frames"]))],
            ["generate (wall / CPU)", "%s s / %s s" % (fmt(gen_wall, 1), fmt(gen_cpu, 1))],
            ["map_from_bag (wall / CPU)", "%s s / %s s" % (fmt(map_wall, 1), fmt(map_cpu, 1))],
            ["start-up", "%s s" % fmt(long_stats.startup_s(os.path.join(out, "map.log")), 2)]]
    for k, ms in enumerate(tenths):
        rows.append(["CPU ms / frame, tenth %d (%.1f-%.1f km)"
                     % (k + 1, k * total_km / TENTHS, (k + 1) * total_km / TENTHS), fmt(ms, 2)])
    ratio = tenths[-1] / tenths[0] if tenths[0] and tenths[-1] is not None else None
    rows.append(["CPU last tenth / first tenth", fmt(ratio, 2)])
    return rows, whole, split, stats, distances


def accuracy_rows(ctx, out, whole, split, stats, distances):
    total_km = split.index.total_m / 1e3
    rss_mb = [row[3] / 1024.0 for row in stats]
    rows = [["peak RSS", "%s MB" % fmt(max(rss_mb), 1)],
            ["RSS growth (least squares over distance)", "%s MB/km" % fmt(
                long_stats.slope([d / 1e3 for d in distances], rss_mb), 2)]]
    map_bytes = os.path.getsize(os.path.join(out, "map.json"))
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
    for k, (d0, d1, marking, lane, recall) in enumerate(evaluate_sixths(ctx, split, out)):
        rows.append(["marking / lane APE, sixth %d (%.1f-%.1f km)" % (k + 1, d0 / 1e3, d1 / 1e3),
                     "%s / %s m (marking recall %s)" % (fmt(marking), fmt(lane), fmt(recall, 2))])
    return rows


def tables(ctx, results):
    help_text = map_from_bag_options(ctx)
    drive = drives.synthetic(ctx, drives.LONG)
    out = os.path.join(ctx.out, "maps", drives.LONG, "mapper")
    print("[benchmark] %s: generating unless cached (the scenario and the generator's build)"
          % drives.LONG, file=sys.stderr)
    generate_time = generate_drive(ctx, drive)
    print("[benchmark] %s: mapping (config/mapper.yaml)" % drives.LONG, file=sys.stderr)
    map_time = map_drive(ctx, drive, out, help_text)
    instructions = instruction_rows(ctx, drive) if ctx.instructions else []
    unloaded = unload.rows(ctx, drive)
    rows, whole, split, stats, distances = report_rows(ctx, drive, out, generate_time, map_time)
    rows += instructions + accuracy_rows(ctx, out, whole, split, stats, distances)
    rows += publish_rows(long_stats.read_publish_stats(os.path.join(out, "publish.csv")))
    rows += unloaded
    with open(os.path.join(out, "long_results.json"), "w") as f:
        json.dump({"rows": rows}, f, indent=1)
    return [Table("Long drive: %s, config/mapper.yaml, seed 1" % drives.LONG,
                  ["quantity", "value"], rows),
            Line("[benchmark] long-drive outputs: %s" % out, docs=False)]
