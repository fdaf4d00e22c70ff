#!/usr/bin/env bash
# The main job on the embedded default drive: set-up, generate the default synthetic drive
# (cached until the scenario or the generator changes), map it with the full method and with
# the plain-IPM baseline, print the accuracy table, and write the map files and a plot.
#   IRM_OUT=<dir>          output folder (default: out/demo in the repository)
#   IRM_SCENARIO=<yaml>    scenario (default: config/scenarios/public_road.yaml)
#   IRM_SEED=<n>           seed (default: 1)
set -eo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${IRM_BUILD_DIR:-$repo/.build}"
out="${IRM_OUT:-$repo/out/demo}"
scenario="${IRM_SCENARIO:-$repo/config/scenarios/public_road.yaml}"
seed="${IRM_SEED:-1}"
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
export ROS_HOME="$build/ros_home"

bash "$repo/scripts/setup.sh"
# shellcheck disable=SC1091
source "$build/devel/setup.bash"
bin="$build/devel/lib/ipm_road_mapper"
mkdir -p "$out"

# 1. The drive: regenerate only when the scenario, the seed or the generator changed.
drive="$out/drive"
key="$(sha1sum "$scenario" "$bin/generate_drive" | sha1sum | cut -c1-16)-seed$seed"
if [ "$(cat "$drive/.key" 2>/dev/null)" != "$key" ] || [ ! -f "$drive/drive.bag" ]; then
  echo "[demo] generating $(basename "$scenario" .yaml) (seed $seed) into $drive"
  rm -rf "$drive"
  "$bin/generate_drive" --scenario "$scenario" --seed "$seed" --out "$drive"
  echo "$key" >"$drive/.key"
else
  echo "[demo] drive cached: $drive (delete it to regenerate)"
fi

# 2. Map it: the full method (config/mapper.yaml) and the plain-IPM baseline.
run_config() {  # name config
  local name="$1" config="$2"
  echo "[demo] mapping with $name ($config)"
  "$bin/map_from_bag" --bag "$drive/drive.bag" --config "$config" --out "$out/$name"
  "$bin/evaluate_map" --map "$out/$name/map.json" --ground-truth "$drive/ground_truth.json" \
    --json "$out/$name/metrics.json" >"$out/$name/metrics.txt"
}
run_config ipm "$repo/config/ablations/ipm.yaml"
run_config mapper "$repo/config/mapper.yaml"

echo
echo "=== plain IPM baseline (config/ablations/ipm.yaml) ==="
cat "$out/ipm/metrics.txt"
echo
echo "=== ipm_road_mapper (config/mapper.yaml) ==="
cat "$out/mapper/metrics.txt"

/usr/bin/python3 "$repo/scripts/plot_map.py" --map "$out/mapper/map.json" \
  --ground-truth "$drive/ground_truth.json" --metrics "$out/mapper/metrics.json" \
  --out "$out/mapper/map.png"
echo
echo "[demo] files:"
for f in mapper/map.json mapper/map.geojson mapper/trajectory_tum.txt mapper/metrics.json \
         mapper/map.png mapper/summary.txt drive/drive.bag drive/ground_truth.json; do
  echo "  $out/$f"
done
