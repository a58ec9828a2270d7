#!/usr/bin/env bash
# By hand, around a change that must not move a pixel (a refactor): renders every shipped and
# gallery scene small with four integrators, and the quick gallery, and prints each image's
# sha256. Run it on the commit before and after and diff the two outputs; a square-only camera's
# scenes print FAIL lines (the 48x36 override is not square), the same before and after.
# usage: tests/image-hashes.sh REPO OUTDIR > hashes.txt
set -euo pipefail
repo=$1; out=$2
mkdir -p "$out"
cd "$repo"
cargo build --release --quiet --bin obscura --example gallery
bin=target/release/obscura
for s in scenes/*.toml docs/gallery/*.toml; do
  n=$(basename "$s" .toml)
  for integ in path depth normal albedo; do
    "$bin" render "$s" --resolution 48x36 --spp 3 --threads 2 --integrator $integ -o "$out/$n-$integ.exr" >/dev/null 2>&1 || echo "FAIL $s $integ"
  done
done
target/release/examples/gallery --quick "$out/gallery" >/dev/null
cd "$out" && find . -name '*.exr' -o -name '*.png' | sort | xargs sha256sum
