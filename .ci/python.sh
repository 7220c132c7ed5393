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
# .ci/run sets BLENDSYNTH_CLI_BUILT=1 after `cargo test --release`, which built this binary
# for the CLI tests: a `cargo build` here would compile the crate again (about 2 minutes),
# only because proptest, a dev-dependency, turns on features of a shared dependency
# (getrandom) and so changes the build's hash, not its code.
if [ "${BLENDSYNTH_CLI_BUILT:-}" != 1 ] || [ ! -x target/release/blendsynth ]; then
  cargo build --release --bin blendsynth
fi
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

# The dataset class with PyTorch tensors and a DataLoader. PyPI's torch brings CUDA
# (gigabytes); Debian's CPU build (python3-torch, about 150 MB of packages) is for the
# system Python 3.11, so this environment is made from that Python and sees its packages.
if [ "${CI:-}" = true ] && ! /usr/bin/python3 -c "import torch" 2>/dev/null; then
  apt-get install -y -q --no-install-recommends python3-torch python3-venv >/dev/null
fi
if /usr/bin/python3 -c "import torch" 2>/dev/null; then
  rm -rf "$work/venv-torch"
  /usr/bin/python3 -m venv --system-site-packages "$work/venv-torch"
  "$work/venv-torch/bin/pip" install --quiet --disable-pip-version-check "$wheel" pytest pypng
  # It must run, not skip (conftest skips what lacks its modules).
  torch_rc=0
  torch_out=$(cd python/tests && BLENDSYNTH_REQUIRE_TORCH=1 PATH="$PWD/../../$work/venv-torch/bin:$PATH" \
    python -m pytest -q -rs -p no:cacheprovider test_data.py -k torch 2>&1) || torch_rc=$?
  echo "$torch_out"
  rm -rf "$work/venv-torch"
  if [ "$torch_rc" != 0 ] || ! grep -q "^1 passed" <<<"$torch_out"; then
    echo "python step: the PyTorch test did not pass" >&2
    exit 1
  fi
elif [ "${CI:-}" = true ]; then
  echo "python step: no PyTorch for the dataset class test" >&2
  exit 1
fi
echo "python step: $(( $(date +%s) - start )) s"
