#!/usr/bin/env bash
# End-to-end test of `rosrun ipm_road_mapper map_from_bag` on a small drive generated here
# (test/tools/make_test_bag.py): the outputs exist and parse, the marking lands where the
# ground truth put it, no GeoJSON without a geo origin (one line says why; a stale one is
# removed), with one the GeoJSON is accepted by a standard reader (python3-geojson and
# python3-shapely when installed; the structure is always checked by hand too), the
# extrinsic comes from /tf_static or the config, approximate sync pairs shifted
# camera_infos, a bag loop is counted, every kind of bad input exits 2 with one line, --help
# lists every option, and --stats-out writes one row per frame.
# Run by ctest in the devel space's environment (IRM_SOURCE_DIR = the repository).
set -eo pipefail
export PATH="/usr/bin:/bin:$PATH"
repo="${IRM_SOURCE_DIR:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}"
work="$(mktemp -d /tmp/irm_map_from_bag_XXXXXX)"
trap 'rm -rf "$work"' EXIT
export ROS_HOME="$work/ros_home"
failures=0

fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
pass() { echo "ok: $*"; }

make_bag() { /usr/bin/python3 "$repo/test/tools/make_test_bag.py" "$@"; }
run_mapper() { rosrun ipm_road_mapper map_from_bag "$@"; }

# A config overlaying the package's config/mapper.yaml (`base:`) with the given YAML lines;
# the back end is off so these runs check the runner and the front end only (run 1 runs the
# full default config).
overlay() {
  local out="$work/$1"; shift
  { echo "base: $repo/config/mapper.yaml"; echo "backend: {enabled: false}"; printf '%s\n' "$@"; } >"$out"
  echo "$out"
}

# Expects exit status 2 and exactly one line on stderr mentioning $2.
expect_input_error() {
  local name="$1" pattern="$2"; shift 2
  local rc=0
  run_mapper "$@" >"$work/stdout" 2>"$work/stderr" || rc=$?
  local lines
  lines=$(wc -l <"$work/stderr")
  if [ "$rc" -ne 2 ]; then
    fail "$name: exit $rc, expected 2 ($(cat "$work/stderr"))"
  elif [ "$lines" -ne 1 ]; then
    fail "$name: $lines stderr lines, expected one:"; cat "$work/stderr"
  elif ! grep -q -- "$pattern" "$work/stderr"; then
    fail "$name: error does not mention '$pattern': $(cat "$work/stderr")"
  else
    pass "$name -> exit 2: $(cat "$work/stderr")"
  fi
}

make_bag "$work/drive.bag"
make_bag "$work/no_tf.bag" --no-tf
make_bag "$work/shifted.bag" --camera-info-offset 0.002
make_bag "$work/loop.bag" --loop

# map.json has the arrow where the ground truth put it; one TUM pose per frame.
check_outputs() {
  /usr/bin/python3 - "$1" <<'EOF'
import json, sys
out = sys.argv[1]
m = json.load(open(out + "/map.json"))
assert len(m["markings"]) >= 1, "no marking mapped"
# Ground truth: the arrow at x 18..21, y -0.6..0.6 (center 19.5, 0).
best = min(m["markings"], key=lambda k: (sum(c[0] for c in k["corners"]) / 4 - 19.5) ** 2)
cx = sum(c[0] for c in best["corners"]) / 4
cy = sum(c[1] for c in best["corners"]) / 4
assert abs(cx - 19.5) < 0.5 and abs(cy) < 0.3, f"marking center ({cx:.2f}, {cy:.2f})"
rows = [l.split() for l in open(out + "/map_trajectory_tum.txt") if not l.startswith("#")]
assert len(rows) == 25 and all(len(r) == 8 for r in rows), f"{len(rows)} TUM rows"
print(f"ok: map.json: {len(m['markings'])} markings, {len(m['lanes'])} lanes; "
      f"arrow center ({cx:.2f}, {cy:.2f}); 25 TUM poses")
EOF
}

