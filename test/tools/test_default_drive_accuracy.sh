#!/usr/bin/env bash
# Accuracy regression guard on the whole default drive (public_road, seed 1): generated here,
# mapped with plain IPM (config/ablations/ipm.yaml) and with the full method
# (config/mapper.yaml), both scored by evaluate_map. The bounds are loose versions of the
# benchmark's figures (docs/benchmark.md): they catch a broken estimator or front end, not
# a centimeter. Accuracy and speed are measured by scripts/benchmark.sh, not here.
# Runs in the devel space's environment (ctest) or by hand after sourcing it.
set -eo pipefail

src="${IRM_SOURCE_DIR:-$(cd "$(dirname "$0")/../.." && pwd)}"
work="$(mktemp -d /tmp/irm_accuracy_XXXXXX)"
trap 'rm -rf "$work"' EXIT
export ROS_HOME="$work/ros_home"
fail() { echo "FAIL: $*" >&2; exit 1; }
tool() {
  catkin_find --first-only --libexec ipm_road_mapper "$1" 2>/dev/null ||
    fail "ipm_road_mapper/$1 not found (source the devel space's setup.bash)"
}
generate_drive=$(tool generate_drive)
map_from_bag=$(tool map_from_bag)
evaluate_map=$(tool evaluate_map)

"$generate_drive" --scenario "$src/config/scenarios/public_road.yaml" --seed 1 \
  --out "$work/drive" >"$work/generate.log" || fail "generate_drive: $(tail -3 "$work/generate.log")"

for method in ipm full; do
  config="$src/config/mapper.yaml"
  [ "$method" = ipm ] && config="$src/config/ablations/ipm.yaml"
  "$map_from_bag" --bag "$work/drive/drive.bag" --config "$config" --out "$work/$method" \
    >"$work/$method.log" 2>&1 || fail "map_from_bag ($method): $(tail -3 "$work/$method.log")"
  "$evaluate_map" --map "$work/$method/map.json" --ground-truth "$work/drive/ground_truth.json" \
    --json "$work/$method/metrics.json" >"$work/$method/metrics.txt" ||
    fail "evaluate_map ($method)"
done

/usr/bin/python3 - "$work/ipm/metrics.json" "$work/full/metrics.json" <<'EOF'
import json, sys
ipm, full = (json.load(open(p)) for p in sys.argv[1:3])
failures = []
def check(ok, what, value):
    print("%-4s %-58s %s" % ("ok" if ok else "FAIL", what, value))
    if not ok:
        failures.append(what)

# Plain IPM: the paper's error regime (issue: synthetic drives), complete and continuous.
check(0.4 <= ipm["marking_ape_mean_m"] <= 0.8, "IPM marking APE in the 0.4-0.8 m regime",
      "%.3f m" % ipm["marking_ape_mean_m"])
check(ipm["marking_recall"] >= 0.95, "IPM finds >= 95% of the markings", ipm["marking_recall"])
check(ipm["marking_duplicates"] == 0, "IPM: no duplicate markings", ipm["marking_duplicates"])
check(ipm["lane_recall"] == 1.0 and ipm["lane_splines_per_matched_gt_lane"] <= 1.0,
      "IPM: every GT lane covered by exactly one spline",
      "%s, %.2f" % (ipm["lane_recall"], ipm["lane_splines_per_matched_gt_lane"]))
check(ipm["extrinsic_rot_err_deg"] == ipm["extrinsic_rot_err_deg_initial"],
      "IPM leaves the extrinsic alone", "%.3f deg" % ipm["extrinsic_rot_err_deg"])

# The full method (benchmark seed 1: markings 0.094 m, lanes 0.058 m, extrinsic 0.058 deg,
# poses 0.087 -> 0.038 m).
check(full["marking_ape_mean_m"] < 0.15, "full: marking APE < 0.15 m",
      "%.3f m" % full["marking_ape_mean_m"])
check(full["marking_ape_mean_m"] * 4 < ipm["marking_ape_mean_m"], "full: markings 4x better than IPM",
      "%.1fx" % (ipm["marking_ape_mean_m"] / full["marking_ape_mean_m"]))
check(full["lane_ape_mean_m"] < 0.10, "full: lane APE < 0.10 m", "%.3f m" % full["lane_ape_mean_m"])
check(full["lane_f1"] >= 0.99, "full: lane F1 1", full["lane_f1"])
check(full["marking_recall"] >= 0.95 and full["marking_duplicates"] == 0,
      "full: >= 95% of the markings, no duplicates",
      "%s, %s" % (full["marking_recall"], full["marking_duplicates"]))
check(full["extrinsic_rot_err_deg"] < 0.2 and
      full["extrinsic_rot_err_deg"] < 0.5 * full["extrinsic_rot_err_deg_initial"],
      "full: extrinsic rotation < 0.2 deg and halved",
      "%.3f -> %.3f deg" % (full["extrinsic_rot_err_deg_initial"], full["extrinsic_rot_err_deg"]))
check(full["pose_trans_err_m"] < 0.75 * full["pose_trans_err_m_input"],
      "full: pose translation error down by a quarter",
      "%.3f -> %.3f m" % (full["pose_trans_err_m_input"], full["pose_trans_err_m"]))
if failures:
    sys.exit("%d accuracy check(s) failed" % len(failures))
EOF
echo "default drive accuracy checks passed"
