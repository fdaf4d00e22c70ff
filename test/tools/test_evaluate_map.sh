#!/usr/bin/env bash
# End-to-end test of evaluate_map and plot_map.py (with and without ground truth) on a small
# drive written here: a 160 m road (straight, then an arc) with 3 lane lines, 10 markings and
# 100 frames, and a map with known damage (marking offsets, a duplicate, a false positive, a
# split lane, a lateral lane offset, an extrinsic error, pose noise), and the view's ceiling
# of the drive (every line and seen marking reachable). Run by ctest in the devel space's
# environment.
set -e -o pipefail

PYTHON=/usr/bin/python3
work=$(mktemp -d /tmp/irm_test_evaluate_map.XXXXXX)
trap 'rm -rf "$work"' EXIT
fail() {
  echo "FAIL: $*" >&2
  exit 1
}

# The tools as `rosrun ipm_road_mapper <tool>` finds them in a clean checkout. catkin_find
# gives the devel space's copy only: rosrun also searches the package's source folder and
# stops to ask when a build folder inside it holds another copy.
tool() {
  local path
  path=$(catkin_find --first-only --libexec ipm_road_mapper "$1" 2>/dev/null) ||
    fail "ipm_road_mapper/$1 not found (source the devel space's setup.bash)"
  echo "$path"
}
evaluate_map_bin=$(tool evaluate_map)
# Python tools run from the package's scripts/ folder (rosrun finds them there).
plot_map_bin="$(rospack find ipm_road_mapper)/scripts/plot_map.py"
[ -x "$plot_map_bin" ] || fail "$plot_map_bin is missing or not executable"
evaluate_map() { "$evaluate_map_bin" "$@"; }
plot_map() { "$plot_map_bin" "$@"; }

# ---- Fixtures --------------------------------------------------------------------------
"$PYTHON" - "$work" <<'EOF'
import json, math, random, sys
out = sys.argv[1]
rng = random.Random(3)

def centerline(s):
    """Road centerline point and heading at arc length s: 80 m straight, then R = 100 m."""
    if s <= 80.0:
        return 0.0 + s, 0.0, 0.0
    a = (s - 80.0) / 100.0
    return 80.0 + 100.0 * math.sin(a), 100.0 * (1.0 - math.cos(a)), a

def road_point(s, offset):
    x, y, heading = centerline(s)
    px, py = x - offset * math.sin(heading), y + offset * math.cos(heading)
    return [px, py, 0.01 * s + 0.01 * offset]

def pose(t, yaw):
    return {"t": t, "q_xyzw": [0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)]}

