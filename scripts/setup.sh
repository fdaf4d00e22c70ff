#!/usr/bin/env bash
# One-time (and idempotent) set-up on Debian 12: installs the missing Debian packages and
# builds the catkin package into .build/ at the repository root. A second run only
# rebuilds what changed. Afterwards `source .build/devel/setup.bash` makes
# `rosrun ipm_road_mapper ...` and `roslaunch ipm_road_mapper ...` work.
#   --with-rviz (or IRM_WITH_RVIZ=1): also installs rviz, Xvfb and ImageMagick
#   (scripts/debian-packages-rviz.txt): what `demo.launch rviz:=true` and
#   scripts/rviz_screenshot.sh use. The default set-up stays without them.
set -eo pipefail

with_rviz="${IRM_WITH_RVIZ:-0}"
for arg in "$@"; do
  case "$arg" in
    --with-rviz) with_rviz=1 ;;
    -h|--help) sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "[setup] unknown option: $arg (known: --with-rviz)" >&2; exit 2 ;;
  esac
done

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${IRM_BUILD_DIR:-$repo/.build}"
jobs="${IRM_JOBS:-$(nproc)}"
# Debian's ROS lives in /usr; a pyenv or venv python3 first in PATH lacks its modules.
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"

log() { printf '[setup] %s\n' "$*"; }

# --- 1. Debian packages --------------------------------------------------------------
package_lists=("$repo/scripts/debian-packages.txt")
[ "$with_rviz" = 1 ] && package_lists+=("$repo/scripts/debian-packages-rviz.txt")
mapfile -t wanted < <(cat "${package_lists[@]}" | grep -v '^\s*#' | sed '/^\s*$/d')
missing=()
for pkg in "${wanted[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$pkg" 2>/dev/null || true)
  [ "$status" = "installed" ] || missing+=("$pkg")
done
if [ ${#missing[@]} -gt 0 ]; then
  log "installing ${#missing[@]} Debian packages: ${missing[*]}"
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "[setup] error: not root and no sudo" >&2; exit 1; }
    sudo_cmd=(sudo)
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  log "Debian packages: all ${#wanted[@]} present"
fi

# --- 2. The segmentation runtime (OpenVINO from PyPI, into $build/venv) ---------------------
mkdir -p "$build"
bash "$repo/scripts/setup_openvino.sh" "$build"

# --- 3. Build ----------------------------------------------------------------------------
# catkin writes PYTHONPATH='' into its cached env unless this exists before configure.
mkdir -p "$build/devel/lib/python3/dist-packages"
# IRM_CMAKE_ARGS: extra CMake arguments, e.g. -DIRM_WARNINGS_AS_ERRORS=ON (scripts/test.sh
# passes it when CI is set). On an existing build folder they are applied by re-running cmake.
if [ -f "$build/CMakeCache.txt" ] && [ -n "${IRM_CMAKE_ARGS:-}" ]; then
  log "re-configuring $build with: $IRM_CMAKE_ARGS"
  cmake -S "$repo" -B "$build" ${IRM_CMAKE_ARGS} >"$build/configure.log" 2>&1 \
    || { cat "$build/configure.log"; exit 1; }
fi
if [ ! -f "$build/CMakeCache.txt" ]; then
  log "configuring into $build"
  # ccache, when installed, makes a rebuild in a fresh build folder fast.
  launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  cmake -S "$repo" -B "$build" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" ${IRM_CMAKE_ARGS:-} \
    -DCATKIN_DEVEL_PREFIX="$build/devel" \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 >"$build/configure.log" 2>&1 \
    || { cat "$build/configure.log"; exit 1; }
fi
log "building (make -j$jobs)"
make -C "$build" -j"$jobs" --no-print-directory >"$build/build.log" 2>&1 \
  || { grep -E 'error|Error' -A3 "$build/build.log" | head -60; echo "[setup] build failed, full log: $build/build.log" >&2; exit 1; }
log "ready: source $build/devel/setup.bash"
