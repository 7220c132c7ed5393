#!/usr/bin/env bash
# Checks a sequence dataset's TUM trajectories with evo and its COLMAP models with
# pycolmap (fixtures/ground_truth/check_sequence_files.py). Needs the release build and
# a Python (BLENDSYNTH_BPY_PYTHON or .venv); installs evo and pycolmap into it with numpy
# held below 2 (bpy 4.5 needs numpy 1.x). About a minute.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
py=${BLENDSYNTH_BPY_PYTHON:-$here/.venv/bin/python}
"$py" -m pip install -q evo pycolmap "numpy<2"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cat > "$out/spec.toml" <<'TOML'
[render]
resolution = [16, 12]
samples = 1
denoise = false
[frames]
start = 1
step = 0
[sequence]
length = 3
step = 1
[[param]]
path = 'cameras["Cam"].lens'
dist = "uniform"
min = 25.0
max = 45.0
TOML
"$here/target/release/blendsynth" generate "$here/fixtures/ground_truth/scene" --spec "$out/spec.toml" --frames 6 -o "$out/ds"
(cd "$out" && "$py" "$here/fixtures/ground_truth/check_sequence_files.py" "$out/ds")
