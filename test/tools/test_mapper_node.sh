#!/usr/bin/env bash
# mapper_node --help prints its usage (where its parameters are documented) and exits 0
# without starting a node: with no roscore reachable it would otherwise wait for one. Runs in
# the devel space's environment (ctest) or by hand after `source <devel>/setup.bash`.
set -eo pipefail

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export ROS_HOME="$work/ros_home"
# No master here: a node that started would wait for it (and time out below).
export ROS_MASTER_URI="http://127.0.0.1:1"

tool_bin=$(catkin_find --first-only --libexec ipm_road_mapper mapper_node 2>/dev/null) ||
  fail "ipm_road_mapper/mapper_node not found (source the devel space's setup.bash)"

for flag in --help -h; do
  rc=0
  timeout 10 "$tool_bin" "$flag" >"$work/help.txt" 2>"$work/help.err" || rc=$?
  [ "$rc" -eq 0 ] || fail "mapper_node $flag: exit $rc: $(cat "$work/help.err")"
  [ ! -s "$work/help.err" ] || fail "mapper_node $flag wrote to stderr: $(cat "$work/help.err")"
  grep -q "usage: rosrun ipm_road_mapper mapper_node" "$work/help.txt" || fail "no usage line"
  grep -q "docs/ros_api.md" "$work/help.txt" || fail "the usage does not point at docs/ros_api.md"
  grep -q -- "--help" "$work/help.txt" || fail "the usage does not name --help"
done
echo "ok: mapper_node --help prints its usage and exits 0 without a node"
