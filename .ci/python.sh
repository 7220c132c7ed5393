#!/usr/bin/env bash
# The Python package: builds the wheel with maturin (abi3, the crate recompiled once with
# --features python), bundles the CLI binary in it, installs it into a fresh virtual
# environment and runs the pytest suite (python/tests) against the installed wheel.
# Prints the step's time. Run after `cargo test --release` (it reuses target/release's
# CLI build). Needs python3.11 (or $PYTHON311) and PyPI.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
PY=${PYTHON311:-python3.11}
work=target/python-ci

# Build tools, kept between runs.
if [ ! -x "$work/tools/bin/maturin" ]; then
  "$PY" -m venv "$work/tools"
  "$work/tools/bin/pip" install --quiet --disable-pip-version-check "maturin>=1.5,<2"
fi

# The `blendsynth` command inside the wheel (python/blendsynth/_cli.py execs it).
cargo build --release --bin blendsynth
mkdir -p python/blendsynth/bin
cp target/release/blendsynth python/blendsynth/bin/blendsynth
# The release profile keeps line tables (symbols and lines for profiles); the wheel drops them.
if command -v strip >/dev/null; then strip python/blendsynth/bin/blendsynth; fi

rm -rf "$work/wheels"
"$work/tools/bin/maturin" build --release --quiet -i "$work/tools/bin/python" -o "$work/wheels"
wheel=$(ls "$work"/wheels/blendsynth-*.whl)
echo "wheel: $wheel ($(du -h "$wheel" | cut -f1))"

# A fresh environment with only the wheel and the test tools.
rm -rf "$work/venv"
"$PY" -m venv "$work/venv"
"$work/venv/bin/pip" install --quiet --disable-pip-version-check "$wheel" pytest pypng openexr pycocotools
export PATH="$PWD/$work/venv/bin:$PATH"
blendsynth --version
# From python/tests, so `import blendsynth` finds the installed wheel, not python/.
(cd python/tests && python -m pytest -q -p no:cacheprovider)
echo "python step: $(( $(date +%s) - start )) s"
