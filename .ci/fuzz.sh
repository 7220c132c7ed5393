#!/usr/bin/env bash
# Fuzzing step (issue 27): builds the cargo-fuzz targets in fuzz/ and runs each for a
# bounded time (FUZZ_SECONDS, default 45) from the committed seed corpus; any panic,
# abort, timeout or out-of-memory fails the step and leaves the input in
# fuzz/artifacts/<target>/; FUZZ_TARGETS names a subset. cargo-fuzz needs nightly
# features: the stable toolchain allows them with RUSTC_BOOTSTRAP=1.
set -euo pipefail
cd "$(dirname "$0")/.."
export RUSTC_BOOTSTRAP=1
SECONDS_EACH=${FUZZ_SECONDS:-45}
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked
# -a: overflow checks on, so a wrapped size computation is a finding, not a silent wrap.
# No sanitizer: the crate is safe Rust, and ASan would double the build time.
# FUZZ_PROFILE=dev (what CI uses): an unoptimised build, overflow checks and debug
# assertions on, whose instrumented build takes about 3.5 CPU-minutes here against about
# 78 wall minutes (under load) for the optimised one; it runs fewer inputs per second.
if [ "${FUZZ_PROFILE:-release}" = dev ]; then
  FLAGS=(--dev --sanitizer none)
else
  FLAGS=(-O -a --sanitizer none)
fi
cargo fuzz build "${FLAGS[@]}"
for target in ${FUZZ_TARGETS:-scene_json glb spec set_value}; do
  work=$(mktemp -d)
  echo "fuzz: $target for ${SECONDS_EACH}s"
  # The committed seeds are read only; new inputs go to a scratch folder.
  status=0
  cargo fuzz run "${FLAGS[@]}" "$target" "$work" "fuzz/seeds/$target" -- \
    -max_total_time="$SECONDS_EACH" -timeout=10 -rss_limit_mb=4096 -max_len=262144 \
    -print_final_stats=1 >"$work.log" 2>&1 || status=$?
  grep -E "^(stat::(number_of_executed_units|new_units_added|peak_rss_mb)|Done|SUMMARY|==[0-9]+== ERROR)" "$work.log" || true
  [ "$status" -eq 0 ] || tail -n 40 "$work.log" >&2
  rm -rf "$work" "$work.log"
  if [ "$status" -ne 0 ]; then
    echo "fuzz: $target FAILED (exit $status); see fuzz/artifacts/$target/" >&2
    exit 1
  fi
done
echo "fuzz: all targets ran clean"
