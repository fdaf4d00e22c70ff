#!/usr/bin/env bash
# Takes docs/rviz_demo.png: the demo drive mapped live by the nodelet (launch/demo.launch
# rviz:=true), rviz/mapper.rviz under a virtual X server, captured near the end of the drive.
# Installs rviz, xvfb and imagemagick through `scripts/setup.sh --with-rviz` (no test needs them). Uses the drive of
# scripts/demo.sh (out/demo/drive/drive.bag), generating it when missing.
#   IRM_OUT=<dir>       demo output folder (default: out/demo)
#   IRM_SHOT=<png>      output image (default: docs/rviz_demo.png)
#   IRM_SHOT_AT=<0..1>  capture when this fraction of the drive has played (default 0.8)
set -eo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${IRM_BUILD_DIR:-$repo/.build}"
out="${IRM_OUT:-$repo/out/demo}"
shot="${IRM_SHOT:-$repo/docs/rviz_demo.png}"
at="${IRM_SHOT_AT:-0.8}"
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
export ROS_HOME="$build/ros_home"

bash "$repo/scripts/setup.sh" --with-rviz  # rviz, Xvfb and ImageMagick too
# shellcheck disable=SC1091
source "$build/devel/setup.bash"
bag="$out/drive/drive.bag"
if [ ! -f "$bag" ]; then
  echo "[shot] generating the demo drive into $out/drive"
  "$build/devel/lib/ipm_road_mapper/generate_drive" --scenario "$repo/config/scenarios/public_road.yaml" \
    --seed 1 --out "$out/drive" >/dev/null
fi
duration=$(/usr/bin/python3 -c "import rosbag,sys; b=rosbag.Bag(sys.argv[1]); print(b.get_end_time()-b.get_start_time())" "$bag")

display=":${IRM_DISPLAY:-99}"
Xvfb "$display" -screen 0 1600x1000x24 -nolisten tcp >/dev/null 2>&1 &
xvfb_pid=$!
port=$((11500 + RANDOM % 400))
export ROS_MASTER_URI="http://localhost:$port" DISPLAY="$display" LIBGL_ALWAYS_SOFTWARE=1
roslaunch -p "$port" ipm_road_mapper demo.launch rviz:=true bag:="$bag" \
  save_map_path:="$out/live/map.json" >"$out/rviz_screenshot.log" 2>&1 &
launch_pid=$!
cleanup() { kill -INT "$launch_pid" 2>/dev/null; wait "$launch_pid" 2>/dev/null; kill "$xvfb_pid" 2>/dev/null || true; }
trap cleanup EXIT
# rviz and the mapper start, the player waits 2 s, then the drive plays in real time.
wait_s=$(/usr/bin/python3 -c "print(round(8 + 2 + $duration * $at))")
echo "[shot] playing $duration s of drive, capturing after $wait_s s"
sleep "$wait_s"
mkdir -p "$(dirname "$shot")"
import -display "$display" -window root "$shot"
echo "[shot] wrote $shot"
