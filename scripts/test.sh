#!/usr/bin/env bash
# Runs every test of the package (gtests, rostests, tool tests, the no-ROS-in-core check)
# through ctest, after scripts/setup.sh. Ends with "N passed, N failed" (test cases, taken
# from the gtest/rostest XML where there is one) and exits non-zero on any failure. With CI
# set, the build treats compiler warnings as errors (IRM_WARNINGS_AS_ERRORS).
set -eo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${IRM_BUILD_DIR:-$repo/.build}"
jobs="${IRM_JOBS:-$(nproc)}"
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
export ROS_HOME="$build/ros_home"   # keep logs out of ~/.ros

# CI (CI=true) builds with warnings as errors; a local run turns it back off in a build
# folder a CI run configured.
if [ -n "${CI:-}" ]; then
  export IRM_CMAKE_ARGS="-DIRM_WARNINGS_AS_ERRORS=ON ${IRM_CMAKE_ARGS:-}"
elif grep -qs '^IRM_WARNINGS_AS_ERRORS:BOOL=ON' "$build/CMakeCache.txt"; then
  export IRM_CMAKE_ARGS="-DIRM_WARNINGS_AS_ERRORS=OFF ${IRM_CMAKE_ARGS:-}"
fi
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
