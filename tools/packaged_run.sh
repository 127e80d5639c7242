#!/usr/bin/env bash
# Run a command on the packaged Blender's system: the chroot of tools/window_setup.sh (Debian sid: Blender 5.2.x built
# on the system Python 3.14, Xvfb, Mesa, PoCL), with this working tree read-only at /tessera-src, OUT_DIR at
# /tessera-out, a fresh tmpfs at /tmp (Blender's user folder and caches live there) and each --bind DIR at its own
# path (so file names given to the command mean the same inside and out).
#
#   tools/packaged_run.sh [--bind DIR]... OUT_DIR SECONDS -- COMMAND [ARG...]
#
# Every mount is made in a private mount namespace (unshare -m), so a run that dies leaves nothing mounted. The
# command's output passes through; exits with its status (124 when it ran past SECONDS). Needs root.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
binds=()
while [ "${1:-}" = --bind ]; do binds+=("$(cd "$2" && pwd)"); shift 2; done
[ $# -ge 4 ] && [ "$3" = -- ] || { echo "usage: $0 [--bind DIR]... OUT_DIR SECONDS -- COMMAND [ARG...]" >&2; exit 2; }
out=$1 seconds=$2
shift 3
mkdir -p "$out"
out=$(cd "$out" && pwd)
root=$(bash "$here/tools/window_setup.sh" | tail -n 1)
[ -x "$root/usr/bin/blender" ] || { echo "packaged_run: no Blender in $root" >&2; exit 1; }
for d in proc dev sys tessera-src tessera-out; do mkdir -p "$root/$d"; done

exec unshare -m --propagation private bash -euo pipefail -c '
  root=$1 here=$2 out=$3 seconds=$4 nbinds=$5
  shift 5
  mount --rbind /proc "$root/proc"; mount --rbind /dev "$root/dev"; mount --rbind /sys "$root/sys"
  mount --bind "$here" "$root/tessera-src"; mount -o remount,bind,ro "$root/tessera-src"
  mount --bind "$out" "$root/tessera-out"
  mount -t tmpfs tmpfs "$root/tmp"
  for ((i = 0; i < nbinds; i++)); do
    mkdir -p "$root$1"; mount --bind "$1" "$root$1"; shift
  done
  exec chroot "$root" env -i HOME=/tmp PATH=/usr/bin:/bin LANG=C.UTF-8 \
    BLENDER_USER_RESOURCES=/tmp/blender-user XDG_CACHE_HOME=/tmp/cache XDG_RUNTIME_DIR=/tmp \
    timeout -k 10 "$seconds" "$@"
' _ "$root" "$here" "$out" "$seconds" "${#binds[@]}" "${binds[@]}" "$@"