# The GeoJSON: hand-checked structure plus any standard reader that is installed.
check_geojson() {
  /usr/bin/python3 - "$1" "$2" <<'EOF'
import json, sys
path, expected_system = sys.argv[1], sys.argv[2]
text = open(path).read()
g = json.loads(text)
assert g["type"] == "FeatureCollection" and "crs" not in g
assert g["coordinate_system"] == expected_system, g["coordinate_system"]
kinds = {}
for f in g["features"]:
    assert f["type"] == "Feature" and isinstance(f["properties"], dict)
    kinds[f["properties"]["kind"]] = kinds.get(f["properties"]["kind"], 0) + 1
    geometry = f["geometry"]
    if geometry is None:
        continue
    if geometry["type"] == "Polygon":
        ring = geometry["coordinates"][0]
        assert len(ring) == 5 and ring[0] == ring[-1], "ring not closed"
        area2 = sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(ring, ring[1:]))
        assert area2 > 0, "exterior ring is not counter-clockwise"
    else:
        assert geometry["type"] == "LineString" and len(geometry["coordinates"]) >= 2
    for position in (geometry["coordinates"][0] if geometry["type"] == "Polygon"
                     else geometry["coordinates"]):
        assert len(position) == 3 and all(isinstance(v, (int, float)) for v in position)
assert kinds.get("marking", 0) >= 1, kinds
readers = []
try:
    import geojson  # python3-geojson: RFC 7946 validation
    obj = geojson.loads(text)
    assert obj.is_valid, obj.errors()
    readers.append("geojson " + geojson.__version__)
except ImportError:
    pass
try:
    from shapely.geometry import shape  # python3-shapely: geometry validity, orientation
    for f in g["features"]:
        if f["geometry"] is not None:
            s = shape(f["geometry"])
            assert s.is_valid, f"invalid {s.geom_type}"
            if s.geom_type == "Polygon":
                assert s.exterior.is_ccw
    readers.append("shapely")
except ImportError:
    pass
print(f"ok: {path}: {kinds}; readers: {', '.join(readers) or 'none installed (hand checks only)'}")
EOF
}

# 1. The normal run: the default (full) config and classes, found through the package.
if run_mapper --bag "$work/drive.bag" --out "$work/out" >"$work/summary.log" 2>"$work/progress.log"; then
  pass "map_from_bag on drive.bag (default config)"
  cat "$work/summary.log"
  for file in map.json map_trajectory_tum.txt summary.txt; do
    [ -s "$work/out/$file" ] || fail "$file missing or empty"
  done
  [ ! -e "$work/out/map.geojson" ] || fail "map.geojson written without a geo_origin"
  [ ! -e "$work/out/map.osm" ] || fail "map.osm written without a geo_origin"
  [ "$(grep -c "^no GeoJSON, no Lanelet2 OSM: no geo_origin in the config" "$work/summary.log")" = 1 ] \
    || fail "no single 'no GeoJSON, no Lanelet2 OSM' line on stdout"
  grep -q "^outputs: .*map.geojson" "$work/out/summary.txt" && fail "summary lists map.geojson"
  grep -q "^frames read: 25$" "$work/out/summary.txt" || fail "summary: frames read is not 25"
  grep -q "^frames used: 25$" "$work/out/summary.txt" || fail "summary: not all 25 frames used"
  grep -q "frames/s" "$work/progress.log" || fail "no progress line on stderr"
  check_outputs "$work/out" || fail "output checks of the default run (above)"
  default_run=ok
else
  fail "map_from_bag on drive.bag (default config) exited $?:"; tail -5 "$work/progress.log"
fi

# The plain-IPM ablation (a `base:` config) maps the lane too (its curve: the control points
# without the phantom ends).
if run_mapper --bag "$work/drive.bag" --config "$repo/config/ablations/ipm.yaml" --out "$work/ipm" \
    >/dev/null 2>&1; then
  [ ! -e "$work/ipm/map.geojson" ] || fail "map.geojson (ipm) written without a geo_origin"
  /usr/bin/python3 - "$work/ipm" <<'EOF' || fail "lane of the ipm run"
