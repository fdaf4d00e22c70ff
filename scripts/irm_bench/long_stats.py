"""The long drive's files and arithmetic: map_from_bag's --stats-out and --publish-stats-out
CSVs, CPU per part of the drive, RSS slope, callgrind dumps, the unload test's line."""
import bisect
import csv
import os
import re

from .runners import BenchmarkError

STATS_HEADER = ["frame", "stamp", "cpu_s", "rss_kb"]
# The --publish-stats-out columns the table reads (others the file may hold are ignored).
PUBLISH_COLUMNS = ["km", "markings", "lanes", "export_changes_ms", "export_snapshot_ms",
                   "publish_ms"]
MIN_STATS_ROWS = 20


def read_stats(path):
    """The --stats-out CSV as a list of (frame, stamp, cpu_s, rss_kb), checked."""
    with open(path) as f:
        rows = list(csv.reader(f))
    if not rows or rows[0] != STATS_HEADER:
        raise BenchmarkError("%s: expected the header %s, got %s" % (
            path, ",".join(STATS_HEADER), ",".join(rows[0]) if rows else "nothing"))
    stats = [(int(r[0]), float(r[1]), float(r[2]), float(r[3])) for r in rows[1:] if r]
    if len(stats) < MIN_STATS_ROWS:
        raise BenchmarkError("%s: only %d rows" % (path, len(stats)))
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
        result.append(1e3 * (stats[row][2] - stats[previous][2]) /
                      (stats[row][0] - stats[previous][0]))
        previous = row
    return result


def slope(xs, ys):
    """Least-squares slope of ys over xs."""
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else None


def median(values):
    """The median of `values` (None when empty)."""
    values = sorted(values)
    n = len(values)
    if n == 0:
        return None
    return values[n // 2] if n % 2 else 0.5 * (values[n // 2 - 1] + values[n // 2])


def startup_s(log_path):
    """The `startup_s` map_from_bag's summary prints (None when it does not)."""
    with open(log_path) as f:
        match = re.search(r"startup_s\D{0,3}([0-9.]+)", f.read())
    return float(match.group(1)) if match else None


def read_publish_stats(path):
    """The --publish-stats-out CSV as a list of dicts (None when the file is absent)."""
    if not os.path.exists(path):
        return None
    with open(path) as f:
        rows = list(csv.reader(f))
    missing = [c for c in PUBLISH_COLUMNS if not rows or c not in rows[0]]
    if missing:
        raise BenchmarkError("%s: no column %s" % (path, ", ".join(missing)))
    return [dict(zip(rows[0], map(float, r))) for r in rows[1:] if r]


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
        with open(os.path.join(folder, name), errors="replace") as f:
            text = f.read()
        trigger = re.search(r"^desc: Trigger: Client Request: span (\d+) frames (\d+)", text, re.M)
        total = re.search(r"^totals:\s*(\d+)", text, re.M)
        if trigger and total:
            result.append((int(trigger.group(1)), int(trigger.group(2)), int(total.group(1))))
    return sorted(result)


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


def unload_figures(output):
    """(unload s, budget s) from the line ros_test_long_drive_unload prints ("... mapping
    thread joined at <s> s; budget <s> s"); None for a figure the output lacks."""
    joined = re.search(r"joined at ([0-9.]+) s", output)
    budget = re.search(r"budget ([0-9.]+) s", output)
    return (float(joined.group(1)) if joined else None,
            float(budget.group(1)) if budget else None)
