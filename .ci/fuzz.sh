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
# libFuzzer runs one thread per target: run the targets side by side, one per core, so
# each still gets its full time and the step takes about a fraction 1/cores of it.
jobs=$(nproc 2>/dev/null || echo 1)
targets=(${FUZZ_TARGETS:-scene_json glb spec set_value})
run_one() {
  local target=$1 work status=0
  work=$(mktemp -d)
  # The committed seeds are read only; new inputs go to a scratch folder.
  cargo fuzz run "${FLAGS[@]}" "$target" "$work" "fuzz/seeds/$target" -- \
    -max_total_time="$SECONDS_EACH" -timeout=10 -rss_limit_mb=4096 -max_len=262144 \
    -print_final_stats=1 >"$logs/$target.log" 2>&1 || status=$?
  rm -rf "$work"
  return $status
}
logs=$(mktemp -d)
declare -A pid
failed=0
report() {
  local target=$1 status=0
  wait "${pid[$target]}" || status=$?
  echo "fuzz: $target for ${SECONDS_EACH}s"
  grep -E "^(stat::(number_of_executed_units|new_units_added|peak_rss_mb)|Done|SUMMARY|==[0-9]+== ERROR)" "$logs/$target.log" || true
  if [ "$status" -ne 0 ]; then
    tail -n 40 "$logs/$target.log" >&2
    echo "fuzz: $target FAILED (exit $status); see fuzz/artifacts/$target/" >&2
    failed=1
  fi
}
running=()
for target in "${targets[@]}"; do
  if [ "${#running[@]}" -ge "$jobs" ]; then
    report "${running[0]}"
    running=("${running[@]:1}")
  fi
  run_one "$target" &
  pid[$target]=$!
  running+=("$target")
done
for target in "${running[@]}"; do report "$target"; done
rm -rf "$logs"
[ "$failed" = 0 ] || exit 1
echo "fuzz: all targets ran clean"