import json, sys
m = json.load(open(sys.argv[1] + "/map.json"))
assert len(m["lanes"]) >= 1, "no lane mapped"
ys = [p[1] for p in m["lanes"][0]["control_points"][1:-1]]
assert all(abs(y - 1.675) < 0.3 for y in ys), (min(ys), max(ys))
print(f"ok: ipm config: {len(m['lanes'])} lane(s), {len(ys)} curve control points near y = 1.675")
EOF
else
  fail "map_from_bag with config/ablations/ipm.yaml"
fi

# 2. A geo origin: the GeoJSON is written, positions become lon/lat near it, map.json records
# the origin.
geo_config=$(overlay geo.yaml "geo_origin: {latitude_deg: 48.0, longitude_deg: 11.0, altitude_m: 500.0}")
if run_mapper --bag "$work/drive.bag" --config "$geo_config" --out "$work/geo" >"$work/geo.log" 2>&1; then
  check_geojson "$work/geo/map.geojson" wgs84 || fail "map.geojson (wgs84) checks"
  grep -q "no GeoJSON" "$work/geo.log" && fail "'no GeoJSON' printed with a geo_origin"
  # The Lanelet2 OSM: well-formed XML whose references resolve, the drive's lane a line string.
  /usr/bin/python3 - "$work/geo/map.osm" <<'EOF' && pass "map.osm (Lanelet2) checks" || fail "map.osm (Lanelet2) checks"
import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
assert root.tag == "osm" and root.get("version") == "0.6", root.attrib
nodes = {n.get("id"): n for n in root.findall("node")}
ways = {w.get("id"): w for w in root.findall("way")}
assert nodes and ways, "no nodes or ways"
for w in ways.values():
    refs = [nd.get("ref") for nd in w.findall("nd")]
    assert len(refs) >= 2 and all(r in nodes for r in refs), w.get("id")
for r in root.findall("relation"):
    assert all(m.get("ref") in ways for m in r.findall("member")), r.get("id")
for n in nodes.values():
    lat, lon = float(n.get("lat")), float(n.get("lon"))
    assert abs(lat - 48.0) < 0.01 and abs(lon - 11.0) < 0.01, (lat, lon)
lines = [w for w in ways.values() if any(t.get("k") == "type" and t.get("v") == "line_thin" for t in w.findall("tag"))]
assert lines, "no lane line string"
print("ok: map.osm: %d nodes, %d ways (%d lane line pieces), %d lanelets" % (len(nodes), len(ways), len(lines), len(root.findall("relation"))))
EOF
  /usr/bin/python3 -c '
import json, sys
o = json.load(open(sys.argv[1]))["geo_origin"]
assert o == {"latitude_deg": 48.0, "longitude_deg": 11.0, "altitude_m": 500.0,
            "heading_deg": 0.0}, o  # the heading is recorded too (0: the map frame is ENU)' \
    "$work/geo/map.json" && pass "map.json records the geo_origin" || fail "geo_origin in map.json"
  # A copy of that folder mapped again without an origin: the stale GeoJSON goes.
  cp -r "$work/geo" "$work/stale"
  plain_config=$(overlay plain.yaml)
  if run_mapper --bag "$work/drive.bag" --config "$plain_config" --out "$work/stale" >/dev/null 2>&1 &&
     [ ! -e "$work/stale/map.geojson" ] && [ ! -e "$work/stale/map.osm" ]; then
    pass "a stale map.geojson is removed by a run without geo_origin"
  else
    fail "stale map.geojson left (or the run failed)"
  fi
  /usr/bin/python3 - "$work/geo/map.geojson" <<'EOF' || fail "lon/lat of the arrow"
import json, sys
g = json.load(open(sys.argv[1]))
lons = [p[0] for f in g["features"] if f["geometry"] and f["geometry"]["type"] == "Polygon"
        for p in f["geometry"]["coordinates"][0]]
lats = [p[1] for f in g["features"] if f["geometry"] and f["geometry"]["type"] == "Polygon"
        for p in f["geometry"]["coordinates"][0]]
# 18..21 m east of the origin at 48 deg N: 0.00024..0.00029 deg of longitude.
assert 11.0002 < min(lons) and max(lons) < 11.0010, (min(lons), max(lons))
assert abs(sum(lats) / len(lats) - 48.0) < 1e-4
print(f"ok: wgs84 marking longitudes {min(lons):.6f}..{max(lons):.6f}")
EOF
else
  fail "map_from_bag with geo_origin"
