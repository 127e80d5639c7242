#!/usr/bin/env bash
# Run one window-tier scenario in a real Blender window: Debian's packaged Blender (tools/window_setup.sh) under
# Xvfb with Mesa, the add-on from this working tree, events injected with Blender's --enable-event-simulate.
#
#   tools/window_run.sh OUT_DIR SCENARIO [opengl|vulkan] [SECONDS]
#
# SCENARIO is a module of tests/window/scenarios; what it writes (results.json, screenshots, blender.log) lands in
# OUT_DIR. The chroot and its mounts are tools/packaged_run.sh's. Exits with Blender's status (124 when it ran past
# SECONDS, default 300).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=$1 scenario=$2 backend=${3:-opengl} seconds=${4:-300}
mkdir -p "$out"
args=()
[ "$backend" = vulkan ] && args+=(--gpu-backend vulkan)
exec bash "$here/tools/packaged_run.sh" "$out" "$seconds" -- \
  xvfb-run -a -s "-screen 0 1600x900x24 -nolisten tcp" \
  blender --factory-startup --enable-event-simulate --window-geometry 0 0 1600 900 --no-window-focus \
    "${args[@]}" --python /tessera-src/tests/window/driver.py -- "$scenario" /tessera-out "$backend" \
  >"$out/blender.log" 2>&1
