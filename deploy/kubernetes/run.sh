#!/usr/bin/env bash
# Applies the recipe in order: the shared volume, the Indexed Job of slices, then (once it has
# completed) the merge Job. Copy the scene to /shared/scenes/scene.toml on the volume first
# (e.g. kubectl cp into a pod that mounts it). A failed pod is recreated with the same index
# (backoffLimit in all); if the Job still fails, `obscura merge --list-missing --slices 8
# /shared/parts/slice-*.part`, run in a pod on the volume, prints the indices without a valid
# part: render those (the same command with that index) and apply merge.yaml.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
kubectl apply -f "$here/shared-volume.yaml"
kubectl apply -f "$here/render-slices.yaml"
kubectl wait --for=condition=complete --timeout="${TIMEOUT:-24h}" job/obscura-slices
kubectl apply -f "$here/merge.yaml"
kubectl wait --for=condition=complete --timeout=1h job/obscura-merge
kubectl logs job/obscura-merge
