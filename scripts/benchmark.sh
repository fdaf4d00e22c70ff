#!/usr/bin/env bash
# The project's benchmark (scripts/irm_bench; docs/benchmark.md says what each table means):
# the ablations on the synthetic scenarios, the real-geometry drive and the real-geometry fleet
# passes (../shared/data/av2_pit_dev and av2_pit_fleet, when present), printed as tables.
# Drives are cached in out/benchmark/drives. Options are passed on:
#   bash scripts/benchmark.sh [--scenarios public_road,port,hilly,urban,curvy,av2_pit_dev,av2_pit_fleet]
#                             [--quick] [--jobs 2] [--shared <dir>] [--write-docs]
#   bash scripts/benchmark.sh --fleet-passes   # the fleet passes alone, each mapped alone
#   bash scripts/benchmark.sh --long           # the 10 km long-drive benchmark alone
#   bash scripts/benchmark.sh --long --instructions   # and instructions per frame (callgrind)
set -eo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${IRM_BUILD_DIR:-$repo/.build}"
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
export ROS_HOME="$build/ros_home"
bash "$repo/scripts/setup.sh"
# shellcheck disable=SC1091
source "$build/devel/setup.bash"
export PYTHONPATH="$repo/scripts${PYTHONPATH:+:$PYTHONPATH}"
exec /usr/bin/python3 -m irm_bench --repo "$repo" --bin "$build/devel/lib/ipm_road_mapper" \
  --build "$build" "$@"
