#!/usr/bin/env bash
# Renders a dataset on a SLURM cluster: a job array of SHARDS tasks (one shard each),
# then a merge job that depends on all of them. The dataset lands in $OUT/dataset.
#   SCENE=scene/ SPEC=spec.toml FRAMES=50000 SHARDS=100 OUT=/shared/ds deploy/slurm/submit.sh [--wait]
# Optional: SEED, SPLIT (default train=0.9,val=0.1), RENDERER (path|bounds),
# BLENDSYNTH (the binary; it and OUT must be on storage every node sees), OIDN_DIR
# (where Open Image Denoise is fetched once, default $OUT/.oidn; OIDN=off to skip).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
: "${SCENE:?scene folder}" "${SPEC:?spec TOML}" "${FRAMES:?frame count}" "${OUT:?output folder}"
SHARDS=${SHARDS:-4}
mkdir -p "$OUT"
export SCENE SPEC FRAMES OUT SHARDS SEED="${SEED:-0}" SPLIT="${SPLIT:-train=0.9,val=0.1}" RENDERER="${RENDERER:-path}" BLENDSYNTH="${BLENDSYNTH:-blendsynth}"
# Open Image Denoise once for the whole array, not per task: fetched here (this host
# has network; compute nodes often do not) onto the shared storage, then every task
# loads it from there and never downloads. Skipped when BLENDSYNTH_OIDN names a library
# already, for the bounds renderer, or with OIDN=off (frames are then written noisy).
if [ "$RENDERER" = path ] && [ -z "${BLENDSYNTH_OIDN:-}" ] && [ "${OIDN:-fetch}" != off ]; then
  if lib=$("$BLENDSYNTH" fetch-oidn --dir "${OIDN_DIR:-$OUT/.oidn}"); then
    export BLENDSYNTH_OIDN="$lib"
    echo "denoiser: $lib"
  else
    echo "warning: could not fetch Open Image Denoise; frames that ask for denoising will be written noisy" >&2
  fi
fi
export BLENDSYNTH_OIDN_DOWNLOAD=0
array=$(sbatch --parsable --chdir="$OUT" --array="0-$((SHARDS - 1))" "$here/shard.sbatch")
echo "shards: job array $array ($SHARDS tasks)"
wait_flag=()
[ "${1:-}" = "--wait" ] && wait_flag=(--wait)
merge=$(sbatch --parsable "${wait_flag[@]}" --chdir="$OUT" --dependency="afterok:${array%%;*}" --kill-on-invalid-dep=yes "$here/merge.sbatch")
echo "merge: job $merge -> $OUT/dataset"
