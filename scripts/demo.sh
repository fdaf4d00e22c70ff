#!/usr/bin/env bash
# The main job on the embedded default drive: set-up, generate the default synthetic drive
# (cached until the scenario or the generator changes), map it with the full method and with
# the plain-IPM baseline, print the accuracy table, and write the map files and a plot.
#   IRM_OUT=<dir>          output folder (default: out/demo in the repository)
#   IRM_SCENARIO=<yaml>    scenario (default: config/scenarios/public_road.yaml)
#   IRM_SEED=<n>           seed (default: 1)
#   IRM_DEMO_LIVE=1        also map the drive live: roslaunch demo.launch plays the bag into
#                          the nodelet (real time, ~40 s more), then its map is evaluated and
#                          compared with the offline one (scripts/compare_maps.py)
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

# 3. Optionally the same drive live, through the nodelet (launch/demo.launch).
if [ "${IRM_DEMO_LIVE:-0}" = 1 ]; then
  echo
  echo "[demo] mapping live: roslaunch ipm_road_mapper demo.launch (bag played in real time)"
  rm -rf "$out/live"
  port=$((11600 + RANDOM % 300))
  ROS_MASTER_URI="http://localhost:$port" roslaunch -p "$port" ipm_road_mapper demo.launch \
    bag:="$drive/drive.bag" save_map_path:="$out/live/map.json" >"$out/live.log" 2>&1 &
  launch_pid=$!
  # Wait for the player to finish (seen in the graph, then gone), then stop: the nodelet
  # saves its map. A failed `rosnode list` (master still starting, busy) proves nothing.
  seen=0
  for i in $(seq 1 600); do
    if nodes=$(ROS_MASTER_URI="http://localhost:$port" rosnode list 2>/dev/null); then
      if grep -q '^/player$' <<<"$nodes"; then
        seen=1
      elif [ "$seen" = 1 ] || [ "$i" -gt 60 ]; then
        break
      fi
    fi
    sleep 1
  done
  kill -INT "$launch_pid"
  wait "$launch_pid" || true
  if [ -f "$out/live/map.json" ]; then
    "$bin/evaluate_map" --map "$out/live/map.json" --ground-truth "$drive/ground_truth.json" \
      --json "$out/live/metrics.json" >"$out/live/metrics.txt"
    echo "=== ipm_road_mapper live, nodelet (config/mapper.yaml) ==="
    cat "$out/live/metrics.txt"
    echo
    echo "=== live vs offline (scripts/compare_maps.py) ==="
    /usr/bin/python3 "$repo/scripts/compare_maps.py" "$out/live/map.json" "$out/mapper/map.json" \
      --max-center-mean-m 0.8 --min-matched 0.5 --max-lane-mean-m 0.5 --lane-cover-m 1.0 \
      --min-lane-cover 0.7 --max-extrinsic-deg 1.0 --max-extrinsic-m 0.1 --max-pose-mean-m 0.5 || true
  else
    echo "[demo] the live run wrote no map; see $out/live.log" >&2
  fi
fi

/usr/bin/python3 "$repo/scripts/plot_map.py" --map "$out/mapper/map.json" \
  --ground-truth "$drive/ground_truth.json" --metrics "$out/mapper/metrics.json" \
  --out "$out/mapper/map.png"
echo
echo "[demo] files:"
for f in mapper/map.json mapper/map.geojson mapper/map_trajectory_tum.txt mapper/metrics.json \
         mapper/map.png mapper/summary.txt drive/drive.bag drive/ground_truth.json; do
  if [ -e "$out/$f" ]; then echo "  $out/$f"; fi
done
if [ "${IRM_DEMO_LIVE:-0}" = 1 ] && [ -f "$out/live/map.json" ]; then
  for f in live/map.json live/map.geojson live/map_trajectory_tum.txt live/metrics.json; do
    if [ -e "$out/$f" ]; then echo "  $out/$f"; fi
  done
fi