fi

# 3. The extrinsic from the config when the bag has no /tf_static.
extrinsic_config=$(overlay extrinsic.yaml \
  "input: {extrinsic: {xyz: [1.0, 0.0, 1.5], rpy_deg: [-95.0, 0.0, -90.0]}}")
if run_mapper --bag "$work/no_tf.bag" --config "$extrinsic_config" --out "$work/cfg" >/dev/null 2>&1 &&
   grep -q "^extrinsic: config input.extrinsic" "$work/cfg/summary.txt" &&
   grep -q "^frames used: 25$" "$work/cfg/summary.txt" && check_outputs "$work/cfg"; then
  pass "extrinsic from the config"
else
  fail "extrinsic from the config"
fi

# 4. Sync: camera_info 2 ms off the masks. Exact pairs none; approximate pairs all.
exact_config=$(overlay exact.yaml "ros: {sync: exact}")
run_mapper --bag "$work/shifted.bag" --config "$exact_config" --out "$work/exact" >/dev/null 2>&1 || fail "exact sync run"
grep -q "^  no_camera_info: 25$" "$work/exact/summary.txt" && pass "exact sync skips shifted camera_info" \
  || fail "exact sync: $(grep -A3 skipped "$work/exact/summary.txt")"
approx_config=$(overlay approx.yaml "ros: {sync: approximate}")
run_mapper --bag "$work/shifted.bag" --config "$approx_config" --out "$work/approx" >/dev/null 2>&1 \
  || fail "approximate sync run"
grep -q "^frames used: 25$" "$work/approx/summary.txt" && check_outputs "$work/approx" &&
  pass "approximate sync pairs them" \
  || fail "approximate sync: $(grep frames "$work/approx/summary.txt")"

# 5. A bag loop: counted as a time jump; every frame is accounted for.
run_mapper --bag "$work/loop.bag" --config "$exact_config" --out "$work/loop" >/dev/null 2>&1 || fail "loop run"
if grep -q "time jumps: 1$" "$work/loop/summary.txt" && grep -q "^frames read: 50$" "$work/loop/summary.txt" &&
   grep -q "^frames used: 25$" "$work/loop/summary.txt" && grep -q "^frames skipped: 25$" "$work/loop/summary.txt"; then
  pass "bag loop: 1 time jump, 25 used + 25 skipped"
else
  fail "bag loop summary:"; cat "$work/loop/summary.txt"
fi

# 6. Bad input: one clear line, exit 2.
expect_input_error "missing bag" "no such bag" --bag "$work/nope.bag" --out "$work/x"
expect_input_error "no --out" "usage" --bag "$work/drive.bag"
expect_input_error "unknown flag" "unknown argument" --bag "$work/drive.bag" --out "$work/x" --fast
bad_key=$(overlay bad_key.yaml "bogus_key: 1")
expect_input_error "bad config key" "bogus_key: unknown key" --bag "$work/drive.bag" --config "$bad_key" --out "$work/x"
bad_value=$(overlay bad_value.yaml "ros: {sync: sometimes}")
expect_input_error "bad config value" "ros.sync" --bag "$work/drive.bag" --config "$bad_value" --out "$work/x"
missing_topic=$(overlay missing_topic.yaml "ros: {mask_topic: /nope}")
expect_input_error "missing topic" "/nope" --bag "$work/drive.bag" --config "$missing_topic" --out "$work/x"
expect_input_error "no extrinsic" "no extrinsic" --bag "$work/no_tf.bag" --out "$work/x"
echo "not a bag" >"$work/garbage.bag"
expect_input_error "not a bag" "garbage.bag" --bag "$work/garbage.bag" --out "$work/x"
expect_input_error "missing classes" "nope.yaml" --bag "$work/drive.bag" --classes "$work/nope.yaml" --out "$work/x"
expect_input_error "malformed --callgrind-spans" "callgrind-spans: span '3:2'" --bag "$work/drive.bag" --out "$work/x" --callgrind-spans 3:2
expect_input_error "--callgrind-spans outside valgrind" "not running under valgrind" --bag "$work/drive.bag" --out "$work/x" --callgrind-spans 0:1e12

