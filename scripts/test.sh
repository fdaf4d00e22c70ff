#!/usr/bin/env bash
# Runs every test of the package (gtests, rostests, tool tests, the no-ROS-in-core check)
# through ctest, after scripts/setup.sh. Ends with "N passed, N failed" (test cases, taken
# from the gtest/rostest XML where there is one) and exits non-zero on any failure.
set -eo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${IRM_BUILD_DIR:-$repo/.build}"
jobs="${IRM_JOBS:-$(nproc)}"
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
export ROS_HOME="$build/ros_home"   # keep logs out of ~/.ros

bash "$repo/scripts/setup.sh"
echo "[test] building tests"
make -C "$build" -j"$jobs" --no-print-directory tests >"$build/build_tests.log" 2>&1 \
  || { grep -E 'error' -A3 "$build/build_tests.log" | head -60; echo "[test] test build failed: $build/build_tests.log" >&2; echo "0 passed, 1 failed"; exit 1; }

rm -rf "$build/test_results"
set +e
(cd "$build" && ctest --output-on-failure --output-junit ctest_results.xml ${IRM_CTEST_ARGS:-})
ctest_rc=$?
set -e
/usr/bin/python3 "$repo/scripts/summarize_tests.py" "$build" "$ctest_rc"
