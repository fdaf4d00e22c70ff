#!/usr/bin/env bash
# The Lanelet2 export read by Lanelet2 itself (lanelet2 1.2.3, the PyPI wheel, cached in the
# build folder): a map of three parallel lines (the test bag's mapped line and two copies 3.5 m
# either side) exported by export_map loads with no error, gives two lanelets that are each
# other's neighbours in Lanelet2's routing graph (lane change allowed over the dashed middle
# line only), a graph without validity errors, points at their map-frame metres under
# LocalCartesianProjector, and the points of a stretch a join laid (map.json `unmeasured`)
# with the attribute irm:measured = no, on that line only. Without the wheel (no network, no pip, another Python) the test
# exits 77: skipped.
set -eo pipefail
export PATH="/usr/bin:/bin:$PATH"
repo="${IRM_SOURCE_DIR:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}"
work="$(mktemp -d /tmp/irm_lanelet2_load_XXXXXX)"
trap 'rm -rf "$work"' EXIT
export ROS_HOME="$work/ros_home"
skip() { echo "skipped: $*"; exit 77; }

# Lanelet2's Python bindings: the cp311 manylinux wheel, unpacked (a wheel is a zip).
cache="${IRM_LANELET2_CACHE:-$PWD/lanelet2_py}"
if [ ! -f "$cache/lanelet2/__init__.py" ]; then
  [ "$(/usr/bin/python3 -c 'import sys; print("%d%d" % sys.version_info[:2])')" = 311 ] ||
    skip "the lanelet2 1.2.3 wheel is for Python 3.11"
  fetched=""
  for python in python3 /usr/bin/python3; do
    if timeout 120 "$python" -m pip download --quiet --no-deps --only-binary=:all: \
        --python-version 3.11 --platform manylinux_2_31_x86_64 lanelet2==1.2.3 \
        -d "$work/wheel" >/dev/null 2>&1; then
      fetched=yes
      break
    fi
  done
  [ -n "$fetched" ] || skip "lanelet2 wheel not downloadable (no pip or no network)"
  rm -rf "$cache.partial"
  /usr/bin/python3 -c 'import sys, zipfile, glob; zipfile.ZipFile(glob.glob(sys.argv[1] + "/*.whl")[0]).extractall(sys.argv[2])' \
    "$work/wheel" "$cache.partial"
  rm -rf "$cache" && mv "$cache.partial" "$cache"
fi
PYTHONPATH="$cache" /usr/bin/python3 -c "import lanelet2.io" 2>/dev/null || skip "lanelet2 does not import here"

# The test bag's map and two more lines beside its one.
/usr/bin/python3 "$repo/test/tools/make_test_bag.py" "$work/drive.bag"
{ echo "base: $repo/config/mapper.yaml"; echo "backend: {enabled: false}"; } >"$work/plain.yaml"
rosrun ipm_road_mapper map_from_bag --bag "$work/drive.bag" --config "$work/plain.yaml" \
  --out "$work/out" >"$work/map.log" 2>&1 || { echo "FAIL: map_from_bag: $(tail -3 "$work/map.log")"; exit 1; }
/usr/bin/python3 - "$work/out/map.json" "$work/three.json" <<'PY'
import copy, json, sys
m = json.load(open(sys.argv[1]))
assert len(m["lanes"]) == 1, len(m["lanes"])
middle = m["lanes"][0]
middle["style"] = "dashed"
lanes = [middle]
for k, dy in ((1, -3.5), (2, 3.5)):
    lane = copy.deepcopy(middle)
    lane["id"] = 1000 + k
    lane["style"] = "solid"
    lane["control_points"] = [[p[0], p[1] + dy, p[2]] for p in middle["control_points"]]
    lanes.append(lane)
# The right line's control points 3-4 laid by a join: no pixel measured them.
assert len(lanes[1]["control_points"]) >= 8, len(lanes[1]["control_points"])
lanes[1]["unmeasured"] = [[3, 4]]
m["lanes"] = lanes
json.dump(m, open(sys.argv[2], "w"))
PY
rosrun ipm_road_mapper export_map --map "$work/three.json" --geo-origin 48.0,11.0,500 \
  --out "$work/export" >"$work/export.log" 2>&1 || { echo "FAIL: export_map: $(cat "$work/export.log")"; exit 1; }
cat "$work/export.log"

PYTHONPATH="$cache" /usr/bin/python3 - "$work/export/map.osm" <<'PY'
import sys
import lanelet2
from lanelet2.io import Origin
from lanelet2.projection import LocalCartesianProjector
m, errors = lanelet2.io.loadRobust(sys.argv[1], LocalCartesianProjector(Origin(48.0, 11.0, 500.0)))
assert not errors, errors
lanelets = list(m.laneletLayer)
assert len(lanelets) == 2, len(lanelets)
rules = lanelet2.traffic_rules.create(lanelet2.traffic_rules.Locations.Germany,
                                      lanelet2.traffic_rules.Participants.Vehicle)
graph = lanelet2.routing.RoutingGraph(m, rules)
assert not graph.checkValidity(), graph.checkValidity()
a, b = lanelets
assert {graph.left(a).id if graph.left(a) else None, graph.right(a).id if graph.right(a) else None} - {None} == {b.id}, \
    "the two lanelets are not lane-change neighbours over the dashed line"
for p in m.pointLayer:
    assert abs(p.x - float(p.attributes["local_x"])) < 2e-3 and abs(p.y - float(p.attributes["local_y"])) < 2e-3, p
# The laid stretch's points carry irm:measured = no, on the right line only.
laid = [p for p in m.pointLayer if "irm:measured" in p.attributes]
assert laid, "no point of the laid stretch carries irm:measured"
assert all(p.attributes["irm:measured"] == "no" for p in laid)
on_right = {p.id for ls in m.lineStringLayer
            if "irm:id" in ls.attributes and ls.attributes["irm:id"] == "1001" for p in ls}
assert {p.id for p in laid} <= on_right, "a laid point off the line the join laid"
print("ok: lanelet2 loads map.osm: 2 lanelets, neighbours over the dashed line, routing graph valid, "
      "%d points at their map-frame metres, %d of the laid stretch flagged" % (len(m.pointLayer), len(laid)))
PY
echo "lanelet2 load: all checks passed"
