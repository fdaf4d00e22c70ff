#!/usr/bin/env bash
# The real-geometry drive (../shared/data/av2_pit_dev: real Argoverse 2 trajectory, portrait
# camera and 3D road, synthetic masks; see its README) mapped with the full method
# (config/mapper.yaml) and scored by evaluate_map, with loose bounds that hold today: no
# crash, the map files written, lane F1 >= 0.5, lane APE <= 0.3 m, every lane spline on a
# painted line, and calibration and poses no worse than their input; the view's ceiling is
# 2 of 4 crossings and 5 of 8 lines. Crossing recall is not bounded yet (issue 11). Mapped again with the package's class table instead of the drive's,
# the summary names the class whose views its size bounds drop. The data is read in place, never copied (non-commercial license);
# without it the test exits 77, which ctest reports as skipped (SKIP_RETURN_CODE).
# Runs in the devel space's environment (ctest) or by hand after sourcing it.
set -eo pipefail

src="${IRM_SOURCE_DIR:-$(cd "$(dirname "$0")/../.." && pwd)}"
data="${IRM_SHARED_DIR:-$src/../shared}/data/av2_pit_dev"
if [ ! -f "$data/drive.bag" ] || [ ! -f "$data/ground_truth.json" ]; then
  echo "skipped: $data not present"
  exit 77
fi
work="$(mktemp -d /tmp/irm_av2_XXXXXX)"
trap 'rm -rf "$work"' EXIT
export ROS_HOME="$work/ros_home"
fail() { echo "FAIL: $*" >&2; exit 1; }
tool() {
  catkin_find --first-only --libexec ipm_road_mapper "$1" 2>/dev/null ||
    fail "ipm_road_mapper/$1 not found (source the devel space's setup.bash)"
}
map_from_bag=$(tool map_from_bag)
evaluate_map=$(tool evaluate_map)

"$map_from_bag" --bag "$data/drive.bag" --config "$src/config/mapper.yaml" \
  --classes "$data/classes.yaml" --out "$work/map" >"$work/map.log" 2>&1 ||
  fail "map_from_bag: $(tail -3 "$work/map.log")"
for f in map.json map_trajectory_tum.txt; do
  [ -s "$work/map/$f" ] || fail "map_from_bag wrote no $f"
done
# With its own class table no class is suspect; with the package's, whose id 10 is an arrow
# of at most 10 x 4 m, the crossings' views are oversized and the summary names the class
# (core/frontend/class_size_check.h).
if grep -q "^warning: class" "$work/map.log"; then
  fail "a class named suspect with the drive's own table: $(grep '^warning: class' "$work/map.log")"
fi
"$map_from_bag" --bag "$data/drive.bag" --config "$src/config/mapper.yaml" \
  --classes "$src/config/classes.yaml" --out "$work/map_package_table" >"$work/map2.log" 2>&1 ||
  fail "map_from_bag with the package's table: $(tail -3 "$work/map2.log")"
grep -q "^warning: class 10 'arrow_straight'" "$work/map2.log" ||
  fail "the package's class table on this drive: no warning naming class 10"
echo "ok   class table check: $(grep '^warning: class' "$work/map2.log")"
"$evaluate_map" --map "$work/map/map.json" --ground-truth "$data/ground_truth.json" \
  --json "$work/metrics.json" >"$work/evaluate.log" 2>&1 ||
  fail "evaluate_map: $(tail -3 "$work/evaluate.log")"

/usr/bin/python3 - "$work/metrics.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
failures = []
def check(ok, what, value):
    print("%-4s %-60s %s" % ("ok" if ok else "FAIL", what, value))
    if not ok:
        failures.append(what)

# Today (docs/benchmark.md): lane F1 0.667, APE 0.160 m, precision 1.0; rotation 1.079 ->
# 0.878 deg, IPM grid 0.488 -> 0.448 m, poses 0.181 -> 0.173 m.
check(m["lane_f1"] >= 0.5, "lane F1 >= 0.5", "%.3f" % m["lane_f1"])
check(m["lane_ape_mean_m"] is not None and m["lane_ape_mean_m"] <= 0.3, "lane APE <= 0.3 m",
      m["lane_ape_mean_m"])
check(m["lane_precision"] >= 0.75, "lane precision >= 0.75 (splines on painted lines)",
      "%.3f" % m["lane_precision"])
check(m["extrinsic_rot_err_deg"] <= m["extrinsic_rot_err_deg_initial"],
      "extrinsic rotation no worse than the rough one",
      "%.3f -> %.3f deg" % (m["extrinsic_rot_err_deg_initial"], m["extrinsic_rot_err_deg"]))
check(m["ipm_grid_err_m"] <= m["ipm_grid_err_m_initial"], "IPM grid error no worse than rough",
      "%.3f -> %.3f m" % (m["ipm_grid_err_m_initial"], m["ipm_grid_err_m"]))
check(m["pose_has_trajectory"] and m["pose_trans_err_m"] <= m["pose_trans_err_m_input"] + 0.01,
      "poses no worse than the odometry (+0.01 m)",
      "%.3f -> %.3f m" % (m["pose_trans_err_m_input"], m["pose_trans_err_m"]))
# The view's ceiling (eval/view_ceiling.h, from the ground truth alone): two of the four
# crossings are never in view at one end (their seen parts are centered 2.99 and 2.34 m from
# theirs, beyond the 2 m gate), three of the eight lines lie mostly beyond 40 m of every pose.
# A map that records what was seen, and guesses nothing beyond, cannot beat it.
check(m["ceiling_markings_reachable"] == 2, "view ceiling: 2 of 4 crossings reachable",
      m["ceiling_markings_reachable"])
check(m["ceiling_lanes_reachable"] == 5, "view ceiling: 5 of 8 lines reachable within 40 m",
      m["ceiling_lanes_reachable"])
print("crossing recall (not bounded yet): %.2f of %d" % (m["marking_recall"],
                                                        m["marking_gt_visible"]))
sys.exit(1 if failures else 0)
PY
echo "av2_pit_dev drive: all checks passed"
