#!/usr/bin/env bash
# Run a command on the packaged Blender's system: the chroot of tools/window_setup.sh (Debian sid: Blender 5.2.x built
# on the system Python 3.14, Xvfb, Mesa, PoCL), with this working tree read-only at /tessera-src, OUT_DIR at
# /tessera-out, a fresh tmpfs at /tmp (Blender's user folder and caches live there unless --env moves them) and each
# --bind DIR at its own path, with what is mounted below it (so file names given to the command mean the same inside
# and out).
#
#   tools/packaged_run.sh [--bind DIR]... [--env NAME=VALUE]... [--cd DIR] OUT_DIR SECONDS -- COMMAND [ARG...]
#
# --cd runs the command in DIR (default /). SECONDS 0: no time limit, and the command replaces this script's process
# (exec all the way down: a signal sent to this process reaches the command itself, as it would reach `blender`).
# Every mount is made in a private mount namespace (unshare -m), so a run that dies leaves nothing mounted. The
# command's output passes through; exits with its status (124 when it ran past SECONDS). Needs root.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
binds=() envs=() cwd=/
while :; do
  case "${1:-}" in
    --bind) binds+=("$(cd "$2" && pwd)"); shift 2 ;;
    --env) envs+=("$2"); shift 2 ;;
    --cd) cwd=$2; shift 2 ;;
    *) break ;;
  esac
done
[ $# -ge 4 ] && [ "$3" = -- ] || {
  echo "usage: $0 [--bind DIR]... [--env NAME=VALUE]... [--cd DIR] OUT_DIR SECONDS -- COMMAND [ARG...]" >&2; exit 2; }
out=$1 seconds=$2
shift 3
mkdir -p "$out"
out=$(cd "$out" && pwd)
root=$(bash "$here/tools/window_setup.sh" | tail -n 1)
[ -x "$root/usr/bin/blender" ] || { echo "packaged_run: no Blender in $root" >&2; exit 1; }
for d in proc dev sys tessera-src tessera-out; do mkdir -p "$root/$d"; done

exec unshare -m --propagation private bash -euo pipefail -c '
  root=$1 here=$2 out=$3 seconds=$4 cwd=$5 nbinds=$6 nenvs=$7
  shift 7
  mount --rbind /proc "$root/proc"; mount --rbind /dev "$root/dev"; mount --rbind /sys "$root/sys"
  mount --bind "$here" "$root/tessera-src"; mount -o remount,bind,ro "$root/tessera-src"
  mount --bind "$out" "$root/tessera-out"
  mount -t tmpfs tmpfs "$root/tmp"
  for ((i = 0; i < nbinds; i++)); do
    mkdir -p "$root$1"; mount --rbind "$1" "$root$1"; shift
  done
  envs=()
  for ((i = 0; i < nenvs; i++)); do envs+=("$1"); shift; done
  limit=()
  [ "$seconds" = 0 ] || limit=(timeout -k 10 "$seconds")
  exec chroot "$root" env -i -C "$cwd" HOME=/tmp PATH=/usr/bin:/bin LANG=C.UTF-8 \
    BLENDER_USER_RESOURCES=/tmp/blender-user XDG_CACHE_HOME=/tmp/cache XDG_RUNTIME_DIR=/tmp "${envs[@]}" \
    "${limit[@]}" "$@"
' _ "$root" "$here" "$out" "$seconds" "$cwd" "${#binds[@]}" "${#envs[@]}" "${binds[@]}" "${envs[@]}" "$@"
