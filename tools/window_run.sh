#!/usr/bin/env bash
# Run one window-tier scenario in a real Blender window: Debian's packaged Blender (tools/window_setup.sh) under
# Xvfb with Mesa, the add-on from this working tree, events injected with Blender's --enable-event-simulate.
#
#   tools/window_run.sh OUT_DIR SCENARIO [opengl|vulkan] [SECONDS]
#
# SCENARIO is a module of tests/window/scenarios; what it writes (results.json, screenshots, blender.log) lands in
# OUT_DIR. Every mount is made in a private mount namespace (unshare -m), so a run that dies leaves nothing
# mounted. Exits with Blender's status (124 when it ran past SECONDS, default 300).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=$1 scenario=$2 backend=${3:-opengl} seconds=${4:-300}
mkdir -p "$out"
out=$(cd "$out" && pwd)
root=$(bash "$here/tools/window_setup.sh" | tail -n 1)
[ -x "$root/usr/bin/blender" ] || { echo "window_run: no Blender in $root" >&2; exit 1; }
for d in proc dev sys tessera-src tessera-out; do mkdir -p "$root/$d"; done

exec unshare -m --propagation private bash -euo pipefail -c '
  root=$1 here=$2 out=$3 scenario=$4 backend=$5 seconds=$6
  mount --rbind /proc "$root/proc"; mount --rbind /dev "$root/dev"; mount --rbind /sys "$root/sys"
  mount --bind "$here" "$root/tessera-src"; mount -o remount,bind,ro "$root/tessera-src"
  mount --bind "$out" "$root/tessera-out"
  mount -t tmpfs tmpfs "$root/tmp"
  args=()
  [ "$backend" = vulkan ] && args+=(--gpu-backend vulkan)
  set +e
  chroot "$root" env -i HOME=/tmp PATH=/usr/bin:/bin LANG=C.UTF-8 \
    BLENDER_USER_RESOURCES=/tmp/blender-user XDG_CACHE_HOME=/tmp/cache XDG_RUNTIME_DIR=/tmp \
    timeout -k 10 "$seconds" xvfb-run -a -s "-screen 0 1600x900x24 -nolisten tcp" \
    blender --factory-startup --enable-event-simulate --window-geometry 0 0 1600 900 --no-window-focus \
      "${args[@]}" --python /tessera-src/tests/window/driver.py -- "$scenario" /tessera-out "$backend" \
    >"$out/blender.log" 2>&1
  rc=$?
  exit $rc
' _ "$root" "$here" "$out" "$scenario" "$backend" "$seconds"