# 7. The command line: --help names every option with its default and exits 0; an unknown
# option exits 2 (above), and so does an abbreviated one.
help_rc=0
run_mapper --help >"$work/help.txt" 2>"$work/help.err" || help_rc=$?
if [ "$help_rc" -ne 0 ] || [ -s "$work/help.err" ]; then
  fail "--help: exit $help_rc, stderr: $(cat "$work/help.err")"
else
  missing=""
  for option in --bag --config --classes --async --out --stats-out --publish-stats-out \
    --calibration-out --callgrind-spans --help; do
    grep -q -- "$option" "$work/help.txt" || missing="$missing $option"
  done
  described=$(grep -o -e "(default: " -e "(required)" "$work/help.txt" | wc -l)
  if [ -n "$missing" ]; then
    fail "--help does not name:$missing"
  elif [ "$described" -lt 8 ]; then
    fail "--help gives a default (or 'required') for $described of the 8 options"
  else
    pass "--help names every option with its default, exit 0"
  fi
fi
expect_input_error "abbreviated option" "unknown argument '--conf'" --bag "$work/drive.bag" --out "$work/x" --conf c.yaml

# 8. --stats-out: one CSV row per frame read (used or skipped), CPU time and RSS; startup_s
# in the summary and the first-frame line on stderr.
if run_mapper --bag "$work/loop.bag" --config "$exact_config" --out "$work/stats" \
    --stats-out "$work/stats.csv" >/dev/null 2>"$work/stats.err"; then
  /usr/bin/python3 - "$work/stats.csv" "$work/stats/summary.txt" "$work/stats.err" <<'EOF' \
    && pass "--stats-out: 50 rows (25 used, 25 skipped), startup_s" || fail "--stats-out checks"
import csv, json, re, sys
rows = list(csv.reader(open(sys.argv[1])))
assert rows[0] == ["frame", "stamp", "cpu_s", "rss_kb"], rows[0]
rows = rows[1:]
assert len(rows) == 50, f"{len(rows)} rows, expected 50 (every frame read)"
assert [int(r[0]) for r in rows] == list(range(50)), "frame is the 0-based count"
stamps = [float(r[1]) for r in rows]
# The loop bag: 25 masks at T0 + 0.1 k, then the same stamps again.
expected = [1700000000.0 + 0.1 * (k % 25 + 1) for k in range(50)]
assert all(abs(a - b) < 1e-5 for a, b in zip(stamps, expected)), stamps[:3]
cpu = [float(r[2]) for r in rows]
assert cpu[0] > 0 and all(b >= a for a, b in zip(cpu, cpu[1:])), "cpu_s not non-decreasing"
assert all(int(r[3]) > 10000 for r in rows), "rss_kb"
summary = open(sys.argv[2]).read()
m = re.search(r"^startup_s: ([0-9.]+) ", summary, re.M)
assert m and 0 < float(m.group(1)) < 60, "startup_s in the summary"
meta = json.load(open(sys.argv[2].replace("summary.txt", "map.json")))["metadata"]
assert abs(meta["startup_s"] - float(m.group(1))) < 1e-3, "map.json metadata startup_s"
err = open(sys.argv[3]).read()
assert re.search(r"^map_from_bag: first frame mapped after [0-9]+\.[0-9]{3} s$", err, re.M), err
print(f"ok: {len(rows)} rows; cpu {cpu[0]:.3f} -> {cpu[-1]:.3f} s; startup_s {m.group(1)}")
EOF
else
  fail "map_from_bag --stats-out exited $?: $(tail -3 "$work/stats.err")"
fi
rc=0
run_mapper --bag "$work/drive.bag" --out "$work/x" --stats-out "$work/no_dir/stats.csv" \
  >/dev/null 2>"$work/stderr" || rc=$?
if [ "$rc" -eq 1 ] && [ "$(wc -l <"$work/stderr")" -eq 1 ] && grep -q "stats" "$work/stderr"; then
  pass "unwritable --stats-out -> exit 1: $(cat "$work/stderr")"
