#!/usr/bin/env bash
# Set up .venv (Python 3.11, pinned requirements) and, on Debian as root, the system pieces:
# Blender's X/GL libraries, Mesa EGL + llvmpipe (headless GPU context) and the PoCL OpenCL ICD.
# Safe to re-run: does nothing when everything is in place.
set -euo pipefail
cd "$(dirname "$0")/.."

system_packages=(
  libx11-6 libxext6 libxrender1 libxfixes3 libxi6 libxkbcommon0 libxxf86vm1 libsm6 libice6
  libgl1 libegl1 libegl-mesa0 libgl1-mesa-dri
  ocl-icd-libopencl1 pocl-opencl-icd
)

if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
  missing=()
  for p in "${system_packages[@]}"; do
    dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
  done
  command -v python3.11 >/dev/null 2>&1 || missing+=(python3.11)
  python3.11 -c 'import ensurepip, venv' >/dev/null 2>&1 || missing+=(python3.11-venv)
  if [ ${#missing[@]} -gt 0 ]; then
    echo "setup: installing system packages: ${missing[*]}"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  fi
else
  echo "setup: not root on Debian; make sure these are installed: ${system_packages[*]} (tiers missing them are skipped)"
fi

PY=$(command -v python3.11 || true)
if [ -z "$PY" ]; then
  echo "setup: Python 3.11 is required (Blender 4.2-5.0 and bpy==5.0.1 use it); install python3.11" >&2
  exit 1
fi

if [ ! -x .venv/bin/python ] || ! .venv/bin/python -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))'; then
  rm -rf .venv
  "$PY" -m venv .venv
fi

stamp=.venv/.requirements.sha256
want=$(sha256sum requirements.txt | cut -d' ' -f1)
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
  echo "setup: installing Python packages into .venv (bpy is large; first run takes a few minutes)"
  .venv/bin/python -m pip install -q --upgrade pip
  .venv/bin/python -m pip install -q -r requirements.txt
  echo "$want" > "$stamp"
fi
