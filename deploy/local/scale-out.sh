#!/usr/bin/env bash
# Splits a render into N = 1, 2, 4 slices run as local processes (one thread each, all at
# once, as N one-core machines would), merges them, checks the merge against a one-process
# render byte for byte, and prints a table: wall time here, cost (CPU seconds summed over the
# slices and the merge), the slowest slice's CPU seconds and from it the wall time N one-core
# machines would take (slowest slice + merge: on a shared machine the wall time here measures
# the other users as much as the render), per-slice set-up (scene parse and BVH build) and
# render time as obscura reports them (wall), part size and merge time; then draws cost and
# N-machine time against N to OUT_DIR/scale-out.svg. docs/scale-out.md quotes its output.
#
#   deploy/local/scale-out.sh [OUT_DIR] > table.md
#
# Three workloads: the Cornell box at 320x240 and 64 spp (render-bound); a generated mesh of
# about 800k triangles at 160x120 and 4 spp (start-up-bound: the OBJ parse and BVH build are
# repeated by every slice); the spheres at 1920x1080, depth AOV, 4 spp (merge-I/O-bound: each
# part is 80 bytes a pixel, 166 MB). OBSCURA=path skips the release build.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
out=${1:-$(mktemp -d /tmp/obscura-scale.XXXXXX)}
mkdir -p "$out"
if [ -z "${OBSCURA:-}" ]; then
  (cd "$repo" && cargo build --release --quiet --bin obscura)
  OBSCURA="$repo/target/release/obscura"
fi

# A UV sphere of 640 x 640 quads (819,200 triangles) in front of the Cornell box's camera.
python3 - "$out/sphere.obj" <<'PY'
import math, sys
n = 640
with open(sys.argv[1], "w") as f:
    for i in range(n + 1):
        t = math.pi * i / n
        for j in range(n):
            p = 2 * math.pi * j / n
            f.write(f"v {0.3 * math.sin(t) * math.cos(p):.6f} {0.3 * math.cos(t) + 0.3:.6f} {0.3 * math.sin(t) * math.sin(p):.6f}\n")
    for i in range(n):
        for j in range(n):
            a, b = i * n + j + 1, i * n + (j + 1) % n + 1
            c, d = a + n, b + n
            f.write(f"f {a} {c} {d}\nf {a} {d} {b}\n")
PY
cat > "$out/mesh.toml" <<'TOML'
[film]
resolution = [160, 120]
[sampler]
spp = 4
[integrator]
type = "path"
max_depth = 3
[camera]
eye = [0.0, 0.3, 1.6]
target = [0.0, 0.3, 0.0]
fov = 40.0
[materials.white]
type = "diffuse"
reflectance = [0.7, 0.7, 0.7]
[[shapes]]
type = "mesh"
file = "sphere.obj"
material = "white"
[[lights]]
type = "point"
position = [0.5, 1.0, 1.0]
intensity = [3.0, 3.0, 3.0]
TOML

# field N of `/usr/bin/time -f "%e %U %S"` output, summed over files
sum() { awk -v f="$1" '{ s += $f } END { printf "%.2f", s }' "${@:2}"; }
max() { awk -v f="$1" '$f > m { m = $f } END { printf "%.2f", m }' "${@:2}"; }
# the "label X s" figure of obscura's summary lines, mean over files
mean_of() { grep -ho "$1 [0-9.]* s" "${@:2}" | awk '{ s += $(NF-1); n++ } END { printf "%.3f", s / n }'; }

