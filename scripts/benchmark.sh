#!/usr/bin/env bash
# Runs the ablations on the synthetic scenarios (and on ../shared/data/av2_pit_dev when it
# is present) and prints the paper-style tables plus the issues' "Done when" rows
# (scripts/benchmark.py). Drives are cached in out/benchmark/drives. Options are passed on:
#   bash scripts/benchmark.sh [--scenarios public_road,port,hilly,urban,curvy,av2_pit_dev]
#                             [--quick] [--jobs 2] [--shared <dir>]
#   bash scripts/benchmark.sh --long     # the 10 km long-drive benchmark alone (docs/benchmark.md)
#   bash scripts/benchmark.sh --long --instructions   # and instructions per frame (callgrind)
set -eo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${IRM_BUILD_DIR:-$repo/.build}"
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
export ROS_HOME="$build/ros_home"
bash "$repo/scripts/setup.sh"
# shellcheck disable=SC1091
source "$build/devel/setup.bash"
exec /usr/bin/python3 "$repo/scripts/benchmark.py" --repo "$repo" --bin "$build/devel/lib/ipm_road_mapper" "$@"
