#!/usr/bin/env bash
# `make test-all`: every test tier on each supported Blender (4.2, 4.5, 5.0, 5.1, 5.2), each in its own venv
# (.venv-4.2, ...; tools/setup.sh VERSION). The extension zips are built once and the packaging test installs
# that same linux zip in every Blender. The kernels' output digests (tools/kernel_digest.py) must agree across
# every environment (NumPy 1.26 on Python 3.11, NumPy 2 on 3.13). A Blender whose Python is missing fails. The
# window tier (Debian's packaged Blender in a real window) runs once, in `make test`, not per bpy version; here the
# command line's process tests run the stand-in of each bpy version (TESSERA_CLI_BLENDER=standin), where `make test`
# runs them with the packaged Blender.
#
#   tools/matrix.sh            every version
#   tools/matrix.sh 4.2 5.2    some of them
set -uo pipefail
cd "$(dirname "$0")/.."
versions=("$@")
[ ${#versions[@]} -gt 0 ] || versions=(4.2 4.5 5.0 5.1 5.2)
out=out/matrix
mkdir -p "$out"

bash tools/setup.sh || exit 1
rm -rf "$out/dist"
echo "matrix: building the extension zips once (.venv)"
.venv/bin/python tools/build_extension.py --out "$out/dist" --wheels "$out/wheels" >"$out/build.log" 2>&1 || {
  tail -n 30 "$out/build.log"; echo "matrix: the build failed" >&2; exit 1; }

declare -A status seconds digests
failed=0
for v in "${versions[@]}"; do
  start=$(date +%s)
  if ! bash tools/setup.sh "$v"; then
    status[$v]="no environment"; seconds[$v]=0; failed=1; continue
  fi
  echo "matrix: Blender $v"
  TESSERA_CLI_BLENDER=standin TESSERA_ZIP_DIR="$PWD/$out/dist" ".venv-$v/bin/python" -m pytest -q -p no:cacheprovider -m "not window and not farm" >"$out/test-$v.log" 2>&1
  rc=$?
  seconds[$v]=$(( $(date +%s) - start ))
  summary=$(tail -n 1 "$out/test-$v.log")
  if [ $rc -eq 0 ]; then status[$v]="passed: $summary"; else status[$v]="FAILED: $summary"; failed=1
    grep -E "^(FAILED|ERROR)" "$out/test-$v.log" | head -n 20; fi
  digests[$v]=$(".venv-$v/bin/python" tools/kernel_digest.py 2>>"$out/test-$v.log" | sed 's/"numpy": "[^"]*", //')
done

echo
echo "| Blender | result | seconds |"
echo "|---|---|---|"
for v in "${versions[@]}"; do echo "| $v | ${status[$v]} | ${seconds[$v]} |"; done
first=""
for v in "${versions[@]}"; do
  [ -n "${digests[$v]:-}" ] || continue
  if [ -z "$first" ]; then first=$v
  elif [ "${digests[$v]}" != "${digests[$first]}" ]; then
    echo "matrix: kernel outputs differ between Blender $first and $v:"; echo "  ${digests[$first]}"; echo "  ${digests[$v]}"
    failed=1
  fi
done
[ -n "$first" ] && echo "kernel digests agree across: ${!digests[*]}"
exit $failed
