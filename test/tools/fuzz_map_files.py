#!/usr/bin/env python3
"""Seeded mutation fuzzer of evaluate_map's two inputs (map.json, ground_truth.json).

Writes a small valid map and ground truth, then N mutants of each (byte flips, truncation,
deep nesting, huge numbers, type swaps, duplicate keys, long arrays) and runs
`evaluate_map --map M --ground-truth G` on every mutant with the other file intact. Any
signal, timeout or exit code other than 0 (accepted) or 2 (refused in one line) is a
failure; exit 1 (an exception the tool did not classify) is counted on its own.
Exit status: 0 when no mutant failed, 1 otherwise.
"""
import argparse
import json
import math
import os
import random
import subprocess
import sys

TIMEOUT_S = 20.0
NUMBER_CHARS = set("0123456789+-.eE")
HUGE_NUMBERS = ["1e999", "-1e999", "1e308", "-1.7976931348623157e308", "1e8", "1e6", "-1e7",
                "18446744073709551616", "99999999999999999999999", "-9223372036854775809",
                "4294967296", "2147483648", "1e-400", "-0", "0", "NaN", "Infinity"]
TYPE_SAMPLES = ['"text"', "[]", "{}", "null", "true", "[1, 2]", '{"t": [0, 0, 0]}', "0",
                "-1", "3.5", "[[0, 0, 0]]", '""']


def pose(x, y, yaw):
    return {"t": [x, y, 0.0], "q_xyzw": [0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)]}


def camera_pose():
    # Camera optical frame looking forward, 1.4 m up: R_base_cam = [[0,0,1],[-1,0,0],[0,-1,0]].
    return {"t": [1.5, 0.0, 1.4], "q_xyzw": [-0.5, 0.5, -0.5, 0.5]}


def fixture(out_dir):
    """A 40 m straight road: 2 lane lines, 3 markings, 20 frames; the map is close to it."""
    gt_lanes = [{"id": i + 1, "class_id": 1, "class_name": "lane_white_solid", "style": "solid",
                 "points": [[0.5 * k, y, 0.0] for k in range(81)]}
                for i, y in enumerate((-1.75, 1.75))]
    markings = []
    for k in range(3):
        x = 8.0 + 10.0 * k
        corners = [[x, -0.5, 0.0], [x + 3.0, -0.5, 0.0], [x + 3.0, 0.5, 0.0], [x, 0.5, 0.0]]
        markings.append({"id": k + 1, "class_id": 10, "class_name": "arrow_straight",
                         "corners": corners, "center": [x + 1.5, 0.0, 0.0],
                         "visible_frames": 10})
    frames = [{"stamp": 100.0 + 0.1 * k, "T_map_base_true": pose(2.0 * k, 0.0, 0.0),
               "T_map_base_odom": pose(2.0 * k + 0.01 * k, 0.0, 0.001)} for k in range(20)]
    gt = {"format": "ipm_road_mapper/ground_truth", "version": 1, "scenario": "fuzz", "seed": 1,
          "frame_rate_hz": 10.0,
          "camera": {"width": 640, "height": 360, "fx": 500.0, "fy": 500.0, "cx": 320.0,
                     "cy": 180.0, "distortion": [0.0, 0.0, 0.0, 0.0, 0.0]},
          "T_base_cam_true": camera_pose(), "T_base_cam_rough": camera_pose(),
          "markings": markings, "lanes": gt_lanes, "frames": frames}
    map_lanes = [{"id": i + 1, "class_id": 1, "class_name": "lane_white_solid", "style": "solid",
                  "observations": 15, "first_seen": 100.0, "last_seen": 101.9,
                  "control_points": [[3.0 * k - 3.0, y + 0.05, 0.01] for k in range(15)]}
                 for i, y in enumerate((-1.75, 1.75))]
    map_markings = [dict({k: v for k, v in m.items() if k not in ("center", "visible_frames")},
                         id=100 + m["id"], observations=8, first_seen=100.0, last_seen=101.0,
                         corners=[[c[0] + 0.1, c[1] - 0.05, c[2]] for c in m["corners"]])
                    for m in markings]
    trajectory = [dict(pose(2.0 * k + 0.02, 0.01, 0.0), stamp=100.0 + 0.1 * k)
                  for k in range(20)]
    vmap = {"format": "ipm_road_mapper/vector_map", "version": 1, "frame_id": "map",
            "T_base_cam": camera_pose(), "T_base_cam_initial": camera_pose(),
            "markings": map_markings, "lanes": map_lanes, "trajectory": trajectory,
            "metadata": {"method": "fuzz fixture", "counters": {"frames": 20, "skipped": 0},
                         "config": {"ipm": {"max_range_m": 40.0, "pixel_error_px": [2, 2]}}}}
    paths = {}
    for name, doc in (("map.json", vmap), ("ground_truth.json", gt)):
        paths[name] = os.path.join(out_dir, name)
        with open(paths[name], "w") as f:
            json.dump(doc, f, indent=1)
    return paths["map.json"], paths["ground_truth.json"]


def number_spans(text):
    """(start, end) of every number token in the text (outside strings, roughly)."""
    spans, k, in_string = [], 0, False
    while k < len(text):
        ch = text[k]
        if in_string:
            if ch == "\\":
                k += 1
            elif ch == '"':
                in_string = False
        elif ch == '"':
            in_string = True
        elif ch in "-0123456789":
            start = k
            while k < len(text) and text[k] in NUMBER_CHARS:
                k += 1
            spans.append((start, k))
            continue
        k += 1
    return spans


