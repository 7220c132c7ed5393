#!/usr/bin/env bash
# Renders a dataset on a SLURM cluster: a job array of SHARDS tasks (one shard each),
# then a merge job that depends on all of them. The dataset lands in $OUT/dataset.
#   SCENE=scene/ SPEC=spec.toml FRAMES=50000 SHARDS=100 OUT=/shared/ds deploy/slurm/submit.sh [--wait]
# Optional: SEED, SPLIT (default train=0.9,val=0.1), RENDERER (path|bounds),
# BLENDSYNTH (the binary; it and OUT must be on storage every node sees).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
: "${SCENE:?scene folder}" "${SPEC:?spec TOML}" "${FRAMES:?frame count}" "${OUT:?output folder}"
SHARDS=${SHARDS:-4}
mkdir -p "$OUT"
export SCENE SPEC FRAMES OUT SHARDS SEED="${SEED:-0}" SPLIT="${SPLIT:-train=0.9,val=0.1}" RENDERER="${RENDERER:-path}" BLENDSYNTH="${BLENDSYNTH:-blendsynth}"
array=$(sbatch --parsable --chdir="$OUT" --array="0-$((SHARDS - 1))" "$here/shard.sbatch")
echo "shards: job array $array ($SHARDS tasks)"
wait_flag=()
[ "${1:-}" = "--wait" ] && wait_flag=(--wait)
merge=$(sbatch --parsable "${wait_flag[@]}" --chdir="$OUT" --dependency="afterok:${array%%;*}" --kill-on-invalid-dep=yes "$here/merge.sbatch")
echo "merge: job $merge -> $OUT/dataset"
