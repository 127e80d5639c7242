#!/usr/bin/env bash
# The manual's pictures of the real Blender window, made anew: runs each scenario below in the window tier's
# packaged Blender (tools/window_run.sh, OpenGL on Mesa's llvmpipe) and copies every shot_NAME.png it takes to
# docs/shots/NAME.png, scaled to at most 1000 pixels wide. Never edit those pictures by hand: run this.
#
#   tools/manual_shots.sh          (needs what the window tier needs: root and Debian's packages)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
scenarios=(quick_start worked_examples)
work=$(mktemp -d "${TMPDIR:-/tmp}/tessera-shots.XXXXXX")
trap 'rm -rf "$work"' EXIT
mkdir -p "$here/docs/shots"
for scenario in "${scenarios[@]}"; do
  bash "$here/tools/window_run.sh" "$work/$scenario" "$scenario" opengl 300 || true
  grep -q '"finished": true' "$work/$scenario/results.json" 2>/dev/null || {
    echo "manual_shots: the scenario $scenario did not finish; see its log:" >&2
    tail -n 30 "$work/$scenario/blender.log" >&2; exit 1; }
  for shot in "$work/$scenario"/shot_*.png; do
    name=$(basename "$shot" .png); name=${name#shot_}
    convert "$shot" -resize '1000x>' -strip "$here/docs/shots/$name.png"
    echo "docs/shots/$name.png"
  done
done