def camera_pose(pitch_deg, z):
    # R_base_cam = Ry(pitch) * [[0,0,1],[-1,0,0],[0,-1,0]] as a quaternion.
    p = math.radians(pitch_deg)
    r = [[0, 0, 1], [-1, 0, 0], [0, -1, 0]]
    ry = [[math.cos(p), 0, math.sin(p)], [0, 1, 0], [-math.sin(p), 0, math.cos(p)]]
    m = [[sum(ry[i][k] * r[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    w = math.sqrt(1 + m[0][0] + m[1][1] + m[2][2]) / 2
    return {"t": [1.5, 0.0, z], "q_xyzw": [(m[2][1] - m[1][2]) / (4 * w),
            (m[0][2] - m[2][0]) / (4 * w), (m[1][0] - m[0][1]) / (4 * w), w]}

length = 160.0
offsets = [-1.75, 1.75, 5.25]
lanes = [{"id": i + 1, "class_id": 1, "class_name": "lane_white_solid", "style": "solid",
          "points": [road_point(0.1 * k, o) for k in range(int(length * 10) + 1)]}
         for i, o in enumerate(offsets)]

def rectangle(s, offset, along, across):
    a, c = along / 2, across / 2
    return [road_point(s - a, offset - c), road_point(s + a, offset - c),
            road_point(s + a, offset + c), road_point(s - a, offset + c)]

markings = []
for k in range(10):
    s, offset, cls, name = (12 + 15 * k, 0.0, 10, "arrow_straight") if k % 2 == 0 else \
        (12 + 15 * k, 3.5, 23, "diamond")
    corners = rectangle(s, offset, 4.0 if cls == 10 else 3.0, 1.0)
    center = [sum(c[i] for c in corners) / 4 for i in range(3)]
    markings.append({"id": k + 1, "class_id": cls, "class_name": name, "corners": corners,
                     "center": center, "visible_frames": 0 if k == 9 else 25})

frames, trajectory = [], []
for k in range(100):
    s = 1.5 * k
    x, y, heading = centerline(s)
    z = 0.01 * s
    frames.append({"stamp": 1000.0 + 0.1 * k,
                   "T_map_base_true": pose([x, y, z], heading),
                   "T_map_base_odom": pose([x + 0.003 * k, y + 0.002 * k, z], heading + 0.004)})
    trajectory.append(dict(pose([x + rng.gauss(0, 0.05), y + rng.gauss(0, 0.05), z],
                                heading + rng.gauss(0, 0.001)), stamp=1000.0 + 0.1 * k))

gt = {"format": "ipm_road_mapper/ground_truth", "version": 1, "scenario": "test_evaluate_map",
      "seed": 3, "frame_rate_hz": 10.0,
      "camera": {"width": 1280, "height": 720, "fx": 1000.0, "fy": 1000.0, "cx": 640.0,
                 "cy": 360.0, "distortion": [0.0, 0.0, 0.0, 0.0, 0.0]},
      "T_base_cam_true": camera_pose(3.0, 1.4), "T_base_cam_rough": camera_pose(2.0, 1.45),
      "markings": markings, "lanes": lanes, "frames": frames}

def spline(offset, s0, s1, lateral):
    """Control points every 3 m from s0 to s1, shifted laterally, phantom ends extrapolated."""
    n = int(round((s1 - s0) / 3.0))
    pts = [road_point(s0 + (s1 - s0) * i / n, offset + lateral + rng.gauss(0, 0.03))
           for i in range(n + 1)]
    first = [2 * a - b for a, b in zip(pts[0], pts[1])]
    last = [2 * a - b for a, b in zip(pts[-1], pts[-2])]
    return [first] + pts + [last]

map_lanes = [
    {"id": 1, "class_id": 1, "class_name": "lane_white_solid", "style": "solid",
     "control_points": spline(-1.75, 0.0, 159.0, 0.05)},
    {"id": 2, "class_id": 1, "class_name": "lane_white_solid", "style": "solid",
     "control_points": spline(1.75, 0.0, 90.0, -0.1)},
    {"id": 3, "class_id": 1, "class_name": "lane_white_solid", "style": "solid",
     "control_points": spline(1.75, 90.0, 159.0, -0.1)},
    {"id": 4, "class_id": 1, "class_name": "lane_white_solid", "style": "solid",
     "control_points": spline(5.25, 10.0, 150.0, 0.25)},
]
map_markings = []
for m in markings[:9]:
    dx, dy = rng.gauss(0, 0.2), rng.gauss(0, 0.2)
    map_markings.append({"id": 100 + m["id"], "class_id": m["class_id"],
                         "class_name": m["class_name"], "observations": 20,
                         "corners": [[c[0] + dx, c[1] + dy, c[2] + 0.02] for c in m["corners"]]})
dup = dict(map_markings[2], id=200)
dup["corners"] = [[c[0] + 0.8, c[1], c[2]] for c in map_markings[2]["corners"]]
fp = dict(map_markings[0], id=201)
fp["corners"] = [[c[0], c[1] + 8.0, c[2]] for c in map_markings[0]["corners"]]
map_markings += [dup, fp]

vmap = {"format": "ipm_road_mapper/vector_map", "version": 1, "frame_id": "map",
        "T_base_cam": camera_pose(2.9, 1.41), "T_base_cam_initial": camera_pose(2.0, 1.45),
        "markings": map_markings, "lanes": map_lanes, "trajectory": trajectory,
        "metadata": {"method": "test fixture"}}
no_traj = dict(vmap, trajectory=[])
for name, doc in (("gt.json", gt), ("map.json", vmap), ("map_no_traj.json", no_traj)):
    with open("%s/%s" % (out, name), "w") as f:
        json.dump(doc, f, indent=1)
EOF

# ---- A good run ------------------------------------------------------------------------
evaluate_map --map "$work/map.json" --ground-truth "$work/gt.json" --json "$work/metrics.json" \
  >"$work/table.txt" || fail "evaluate_map exited with $?"
cat "$work/table.txt"
for heading in Markings Lanes Extrinsic Poses Storage; do
  grep -q "$heading" "$work/table.txt" || fail "table has no '$heading' section"
done

"$PYTHON" - "$work/metrics.json" "$work/map.json" <<'EOF' || fail "metrics JSON check"
import json, os, sys
m = json.load(open(sys.argv[1]))
required = ["marking_ape_mean_m", "marking_ape_std_m", "marking_recall", "marking_duplicates",
            "lane_ape_mean_m", "lane_ape_std_m", "lane_f1", "extrinsic_rot_err_deg",
            "extrinsic_trans_err_m", "ipm_grid_err_m", "pose_rot_err_deg_input",
            "pose_trans_err_m_input", "pose_rot_err_deg", "pose_trans_err_m",
            "map_bytes_per_km", "control_points_per_km"]
missing = [k for k in required if k not in m]
assert not missing, "missing keys %s" % missing
nulls = [k for k in required if m[k] is None]
assert not nulls, "null values %s" % nulls
def check(ok, what):
    if not ok:
        sys.exit("bad value: %s" % what)
check(0.05 < m["marking_ape_mean_m"] < 0.6, "marking_ape_mean_m %s" % m["marking_ape_mean_m"])
check(m["marking_recall"] == 1.0, "marking_recall %s (the unseen GT marking must not count)"
      % m["marking_recall"])
check(m["marking_duplicates"] == 1 and m["marking_unmatched"] == 2, "duplicates/unmatched")
check(0.05 < m["lane_ape_mean_m"] < 0.3, "lane_ape_mean_m %s" % m["lane_ape_mean_m"])
check(m["lane_f1"] == 1.0, "lane_f1 %s" % m["lane_f1"])
check(1.0 < m["lane_splines_per_matched_gt_lane"] < 2.0, "splines per GT lane")
check(abs(m["extrinsic_rot_err_deg"] - 0.1) < 1e-6, "extrinsic_rot_err_deg %s"
      % m["extrinsic_rot_err_deg"])
check(abs(m["extrinsic_rot_err_deg_initial"] - 1.0) < 1e-6, "extrinsic_rot_err_deg_initial")
check(abs(m["extrinsic_trans_err_m"] - 0.01) < 1e-6, "extrinsic_trans_err_m")
check(0 < m["ipm_grid_err_m"] < m["ipm_grid_err_m_initial"], "ipm grid error before/after")
check(m["pose_frames_matched"] == 100, "pose_frames_matched")
check(0.02 < m["pose_trans_err_m"] < 0.1, "pose_trans_err_m %s" % m["pose_trans_err_m"])
check(abs(m["pose_yaw_err_deg_input"] - 0.004 * 180 / 3.141592653589793) < 1e-4, "odom yaw")
check(m["map_bytes"] == os.path.getsize(sys.argv[2]), "map_bytes is the file size")
check(m["map_bytes_per_km"] > 0 and m["control_points_per_km"] > 300, "storage")
check(len(m["markings"]) == 11 and len(m["lanes"]) == 4 and len(m["poses"]) == 100, "arrays")
# The view's ceiling: the drive sees every line and every marking the masks hold (the unseen
# one is not counted); the map's markings lie on the seen parts as on the whole markings.
check(m["ceiling_view_range_m"] == 40.0, "ceiling_view_range_m")
check(m["ceiling_lanes_reachable"] == 3 and m["ceiling_lane_f1"] == 1.0, "ceiling lanes %s"
      % m["ceiling_lanes_reachable"])
check(m["ceiling_markings_reachable"] == 9 and m["ceiling_marking_recall"] == 1.0,
      "ceiling markings %s" % m["ceiling_markings_reachable"])
check(len(m["ceiling_markings"]) == 10 and len(m["ceiling_lanes"]) == 3, "ceiling arrays")
check(m["seen_part_gt"] == 9 and m["seen_part_matched"] == m["marking_matched"]
      and abs(m["seen_part_ape_mean_m"] - m["marking_ape_mean_m"]) < 0.05,
      "seen parts %s / %s, %s" % (m["seen_part_matched"], m["seen_part_gt"],
                                  m["seen_part_ape_mean_m"]))
EOF

evaluate_map --map "$work/map.json" --ground-truth "$work/gt.json" --json "$work/m2.json" \
  --map-bytes 1000 >/dev/null || fail "--map-bytes run"
"$PYTHON" -c "import json,sys; m=json.load(open(sys.argv[1])); sys.exit(m['map_bytes'] != 1000)" \
  "$work/m2.json" || fail "--map-bytes not used"

evaluate_map --map "$work/map_no_traj.json" --ground-truth "$work/gt.json" \
  --json "$work/m3.json" >"$work/table3.txt" || fail "map without trajectory"
grep -q "no trajectory" "$work/table3.txt" || fail "table does not say the map has no trajectory"
"$PYTHON" -c "import json,sys; m=json.load(open(sys.argv[1])); \
sys.exit(not (m['pose_trans_err_m'] is None and m['pose_trans_err_m_input'] > 0))" \
  "$work/m3.json" || fail "pose keys without a trajectory"

# ---- Bad input: exit code 2 and exactly one line on stderr -----------------------------
printf '{"format": "ipm_road_mapper/vector_map", "version": 1, "markings": [' \
  >"$work/truncated.json"
echo 'this is not json' >"$work/corrupt.json"
"$PYTHON" -c "import json,sys; d=json.load(open(sys.argv[1])); d['version']=7; \
json.dump(d, open(sys.argv[2], 'w'))" "$work/map.json" "$work/v7.json"
expect_bad_input() {
  local name=$1
  shift
  set +e
  evaluate_map "$@" >"$work/bad.out" 2>"$work/bad.err"
  local code=$?
  set -e
  [ "$code" -eq 2 ] || fail "$name: exit code $code, expected 2"
  local lines
  lines=$(wc -l <"$work/bad.err")
  [ "$lines" -eq 1 ] || fail "$name: $lines lines on stderr: $(cat "$work/bad.err")"
  grep -q "error" "$work/bad.err" || fail "$name: no error message"
  echo "ok ($name): $(cat "$work/bad.err")"
}
expect_bad_input "missing map" --map "$work/nope.json" --ground-truth "$work/gt.json"
expect_bad_input "corrupt map" --map "$work/corrupt.json" --ground-truth "$work/gt.json"
expect_bad_input "truncated map" --map "$work/truncated.json" --ground-truth "$work/gt.json"
expect_bad_input "wrong version" --map "$work/v7.json" --ground-truth "$work/gt.json"
expect_bad_input "map as ground truth" --map "$work/map.json" --ground-truth "$work/map.json"
expect_bad_input "unknown option" --map "$work/map.json" --ground-truth "$work/gt.json" --fast
expect_bad_input "missing option" --map "$work/map.json"
expect_bad_input "option twice" --map "$work/map.json" --map "$work/map.json" \
  --ground-truth "$work/gt.json"

# ---- The command line: --help names every option with its default, exit 0 ----------------
evaluate_map --help >"$work/help.txt" 2>"$work/help.err" || fail "--help exited $?"
[ ! -s "$work/help.err" ] || fail "--help wrote to stderr: $(cat "$work/help.err")"
for option in --map --ground-truth --json --map-bytes --help; do
  grep -q -- "$option" "$work/help.txt" || fail "--help does not name $option"
done
[ "$(grep -o -e "(default: " -e "(required)" "$work/help.txt" | wc -l)" -ge 4 ] ||
  fail "--help does not give every option's default: $(cat "$work/help.txt")"
echo "ok: --help names every option"
expect_bad_input "bad byte count" --map "$work/map.json" --ground-truth "$work/gt.json" \
  --map-bytes -5

# ---- The plot --------------------------------------------------------------------------
plot_map --map "$work/map.json" --ground-truth "$work/gt.json" --metrics "$work/metrics.json" \
  --out "$work/map.png" || fail "plot_map.py exited with $?"
plot_map --map "$work/map_no_traj.json" --ground-truth "$work/gt.json" \
  --out "$work/map_plain.png" || fail "plot_map.py without metrics exited with $?"
# The map alone (a real drive has no ground truth): with and without a trajectory.
plot_map --map "$work/map.json" --out "$work/map_alone.png" >"$work/alone.log" ||
  fail "plot_map.py without --ground-truth exited with $?"
grep -q "^wrote $work/map_alone.png$" "$work/alone.log" || fail "no 'wrote' line: $(cat "$work/alone.log")"
plot_map --map "$work/map_no_traj.json" --out "$work/map_alone_no_traj.png" >/dev/null ||
  fail "plot_map.py without --ground-truth and trajectory exited with $?"
for png in "$work/map.png" "$work/map_plain.png" "$work/map_alone.png" \
    "$work/map_alone_no_traj.png"; do
  [ -s "$png" ] || fail "$png missing"
  size=$(stat -c %s "$png")
  [ "$size" -gt 50000 ] || fail "$png is only $size bytes"
  head -c 8 "$png" | od -An -c | grep -q "P   N   G" || fail "$png is not a PNG"
done
if [ -n "${IRM_KEEP_PLOT:-}" ]; then cp "$work/map.png" "$IRM_KEEP_PLOT"; fi
echo "test_evaluate_map: all checks passed"
