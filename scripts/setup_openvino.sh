#!/usr/bin/env bash
# The segmentation runtime: OpenVINO from PyPI into a venv that the scripts own
# (<build>/venv; called by scripts/setup.sh before the build configures). The wheel carries
# the C++ headers, the CMake config and the shared libraries that segment_masks and
# segment_bag link (docs/segmentation.md). Idempotent: a second run checks one stamp file.
#   IRM_NO_OPENVINO=1: skip it (the segmentation tools are then not built; their tests skip).
# Without network or pip, it warns and returns 0: the mapper builds and runs without it.
set -eo pipefail

build="${1:?usage: setup_openvino.sh BUILD_DIR}"
version="2026.4.1"
venv="$build/venv"
stamp="$venv/.openvino-$version"
log() { printf '[setup] %s\n' "$*"; }

if [ "${IRM_NO_OPENVINO:-0}" = 1 ]; then
  log "OpenVINO: skipped (IRM_NO_OPENVINO=1); segment_masks and segment_bag are not built"
  exit 0
fi
if [ -f "$stamp" ]; then
  log "OpenVINO $version: present ($venv)"
  exit 0
fi
log "OpenVINO $version: installing into $venv (pip, once)"
# --system-site-packages: Debian's numpy and ROS Python modules stay visible in the venv.
if ! /usr/bin/python3 -m venv --system-site-packages "$venv" >"$build/openvino_setup.log" 2>&1 ||
   ! "$venv/bin/pip" install --disable-pip-version-check -q "openvino==$version" \
      >>"$build/openvino_setup.log" 2>&1; then
  log "warning: OpenVINO could not be installed (no network to PyPI?); the segmentation"
  log "         tools are not built and their tests skip. Details: $build/openvino_setup.log"
  exit 0
fi
touch "$stamp"
log "OpenVINO $version: installed"
