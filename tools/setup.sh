#!/usr/bin/env bash
# Set up the virtual environment of one supported Blender and, on Debian as root, the system pieces:
# Blender's X/GL libraries, Mesa EGL + llvmpipe (headless GPU context), the PoCL OpenCL ICD, OpenSubdiv
# (libosd-dev) with g++ for the subdivision oracle the tests build (out/osd/libosd_loop.so), and Slurm with munge
# for the farm tests (a one-node cluster they start and stop).
#
#   tools/setup.sh          .venv for the newest Blender this machine's Pythons can run (5.2 with Python 3.13,
#                           else 5.0 with Python 3.11): `make demo` and `make test` use it
#   tools/setup.sh 4.5      .venv-4.5 (bpy 4.5.x, Python 3.11), from requirements/blender-4.5.txt
#
# Supported: 4.2, 4.5 and 5.0 (Python 3.11); 5.1 and 5.2 (Python 3.13). Safe to re-run: does nothing when
# everything is in place.
set -euo pipefail
cd "$(dirname "$0")/.."

python_of() {  # the Python a Blender version's bpy wheel is built for
  case "$1" in
    4.2|4.5|5.0) echo 3.11 ;;
    5.1|5.2) echo 3.13 ;;
    *) echo "setup: unsupported Blender version '$1' (supported: 4.2 4.5 5.0 5.1 5.2)" >&2; return 1 ;;
  esac
}

find_python() {  # a Python $1 that really runs and can make a venv: PATH first, then pyenv's versions folder
  local want=$1 candidates=() c root
  candidates+=("$(command -v "python$want" 2>/dev/null || true)")  # may be a pyenv shim that refuses to run
  root=$(pyenv root 2>/dev/null || echo "${PYENV_ROOT:-$HOME/.pyenv}")
  for c in "$root"/versions/"$want"*/bin/"python$want" /usr/bin/"python$want" /usr/local/bin/"python$want"; do
    candidates+=("$c")
  done
  for c in "${candidates[@]}"; do
    [ -n "$c" ] && [ -x "$c" ] || continue
    if "$c" -c "import sys, venv, ensurepip; sys.exit(sys.version_info[:2] != tuple(map(int, '$want'.split('.'))))" \
        >/dev/null 2>&1; then
      echo "$c"
      return 0
    fi
  done
  return 1
}

system_packages=(
  libx11-6 libxext6 libxrender1 libxfixes3 libxi6 libxkbcommon0 libxxf86vm1 libsm6 libice6
  libgl1 libegl1 libegl-mesa0 libgl1-mesa-dri
  ocl-icd-libopencl1 pocl-opencl-icd
  libosd-dev g++
  slurmctld slurmd slurm-client munge
)

if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
  missing=()
  for p in "${system_packages[@]}"; do
    dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
  done
  find_python 3.11 >/dev/null || missing+=(python3.11 python3.11-venv)
  if [ ${#missing[@]} -gt 0 ]; then
    echo "setup: installing system packages: ${missing[*]}"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
    # the farm tests start a Slurm node and its munged of their own, and stop them; the packages' services stay off
    if command -v systemctl >/dev/null 2>&1; then
      systemctl disable --now munge slurmctld slurmd >/dev/null 2>&1 || true
    fi
  fi
else
  echo "setup: not root on Debian; make sure these are installed: ${system_packages[*]} (tiers missing them are skipped)"
fi

# The OpenSubdiv Loop oracle of the tests and benches (tools/osd_oracle), rebuilt when its source changes.
osd_src=tools/osd_oracle/osd_loop.cpp osd_lib=out/osd/libosd_loop.so
if [ -f /usr/include/opensubdiv/far/topologyRefiner.h ] && command -v g++ >/dev/null 2>&1 \
    && { [ ! -f "$osd_lib" ] || [ "$osd_src" -nt "$osd_lib" ]; }; then
  mkdir -p out/osd
  g++ -O2 -std=c++14 -shared -fPIC "$osd_src" -o "$osd_lib.tmp" -losdCPU && mv "$osd_lib.tmp" "$osd_lib"
  echo "setup: built $osd_lib"
fi

# Mesa's lavapipe (Vulkan on the CPU) for the gpu tier's Vulkan run, unpacked into out/vulkan so the system's Mesa
# stays as it is; tools/gpu_backend.py points Blender's own Vulkan loader at it.
vk_dir=out/vulkan
if [ ! -f "$vk_dir/lvp_icd.json" ] && command -v apt-get >/dev/null 2>&1 && command -v dpkg >/dev/null 2>&1; then
  mkdir -p "$vk_dir/debs"
  if (cd "$vk_dir/debs" && apt-get download -qq mesa-vulkan-drivers >/dev/null 2>&1); then
    dpkg -x "$vk_dir"/debs/mesa-vulkan-drivers_*.deb "$vk_dir/root"
    lvp=$(find "$(pwd)/$vk_dir/root" -name libvulkan_lvp.so | head -1)
    printf '{"file_format_version": "1.0.0", "ICD": {"api_version": "1.1.0", "library_path": "%s"}}\n' "$lvp" \
      > "$vk_dir/lvp_icd.json"
    echo "setup: Mesa lavapipe (Vulkan on the CPU) unpacked in $vk_dir"
  else
    echo "setup: could not download mesa-vulkan-drivers: the gpu tier's Vulkan run is unavailable"
  fi
fi

version=${1:-}
if [ -z "$version" ]; then  # the newest Blender whose Python is here
  if find_python 3.13 >/dev/null; then version=5.2; else version=5.0; fi
fi
want_py=$(python_of "$version")
PY=$(find_python "$want_py") || {
  echo "setup: Blender $version needs Python $want_py and none that runs was found (tried python$want_py on PATH," \
       "pyenv's versions folder, /usr/bin, /usr/local/bin). Install it, e.g. 'pyenv install $want_py'." >&2
  exit 1
}

venv=.venv-$version
requirements=requirements/blender-$version.txt
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c "import sys; sys.exit(sys.version_info[:2] != tuple(map(int, '$want_py'.split('.'))))"; then
  rm -rf "$venv"
  "$PY" -m venv "$venv"
fi
stamp=$venv/.requirements.sha256
want=$(sha256sum "$requirements" | cut -d' ' -f1)
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
  echo "setup: installing $requirements into $venv (bpy is large; first run takes a few minutes)"
  "$venv/bin/python" -m pip install -q --upgrade pip
  "$venv/bin/python" -m pip install -q -r "$requirements"
  echo "$want" > "$stamp"
fi

if [ -z "${1:-}" ]; then  # .venv is the default Blender's environment
  if [ "$(readlink .venv 2>/dev/null)" != "$venv" ]; then
    rm -rf .venv
    ln -s "$venv" .venv
    echo "setup: .venv is $venv (Blender $version, Python $want_py)"
  fi
fi
