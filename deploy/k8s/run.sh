#!/usr/bin/env bash
# Applies the shard Job, waits for it, then runs the merge Job (kubectl on PATH).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
kubectl apply -f "$here/generate.yaml"
kubectl wait --for=condition=complete job/blendsynth-shards --timeout="${TIMEOUT:-24h}"
kubectl apply -f "$here/merge.yaml"
kubectl wait --for=condition=complete job/blendsynth-merge --timeout=1h
