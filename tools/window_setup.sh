#!/usr/bin/env bash
# The window tier's Blender: Debian sid's packaged Blender (5.2.x, built on the system Python 3.14) with Xvfb, Mesa
# (llvmpipe for OpenGL, lavapipe for Vulkan), PoCL and ImageMagick, in a chroot made by debootstrap from Debian's
# packages. The chroot is cached between runs on one machine (it is not in the work tree): this script does nothing
# when it is complete, and makes it anew when it is not (a half-made chroot is never used).
#
#   tools/window_setup.sh          make or check the chroot; prints its path last
#
# Needs root and debootstrap (installed here when missing). The chroot lives in $TESSERA_WINDOW_ROOT (default
# /var/cache/tessera/window-sid). Mounts are made only by tools/window_run.sh, in a private mount namespace.
set -euo pipefail

root=${TESSERA_WINDOW_ROOT:-/var/cache/tessera/window-sid}
mirror=${TESSERA_DEBIAN_MIRROR:-http://deb.debian.org/debian}
packages=(
  blender xvfb xauth x11-apps imagemagick mesa-utils libgl1-mesa-dri mesa-vulkan-drivers
  python3-numpy python3-openimageio python3-pyopencl pocl-opencl-icd python3-cattr python3-requests fonts-dejavu-core
)
stamp_text="packages: ${packages[*]}"

fail() { echo "window_setup: $*" >&2; exit 1; }

if [ -f "$root/.tessera-complete" ] && [ "$(cat "$root/.tessera-complete")" = "$stamp_text" ]; then
  echo "$root"
  exit 0
fi
[ "$(id -u)" = 0 ] || fail "making the chroot needs root (debootstrap, chroot); run as root or set TESSERA_WINDOW_ROOT to a finished chroot"
if ! command -v debootstrap >/dev/null 2>&1; then
  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends debootstrap >/dev/null \
    || fail "could not install debootstrap"
fi

echo "window_setup: making Debian sid with Blender in $root (a few minutes, once per machine)" >&2
rm -rf "$root.new"
mkdir -p "$(dirname "$root")"
debootstrap --variant=minbase sid "$root.new" "$mirror" >"$root.new.log" 2>&1 || {
  tail -n 20 "$root.new.log" >&2; fail "debootstrap of Debian sid failed (log: $root.new.log)"; }
# apt inside the chroot needs /proc and /dev; mount them in a private namespace so nothing stays mounted.
unshare -m --propagation private bash -euo pipefail -c '
  r=$1; shift
  mount --bind /proc "$r/proc"; mount --bind /dev "$r/dev"; mount --bind /sys "$r/sys"
  cp /etc/resolv.conf "$r/etc/resolv.conf" 2>/dev/null || true
  chroot "$r" apt-get -o Acquire::Check-Valid-Until=false update -qq
  DEBIAN_FRONTEND=noninteractive chroot "$r" apt-get -o Acquire::Check-Valid-Until=false install -y -qq \
    --no-install-recommends "$@"
  chroot "$r" apt-get clean
' _ "$root.new" "${packages[@]}" >>"$root.new.log" 2>&1 || {
  tail -n 20 "$root.new.log" >&2; fail "installing Blender in the chroot failed (log: $root.new.log)"; }
"$root.new/usr/bin/blender" --version >/dev/null 2>&1 || true  # only a smoke check; it runs inside the chroot
echo "$stamp_text" > "$root.new/.tessera-complete"
rm -rf "$root" "$root.new.log"
mv "$root.new" "$root"
echo "$root"