def value_positions(text):
    """Offsets where a JSON value starts: after ':' or '[' or ',' (outside strings)."""
    positions, in_string, escaped = [], False, False
    for k, ch in enumerate(text):
        if in_string:
            if escaped:
                escaped = False
            elif ch == "\\":
                escaped = True
            elif ch == '"':
                in_string = False
        elif ch == '"':
            in_string = True
        elif ch in ":[,":
            positions.append(k + 1)
    return positions


def skip_value(text, start):
    """End offset of the JSON value starting at (or after whitespace from) `start`."""
    k = start
    while k < len(text) and text[k] in " \n\t":
        k += 1
    if k >= len(text):
        return k
    depth, in_string, escaped = 0, False, False
    for j in range(k, len(text)):
        ch = text[j]
        if in_string:
            if escaped:
                escaped = False
            elif ch == "\\":
                escaped = True
            elif ch == '"':
                in_string = False
                if depth == 0:
                    return j + 1
        elif ch == '"':
            in_string = True
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            if depth == 0:
                return j
            depth -= 1
            if depth == 0:
                return j + 1
        elif ch == "," and depth == 0:
            return j
    return len(text)


def mutate(text, rng):
    """One mutant of `text` and a short description of what was done."""
    kind = rng.choice(["flip", "flip", "truncate", "deep", "huge", "huge", "type", "type",
                       "duplicate_key", "long_array"])
    if kind == "flip":
        data = bytearray(text.encode())
        flips = rng.randint(1, 8)
        for _ in range(flips):
            data[rng.randrange(len(data))] = rng.randrange(256)
        return data, "%d byte flips" % flips
    if kind == "truncate":
        cut = rng.randrange(len(text))
        return text[:cut].encode(), "truncated at %d" % cut
    if kind == "deep":
        levels = rng.choice([63, 64, 65, 1000, 200000])
        opener = rng.choice(["[", '{"a":'])
        closer = "]" if opener == "[" else "}"
        where = rng.choice(value_positions(text))
        end = skip_value(text, where)
        nested = opener * levels + "1" + closer * levels
        return (text[:where] + nested + text[end:]).encode(), "%d levels at %d" % (levels, where)
    if kind == "huge":
        start, end = rng.choice(number_spans(text))
        number = rng.choice(HUGE_NUMBERS)
        return (text[:start] + number + text[end:]).encode(), "number %s at %d" % (number, start)
    if kind == "type":
        where = rng.choice(value_positions(text))
        end = skip_value(text, where)
        value = rng.choice(TYPE_SAMPLES)
        return (text[:where] + value + text[end:]).encode(), "value %s at %d" % (value, where)
    if kind == "duplicate_key":
        keys = [k for k in range(len(text)) if text.startswith('": ', k)]
        colon = rng.choice(keys) + 1  # the ':' after a key
        key_start = text.rfind('"', 0, colon - 1)
        key = text[key_start:colon]
        value = rng.choice(TYPE_SAMPLES + HUGE_NUMBERS[:6])
        return (text[:key_start] + key + " " + value + ", " + text[key_start:]).encode(), \
            "duplicate key %s = %s" % (key, value)
    # long_array: one element repeated many times in an array.
    opens = [k for k, ch in enumerate(text) if ch == "["]
    start = rng.choice(opens) + 1
    end = skip_value(text, start)
    element = text[start:end].strip() or "0"
    # At most ~8 MB of copies: enough to cross the element limits of small elements.
    copies = min(rng.choice([1000, 100001, 300000]), max(1, 8_000_000 // (len(element) + 1)))
    body = ",".join([element] * copies)
    return (text[:start] + body + text[end:]).encode(), "array at %d x%d" % (start, copies)


def run(binary, map_path, gt_path):
    try:
        proc = subprocess.run([binary, "--map", map_path, "--ground-truth", gt_path],
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                              timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        return "timeout", ""
    stderr = proc.stderr.decode(errors="replace").strip()
    if proc.returncode < 0:
        return "signal", "signal %d %s" % (-proc.returncode, stderr[-200:])
    return "exit %d" % proc.returncode, stderr[:300]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--evaluate-map", required=True, help="the evaluate_map executable")
    parser.add_argument("--work", required=True, help="folder for the fixture and mutants")
    parser.add_argument("--n", type=int, default=300, help="mutants per file")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    rng = random.Random(args.seed)
    map_path, gt_path = fixture(args.work)
    status, message = run(args.evaluate_map, map_path, gt_path)
    if status != "exit 0":
        sys.exit("the unmutated fixture fails: %s %s" % (status, message))
    counts, failures = {}, []
    mutant = os.path.join(args.work, "mutant.json")
    for index in range(2 * args.n):
        target = map_path if index % 2 == 0 else gt_path
        with open(target) as f:
            data, what = mutate(f.read(), rng)
        with open(mutant, "wb") as f:
            f.write(data)
        pair = (mutant, gt_path) if target == map_path else (map_path, mutant)
        status, message = run(args.evaluate_map, *pair)
        counts[status] = counts.get(status, 0) + 1
        if status not in ("exit 0", "exit 2"):
            failures.append("#%d %s %s: %s: %s" % (index, os.path.basename(target), what, status,
                                                   message))
        elif status == "exit 2" and ("\n" in message or not message):
            counts["exit 2 without one line"] = counts.get("exit 2 without one line", 0) + 1
            failures.append("#%d %s %s: not one line: %r" % (index, os.path.basename(target),
                                                            what, message))
    summary = ", ".join("%s: %d" % (k, counts[k]) for k in sorted(counts))
    print("fuzz_map_files: seed %d, %d mutants per file: %s" % (args.seed, args.n, summary))
    print("fuzz_map_files: signals %d, timeouts %d, exit 1 %d, exit 2 %d" % (
        counts.get("signal", 0), counts.get("timeout", 0), counts.get("exit 1", 0),
        counts.get("exit 2", 0)))
    for line in failures[:20]:
        print("  " + line)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
