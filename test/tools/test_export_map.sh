#!/usr/bin/env bash
# export_map (src/tools/export_map.cpp): a map saved without a geo_origin gets its GeoJSON and
# Lanelet2 OSM once an origin is given; a map that recorded one is exported at it; without
# any origin, with a bad origin or a corrupt map it exits 2 with one line and writes nothing.
set -eo pipefail
export PATH="/usr/bin:/bin:$PATH"
repo="${IRM_SOURCE_DIR:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}"
work="$(mktemp -d /tmp/irm_export_map_XXXXXX)"
trap 'rm -rf "$work"' EXIT
export ROS_HOME="$work/ros_home"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
pass() { echo "ok: $*"; }
export_map() { rosrun ipm_road_mapper export_map "$@"; }

/usr/bin/python3 "$repo/test/tools/make_test_bag.py" "$work/drive.bag"
{ echo "base: $repo/config/mapper.yaml"; echo "backend: {enabled: false}"; } >"$work/plain.yaml"
rosrun ipm_road_mapper map_from_bag --bag "$work/drive.bag" --config "$work/plain.yaml" \
  --out "$work/out" >"$work/map.log" 2>&1 || { echo "FAIL: map_from_bag: $(tail -3 "$work/map.log")"; exit 1; }
[ ! -e "$work/out/map.osm" ] || fail "map_from_bag wrote map.osm without a geo_origin"

expect_input_error() {
  local name="$1" pattern="$2"; shift 2
  local rc=0
  export_map "$@" >"$work/stdout" 2>"$work/stderr" || rc=$?
  if [ "$rc" -ne 2 ] || [ "$(wc -l <"$work/stderr")" -ne 1 ] || ! grep -q -- "$pattern" "$work/stderr"; then
    fail "$name: exit $rc, stderr: $(cat "$work/stderr")"
  else
    pass "$name -> exit 2: $(cat "$work/stderr")"
  fi
}

# No origin anywhere: nothing written.
expect_input_error "no origin" "records no geo_origin" --map "$work/out/map.json"
[ ! -e "$work/out/map.osm" ] && [ ! -e "$work/out/map.geojson" ] || fail "files written without an origin"
expect_input_error "latitude out of range" "latitude" --map "$work/out/map.json" --geo-origin 91,11
expect_input_error "not a number" "not a number" --map "$work/out/map.json" --geo-origin 48,east
expect_input_error "one value" "expected lat,lon" --map "$work/out/map.json" --geo-origin 48
printf '{"format": "ipm_road_mapper' >"$work/corrupt.json"
expect_input_error "corrupt map" "corrupt.json" --map "$work/corrupt.json" --geo-origin 48,11

# With an origin: both files beside the map, positions near it.
if export_map --map "$work/out/map.json" --geo-origin 48.0,11.0,500 >"$work/export.log" 2>&1; then
  cat "$work/export.log"
  /usr/bin/python3 - "$work/out" <<'PY' && pass "exported beside the map" || fail "exported files"
import json, sys, xml.etree.ElementTree as ET
folder = sys.argv[1]
g = json.load(open(folder + "/map.geojson"))
assert g["coordinate_system"] == "wgs84" and g["features"], g.get("coordinate_system")
root = ET.parse(folder + "/map.osm").getroot()
nodes = root.findall("node")
assert nodes and all(abs(float(n.get("lat")) - 48.0) < 0.01 for n in nodes)
m = json.load(open(folder + "/map.json"))
ids = {t.get("v") for w in root.findall("way") for t in w.findall("tag") if t.get("k") == "irm:id"}
assert ids == {str(e["id"]) for e in m["markings"] + m["lanes"]}, (ids, len(m["lanes"]))
PY
else
  fail "export_map with --geo-origin: $(cat "$work/export.log")"
fi

# A map that recorded its origin is exported at it, into --out.
{ cat "$work/plain.yaml"; echo "geo_origin: {latitude_deg: -33.9, longitude_deg: 151.2}"; } >"$work/geo.yaml"
rosrun ipm_road_mapper map_from_bag --bag "$work/drive.bag" --config "$work/geo.yaml" \
  --out "$work/geo" >/dev/null 2>&1 || fail "map_from_bag with a geo_origin"
if export_map --map "$work/geo/map.json" --out "$work/again" >"$work/again.log" 2>&1 &&
   grep -q "recorded in the map" "$work/again.log" && cmp -s "$work/geo/map.osm" "$work/again/map.osm"; then
  pass "the recorded origin: the same map.osm as map_from_bag wrote"
else
  fail "export at the recorded origin: $(cat "$work/again.log")"
fi

if [ "$failures" -eq 0 ]; then echo "export_map: all checks passed"; else echo "$failures failure(s)"; exit 1; fi