echo "| workload | N | wall here s | cost CPU s | slowest slice CPU s | N machines s | slice set-up s | slice render s | part MB | merge s | exact |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
: > "$out/points"
for work in cornell mesh bigfilm; do
  case $work in
    cornell) scene="$repo/scenes/cornell-box.toml"; flags=(--resolution 320x240 --spp 64) ;;
    mesh) scene="$out/mesh.toml"; flags=() ;;
    bigfilm) scene="$repo/scenes/spheres-perspective.toml"
      flags=(--resolution 1920x1080 --spp 4 --integrator depth) ;;
  esac
  "$OBSCURA" render "$scene" "${flags[@]}" --threads 1 -o "$out/$work-one.exr" > /dev/null
  for n in 1 2 4; do
    d="$out/$work-$n"; rm -rf "$d"; mkdir -p "$d"
    start=$(date +%s.%N)
    for ((i = 0; i < n; i++)); do
      /usr/bin/time -o "$d/time-$i" -f "%e %U %S" "$OBSCURA" render "$scene" "${flags[@]}" \
        --threads 1 --slice "$i/$n" -o "$d/slice-$i.part" > "$d/log-$i" &
    done
    wait
    /usr/bin/time -o "$d/time-merge" -f "%e %U %S" "$OBSCURA" merge "$d"/slice-*.part \
      -o "$d/merged.exr" > "$d/log-merge"
    end=$(date +%s.%N)
    wall=$(echo "$end - $start" | bc)
    cost=$(echo "$(sum 2 "$d"/time-*) + $(sum 3 "$d"/time-*)" | bc)
    slowest=$(awk '{ c = $2 + $3; if (c > m) m = c } END { printf "%.2f", m }' "$d"/time-[0-9]*)
    merge=$(max 1 "$d/time-merge")
    machines=$(echo "$slowest + $merge" | bc)
    mb=$(du -m --apparent-size "$d/slice-0.part" | cut -f1)
    exact=$(cmp -s "$d/merged.exr" "$out/$work-one.exr" && echo yes || echo NO)
    printf "| %s | %d | %.2f | %.2f | %s | %.2f | %s | %s | %s | %s | %s |\n" "$work" "$n" \
      "$wall" "$cost" "$slowest" "$machines" "$(mean_of "parse, build)" "$d"/log-[0-9]*)" \
      "$(mean_of render "$d"/log-[0-9]*)" "$mb" "$merge" "$exact"
    echo "$work $n $cost $machines" >> "$out/points"
  done
done

# Two panels: cost (CPU s) and N-machine time (s) against N, one line per workload.
python3 - "$out/points" "$out/scale-out.svg" <<'PY'
import sys
rows = [l.split() for l in open(sys.argv[1])]
works = list(dict.fromkeys(r[0] for r in rows))
colours = {"cornell": "#1b6ca8", "mesh": "#c0392b", "bigfilm": "#27ae60"}
W, H, pad = 330, 250, 45
svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{2 * W}" height="{H + 30}" font-family="sans-serif" font-size="11">']
for panel, (col, title) in enumerate([(2, "cost: CPU seconds, all slices + merge"), (3, "time on N one-core machines, s")]):
    x0 = panel * W
    top = max(float(r[col]) for r in rows) * 1.1
    sx = lambda n: x0 + pad + (W - 2 * pad) * (n - 1) / 3
    sy = lambda v: H - pad + 10 - (H - 2 * pad) * v / top
    svg.append(f'<text x="{x0 + pad}" y="15">{title}</text>')
    svg.append(f'<line x1="{sx(1)}" y1="{sy(0)}" x2="{sx(4)}" y2="{sy(0)}" stroke="black"/>')
    svg.append(f'<line x1="{sx(1)}" y1="{sy(0)}" x2="{sx(1)}" y2="{sy(top)}" stroke="black"/>')
    for n in (1, 2, 4):
        svg.append(f'<text x="{sx(n) - 3}" y="{sy(0) + 14}">{n}</text>')
    svg.append(f'<text x="{sx(4) - 10}" y="{sy(0) + 28}">N</text>')
    for k in range(5):
        v = top * k / 4
        svg.append(f'<text x="{x0 + 5}" y="{sy(v) + 4}">{v:.1f}</text>')
    for w in works:
        pts = [(int(r[1]), float(r[col])) for r in rows if r[0] == w]
        path = " ".join(f"{sx(n):.1f},{sy(v):.1f}" for n, v in pts)
        svg.append(f'<polyline points="{path}" fill="none" stroke="{colours.get(w, "gray")}" stroke-width="2"/>')
        n, v = pts[-1]
        svg.append(f'<text x="{sx(n) - 45}" y="{sy(v) - 6}" fill="{colours.get(w, "gray")}">{w}</text>')
svg.append("</svg>")
open(sys.argv[2], "w").write("\n".join(svg) + "\n")
PY
echo
echo "load average while measuring: $(cut -d' ' -f1-3 /proc/loadavg); $(nproc) cores"
