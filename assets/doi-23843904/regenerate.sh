#!/usr/bin/env bash
# Re-authors the built-in replicate scenes with bpy and exports them with the project's
# exporter into assets/doi-23843904/{colonoscopy,laparoscopy}/ (committed).
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=${BLENDSYNTH_BPY_PYTHON:-.venv/bin/python}
tmp=$(mktemp -d)
"$PY" assets/doi-23843904/make_scenes.py "$tmp"
cargo build --release --quiet
for p in colonoscopy laparoscopy; do
  rm -rf "assets/doi-23843904/$p"
  target/release/blendsynth convert "$tmp/$p.blend" -o "assets/doi-23843904/$p" --no-evaluated --blender "$PY"
done
rm -rf "$tmp"
