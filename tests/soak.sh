#!/usr/bin/env bash
# The long soak test of interrupted renders (run by hand; the test suite runs a five-cycle
# version, tests/it/soak.rs):
#
#   bash tests/soak.sh [CYCLES] [SCENE]        # default 100 cycles of scenes/spheres-thin-lens.toml
#
# Renders SCENE straight through once, then again while sending SIGINT at a random moment of
# each run (0 to 200 ms after it starts, before or after its signal handlers are installed)
# and resuming from the checkpoint every time, until CYCLES interrupts have landed; then lets
# it finish. The final image must equal the straight one bit for bit and the folder must hold
# no temporary file (the interrupted runs' partial images are out.exr's first, then
# out.partial.exr beside it). Exits 0 on success, 1 with a message otherwise.
set -euo pipefail
# Job control: without it bash starts background jobs with SIGINT ignored, and an interrupt
# that lands before the render installs its handler would be lost.
set -m
cd "$(dirname "$0")/.."
cycles=${1:-100}
scene=${2:-scenes/spheres-thin-lens.toml}
cargo build --release --quiet
bin=$PWD/target/release/obscura
dir=$(mktemp -d /tmp/obscura-soak.XXXXXX)
trap 'rm -rf "$dir"' EXIT
# Large enough that 100 interrupts land before the end (a minute or two straight, two cores).
flags=(--resolution 160x120 --spp 4096 --threads 2)

"$bin" render "$scene" -o "$dir/straight.exr" "${flags[@]}" >/dev/null
landed=0 runs=0 early=0
while [ "$landed" -lt "$cycles" ]; do
    resume=()
    [ -f "$dir/soak.ckpt" ] && resume=(--resume "$dir/soak.ckpt")
    # SIGINT at its default action, even when this script was started with it ignored (as a
    # background job of a non-interactive shell is): an early signal must stop the render.
    env --default-signal=INT "$bin" render "$scene" -o "$dir/out.exr" "${flags[@]}" \
        --checkpoint "$dir/soak.ckpt" --checkpoint-every 0 "${resume[@]}" >"$dir/out" 2>"$dir/err" &
    pid=$!
    # Signal the render, not the shell that is about to exec it (a signal there can be lost).
    while [ "$(readlink "/proc/$pid/exe" 2>/dev/null)" != "$bin" ] && kill -0 "$pid" 2>/dev/null; do :; done
    sleep "0.$(printf '%03d' $((RANDOM % 200)))"
    kill -INT "$pid" 2>/dev/null || true
    set +e
    wait "$pid"
    code=$?
    set -e
    runs=$((runs + 1))
    case $code in
        130) landed=$((landed + 1)) ;;
        0) echo "the render finished after $landed interrupts; use a larger --spp" >&2
           cat "$dir/out" "$dir/err" >&2; exit 1 ;;
        # SIGINT before the handlers were installed: the default action, no checkpoint change.
        *) if grep -q . "$dir/err"; then cat "$dir/err" >&2; echo "exit $code" >&2; exit 1; fi
           early=$((early + 1)) ;;
    esac
done
"$bin" render "$scene" -o "$dir/out.exr" "${flags[@]}" --checkpoint "$dir/soak.ckpt" \
    --resume "$dir/soak.ckpt" >/dev/null
rm -f "$dir/err" "$dir/out"
if ! cmp -s "$dir/out.exr" "$dir/straight.exr"; then
    echo "FAIL: the resumed image differs from the straight render" >&2
    exit 1
fi
left=$(ls "$dir" | grep -v -x -e out.exr -e out.partial.exr -e soak.ckpt -e straight.exr || true)
if [ -n "$left" ]; then
    echo "FAIL: files left behind: $left" >&2
    exit 1
fi
echo "soak: $landed interrupts landed in $runs runs ($early before the handlers were installed); final image equals the straight render bit for bit; no file left behind"