else
  fail "unwritable --stats-out: exit $rc: $(cat "$work/stderr")"
fi
rc=0
run_mapper --bag "$work/drive.bag" --out "$work/x" --publish-stats-out "$work/no_dir/publish.csv" \
  >/dev/null 2>"$work/stderr" || rc=$?
if [ "$rc" -eq 1 ] && [ "$(wc -l <"$work/stderr")" -eq 1 ] && grep -q "publish.csv" "$work/stderr"; then
  pass "unwritable --publish-stats-out -> exit 1: $(cat "$work/stderr")"
else
  fail "unwritable --publish-stats-out: exit $rc: $(cat "$work/stderr")"
fi

# 9. --calibration-out: the refined extrinsic as a config the next run starts from (on the
# bag without /tf_static, whose extrinsic then comes from that file alone).
if run_mapper --bag "$work/drive.bag" --out "$work/cal" --calibration-out "$work/calibration.yaml" \
    >"$work/cal.log" 2>&1 &&
   grep -q "^calibration: sigma roll pitch yaw .* observed: " "$work/cal/summary.txt" &&
   grep -q "static_transform_publisher" "$work/calibration.yaml" &&
   grep -q "<joint name=" "$work/calibration.yaml" &&
   run_mapper --bag "$work/no_tf.bag" --config "$work/calibration.yaml" --out "$work/cal2" \
    >/dev/null 2>&1 &&
   grep -q "^extrinsic: config input.extrinsic" "$work/cal2/summary.txt" &&
   /usr/bin/python3 - "$work/cal/map.json" "$work/cal2/map.json" <<'EOF'
import json, sys
first, second = (json.load(open(p)) for p in sys.argv[1:3])
# The second run started from the first one's refined extrinsic.
a, b = first["T_base_cam"], second["T_base_cam_initial"]
assert max(abs(x - y) for x, y in zip(a["t"], b["t"])) < 1e-6, (a, b)
assert max(abs(abs(x) - abs(y)) for x, y in zip(a["q_xyzw"], b["q_xyzw"])) < 1e-6, (a, b)
cal = first["T_base_cam_calibration"]
assert len(cal["covariance"]) == 36 and len(cal["observed"]) == 6, cal
EOF
then
  pass "--calibration-out round-trips into the next run's input.extrinsic"
else
  fail "--calibration-out: $(tail -3 "$work/cal.log")"
fi

# 10. --callgrind-spans under callgrind: one dump per span, its trigger naming the frames
# counted (the first frame only starts the count) and a non-zero instruction total; the map
# is written as without it. Skipped (said so) where valgrind is not installed.
if command -v valgrind >/dev/null; then
  mkdir -p "$work/cg"
  cg_rc=0
  rosrun --prefix "valgrind --tool=callgrind --instr-atstart=no \
    --callgrind-out-file=$work/cg/callgrind.out.%p" ipm_road_mapper map_from_bag \
    --bag "$work/drive.bag" --out "$work/cg" --callgrind-spans 0:1e12 >"$work/cg.log" 2>&1 || cg_rc=$?
  dump=$(grep -l "^desc: Trigger: Client Request: span 0 frames" "$work"/cg/callgrind.out.* 2>/dev/null | head -1)
  frames=$(sed -n 's/^desc: Trigger: Client Request: span 0 frames \([0-9]*\).*/\1/p' "$dump" 2>/dev/null)
  total=$(sed -n 's/^totals: *\([0-9]*\)/\1/p' "$dump" 2>/dev/null)
  if [ "$cg_rc" -eq 0 ] && [ "${frames:-0}" -eq 24 ] && [ "${total:-0}" -gt 1000000 ] \
    && [ -s "$work/cg/map.json" ]; then
    pass "--callgrind-spans: span 0 counted $frames frames, $total instructions"
  else
    fail "--callgrind-spans: exit $cg_rc, frames '${frames}', totals '${total}': $(tail -3 "$work/cg.log")"
  fi
else
  echo "SKIP --callgrind-spans under callgrind: valgrind not installed"
fi

if [ "$failures" -ne 0 ]; then
  echo "$failures check(s) failed"
  exit 1
fi
echo "all map_from_bag checks passed"
