#!/usr/bin/env bash
# Runs every fuzz target (or those named) for SECONDS each, then minimises its corpus.
#
#   fuzz/run.sh [SECONDS] [TARGET...]        # default 600 s, every target of `cargo fuzz list`
#
# Corpora live in fuzz/corpus/TARGET (kept in the repository, minimised); seeds come from the
# shipped scenes, the bad-input files and small EXRs and checkpoints rendered here first;
# dictionaries are fuzz/dicts/TARGET.dict. Each target's libFuzzer log goes to
# fuzz/logs/TARGET.log and a summary line per target (executions, coverage, corpus size,
# crashes) to stdout. A crash leaves its input in fuzz/artifacts/TARGET/ and the script exits 1.
# Uses the nightly toolchain when rustup has one, else stable with RUSTC_BOOTSTRAP=1.
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${1:-600}
shift || true

if rustup toolchain list 2>/dev/null | grep -q '^nightly'; then
    fuzz=(cargo +nightly fuzz)
else
    export RUSTC_BOOTSTRAP=1
    fuzz=(cargo fuzz)
fi
command -v cargo-fuzz >/dev/null || { echo "cargo-fuzz is missing: cargo install cargo-fuzz" >&2; exit 2; }

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    mapfile -t targets < <("${fuzz[@]}" list)
fi

# Seeds that need the renderer: a tiny EXR and a tiny checkpoint of a shipped scene.
gen=fuzz/seeds/generated
mkdir -p "$gen" fuzz/logs
if [ ! -s "$gen/tiny.exr" ] || [ ! -s "$gen/tiny.ckpt" ] || [ ! -s "$gen/tiny.part" ]; then
    cargo build --release --quiet
    bin=target/release/obscura
    "$bin" render scenes/spheres-perspective.toml --resolution 4x2 --spp 1 -o "$gen/tiny.exr" >/dev/null
    "$bin" render scenes/spheres-perspective.toml --resolution 4x2 --spp 2 -o "$gen/ckpt.exr" \
        --checkpoint "$gen/tiny.ckpt" --checkpoint-every 0 >/dev/null
    rm -f "$gen/ckpt.exr"
    "$bin" render scenes/spheres-perspective.toml --resolution 4x2 --spp 4 --slice 1/2 \
        -o "$gen/tiny.part" >/dev/null
fi

seeds_of() {
    case "$1" in
        scene_parser | camera) echo scenes tests/bad-input ;;
        obj) echo fuzz/seeds/obj tests/bad-input/models ;;
        exr) echo "$gen/exr" ;;
        checkpoint) echo "$gen/ckpt" ;;
        partial) echo "$gen/part" ;;
        pbrt) echo scenes ;;
        mitsuba) echo scenes ;;
        *) [ -d "fuzz/seeds/$1" ] && echo "fuzz/seeds/$1" ;;
    esac
}
mkdir -p "$gen/exr" "$gen/ckpt" "$gen/part"
cp "$gen/tiny.exr" "$gen/exr/" && cp "$gen/tiny.ckpt" "$gen/ckpt/" && cp "$gen/tiny.part" "$gen/part/"

status=0
for t in "${targets[@]}"; do
    corpus=fuzz/corpus/$t
    mkdir -p "$corpus"
    dict=()
    [ -f "fuzz/dicts/$t.dict" ] && dict=("-dict=fuzz/dicts/$t.dict")
    # shellcheck disable=SC2046
    if ! "${fuzz[@]}" run "$t" "$corpus" $(seeds_of "$t") -- \
        -max_total_time="$secs" -timeout=10 -rss_limit_mb=4096 -max_len=65536 \
        -print_final_stats=1 "${dict[@]}" >"fuzz/logs/$t.log" 2>&1; then
        status=1
    fi
    # Keep the smallest set of inputs that covers every feature (libFuzzer's set-cover merge),
    # each cut to 4 KiB, so the corpus stays small enough to commit (on the mitsuba corpus the
    # cut kept 95% of the features in a third of the bytes).
    min=$(mktemp -d)
    if "${fuzz[@]}" run "$t" "$min" "$corpus" -- -set_cover_merge=1 -max_len=4096 -rss_limit_mb=4096 \
        >"fuzz/logs/$t.cmin.log" 2>&1; then
        rm -rf "$corpus" && mkdir -p "$corpus" && cp "$min"/* "$corpus"/ 2>/dev/null || true
    fi
    rm -rf "$min"
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "fuzz/logs/$t.log" | grep -o '[0-9]*$' || echo '?')
    cov=$(grep -o 'cov: [0-9]* ft: [0-9]*' "fuzz/logs/$t.log" | tail -1 || echo 'cov: ?')
    crashes=$(find "fuzz/artifacts/$t" -type f 2>/dev/null | wc -l)
    echo "$t: ${secs} s, ${execs} executions, ${cov}, corpus $(find "$corpus" -type f | wc -l) files ($(du -sk "$corpus" | cut -f1) KB), ${crashes} crash/timeout files"
done
exit $status
