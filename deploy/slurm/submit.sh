#!/usr/bin/env bash
# Renders a scene on a Slurm cluster as N slices and merges them, bit for bit the image one
# machine would make:
#
#   OBSCURA=/shared/bin/obscura SCENE=/shared/scenes/cornell-box.toml OUT_DIR=/shared/run1 \
#   SLICES=64 OUTPUT=/shared/run1/cornell.exr RENDER_FLAGS="--spp 1024" deploy/slurm/submit.sh
#
# Submits one round: the job array (render-slices.sbatch, --array=0-(N-1)), the merge
# (merge.sbatch, --dependency=afterok on the array) and the retry (retry.sbatch,
# --dependency=afternotok on the array: resubmits the slices `obscura merge --list-missing`
# names, RETRIES rounds at most, default 2). Jobs whose dependency can never be met are
# removed (--kill-on-invalid-dep=yes). Prints the three job ids.
#
#   submit.sh --array 3,17   a round for these indices only (what retry.sbatch does)
#   submit.sh --merge-only   just the merge job
# Extra sbatch options for every job (partition, account, time): SBATCH_EXTRA.
set -euo pipefail
: "${OBSCURA:?}" "${SCENE:?}" "${OUT_DIR:?}" "${SLICES:?}" "${OUTPUT:?}"
DEPLOY_DIR=${DEPLOY_DIR:-$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)}
export OBSCURA SCENE OUT_DIR SLICES OUTPUT DEPLOY_DIR SLICE_BY="${SLICE_BY:-passes}"
export RENDER_FLAGS="${RENDER_FLAGS:-}" RETRIES="${RETRIES:-2}"
mkdir -p "$OUT_DIR"
# shellcheck disable=SC2086 # SBATCH_EXTRA is a list of words
sb() { sbatch --parsable --chdir="$OUT_DIR" --export=ALL ${SBATCH_EXTRA:-} "$@"; }

if [ "${1:-}" = "--merge-only" ]; then
  merge=$(sb "$DEPLOY_DIR/merge.sbatch")
  echo "merge $merge"
  exit 0
fi
indices="0-$((SLICES - 1))"
if [ "${1:-}" = "--array" ]; then
  indices=${2:?--array needs a list such as 3,17}
fi
array=$(sb --array="$indices" "$DEPLOY_DIR/render-slices.sbatch")
merge=$(sb --dependency="afterok:$array" --kill-on-invalid-dep=yes "$DEPLOY_DIR/merge.sbatch")
retry=$(MERGE_JOB=$merge sb --dependency="afternotok:$array" --kill-on-invalid-dep=yes \
  "$DEPLOY_DIR/retry.sbatch")
echo "array $array ($indices) merge $merge retry $retry"
