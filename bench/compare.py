#!/usr/bin/env python3
"""Side-by-side performance harness: Obscura against the peers a user would pick instead.

Run by hand from the repository root after `bash bench/setup.sh`:

    python3 bench/compare.py                 # everything (about 10 minutes on 2 cores)
    python3 bench/compare.py --only accel    # BVH only; --only render for the renders
    python3 bench/compare.py --only error    # time to equal error (bench/equal_error.py)

It builds the release `obscura` binary and the `obscura-side` example (CARGO_TARGET_DIR is
honoured), then in this one invocation on this one machine:

* accel: Obscura (`obscura-side`) writes each generated mesh and its ray sets (256x256 pinhole
  primary rays, 65,536 incoherent rays, 65,536 rays that miss the box) to a scratch folder and
  times its build and one-thread closest-hit (full hit record, and the preliminary hit with
  only what rtcIntersect1 returns) and occlusion queries, one ray at a time and as batches
  (Scene::intersect_preliminary_batch, occluded_batch: an array of rays, as embreex's `run`
  takes); Intel Embree 4 through
  `embreex` then builds the very same triangles and traces the very same rays, pinned to one
  core. embreex calls Embree one ray at a time from Cython, so its "miss" figure (rays that miss
  the root box) is printed as the per-call overhead that its other figures include.
* render: `obscura render scenes/spheres-perspective.toml` at 512x512, 16 spp (as shipped, with
  its Sobol sampler, and again with the independent sampler Mitsuba uses), and the same scene
  written for Mitsuba 3 (`scalar_rgb`, and `llvm_ad_rgb` where libLLVM >= 15 loads), on 1 and
  2 threads (each peer run in its own process pinned to that many cores). Mitsuba's path
  tracer gets Obscura's depth and Russian-roulette start, so both trace the same paths.

Prints one table with the ratios (Obscura / peer for throughput, peer / Obscura for time: above
1.0 means Obscura is faster) and writes all figures as JSON to bench/results.json.
"""

import argparse
import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import equal_error

ROOT = Path(__file__).resolve().parent.parent
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
SCRATCH = Path(os.environ.get("OBSCURA_BENCH_DIR", "/tmp/obscura-bench"))
MESHES = [("icosphere", 6), ("icosphere", 8), ("grid", 224), ("grid", 724)]


def rr_start_depth():
    """The bounce after which Obscura's path tracer starts Russian roulette, read from its
    source (`PathIntegrator::RR_START_DEPTH`) so Mitsuba's `rr_depth` follows it."""
    source = (ROOT / "crates" / "obscura-shade" / "src" / "integrator.rs").read_text()
    found = re.search(r"const RR_START_DEPTH: u32 = (\d+);", source)
    if not found:
        raise SystemExit("compare.py: RR_START_DEPTH not found in obscura-shade's integrator")
    return int(found.group(1))


RENDER = dict(resolution=512, spp=16, max_depth=6, rr_depth=rr_start_depth())
# Each side of the BVH comparison runs this many times, alternating with the other, and keeps
# its best figure per measure: this machine's noise only ever slows a run down, and a single
# run of either side swung by 10-20% between invocations.
ACCEL_ROUNDS = 3
# Passes of each measure within one run: obscura-side makes 5 of each of its 15 measures
# (bench/obscura_side.rs), one of each in turn. embreex has 6 measures, so it makes 12 passes
# of each, in turn too: its passes then span at least as much time as Obscura's (about two
# seconds on the 1M meshes), and the host's noise, which comes and goes over seconds
# (docs/performance.md, "The host's noise"), gets as many chances to spare either side.
EMBREE_PASSES = 12


def pin(cores):
    """Restricts this process (and the thread pools it starts later) to `cores` CPUs."""
    os.sched_setaffinity(0, set(sorted(os.sched_getaffinity(0))[:cores]))


# --- workers (each runs in its own process) ---------------------------------------------------


def embree_worker(folder):
    pin(1)
    import numpy as np
    from embreex import rtcore_scene as rtcs
    from embreex.mesh_construction import TriangleMesh

    folder = Path(folder)
    positions = np.fromfile(folder / "positions.f32", dtype=np.float32).reshape(-1, 3)
    triangles = np.fromfile(folder / "triangles.u32", dtype=np.uint32).reshape(-1, 3)
    out = {"triangles": int(len(triangles))}
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        scene = rtcs.EmbreeScene()
        TriangleMesh(scene, positions, triangles)
        # embreex commits (builds) lazily on the first query: one ray.
        scene.run(np.zeros((1, 3), np.float32), np.ones((1, 3), np.float32))
        best = min(best, time.perf_counter() - start)
    out["build_s"] = best
    # As obscura-side does: one pass of each measure in turn, each keeping its fastest, so
    # every measure samples the whole measuring time of the process.
    runs = []
    for name in ["primary", "random", "miss"]:
        rays = np.fromfile(folder / f"rays_{name}.bin", dtype=np.float32).reshape(-1, 6)
        o, d = np.ascontiguousarray(rays[:, :3]), np.ascontiguousarray(rays[:, 3:])
        for query, key in [("INTERSECT", "closest"), ("OCCLUDED", "occluded")]:
            runs.append([name, key, query, o, d, float("inf")])
    for _ in range(EMBREE_PASSES):
        for run in runs:
            name, key, query, o, d, best = run
            start = time.perf_counter()
            res = scene.run(o, d, query=query)
            run[5] = min(best, time.perf_counter() - start)
            if query == "INTERSECT":
                out[f"{name}_hits"] = int((np.asarray(res) >= 0).sum())
    for name, key, _, o, _, best in runs:
        out[f"{name}_{key}_rps"] = len(o) / best
    print(json.dumps(out))


def mitsuba_scene_dict(mi):
    r, spp = RENDER["resolution"], RENDER["spp"]

    def diffuse(rgb):
        return {"type": "diffuse", "reflectance": {"type": "rgb", "value": rgb}}

    def sphere(center, rgb):
        return {"type": "sphere", "center": center, "radius": 0.7, "bsdf": diffuse(rgb)}

    T = mi.ScalarTransform4f
    return {
        "type": "scene",
        # Obscura's max_depth counts bounces after the camera ray; Mitsuba's counts path
        # vertices including the emitter, so it is one more for the same paths. Both count
        # bounces alike for Russian roulette, which Obscura starts after
        # PathIntegrator::RR_START_DEPTH bounces and Mitsuba after rr_depth (default 5): the
        # same start, so neither traces bounces the other ends.
        "integrator": {
            "type": "path",
            "max_depth": RENDER["max_depth"] + 1,
            "rr_depth": RENDER["rr_depth"],
        },
        "sensor": {
            "type": "perspective",
            "fov": 40.0,
            "fov_axis": "smaller",
            "to_world": T().look_at(origin=[0, 1.5, 6], target=[0, 0.6, 0], up=[0, 1, 0]),
            "film": {
                "type": "hdrfilm",
                "width": r,
                "height": r,
                "rfilter": {"type": "gaussian"},
            },
            "sampler": {"type": "independent", "sample_count": spp},
        },
        # The 20 x 20 floor quad at y = 0, facing +y.
        "floor": {
            "type": "rectangle",
            "to_world": T().scale(10.0) @ T().rotate([1, 0, 0], -90.0)
            if hasattr(T(), "__matmul__")
            else T().scale(10.0) * T().rotate([1, 0, 0], -90.0),
            "bsdf": diffuse([0.7, 0.7, 0.7]),
        },
        "red": sphere([-1.6, 0.7, -1.5], [0.8, 0.2, 0.15]),
        "green": sphere([0.0, 0.7, 0.0], [0.2, 0.7, 0.25]),
        "blue": sphere([1.6, 0.7, 1.5], [0.2, 0.3, 0.8]),
        "light": {
            "type": "point",
            "position": [3.0, 6.0, 4.0],
            "intensity": {"type": "rgb", "value": [60.0, 60.0, 60.0]},
        },
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [0.25, 0.3, 0.4]}},
    }


def mitsuba_worker(variant, threads):
    pin(threads)
    equal_error.set_llvm_path()
    import drjit as dr
    import mitsuba as mi

    mi.set_variant(variant)
    dr.set_thread_count(threads)
    scene = mi.load_dict(mitsuba_scene_dict(mi))
    import numpy as np

    times = []
    # The first llvm run includes JIT compilation and is reported apart; then the best of three,
    # as Obscura's figure is the best of three runs.
    for seed in range(4):
        start = time.perf_counter()
        image = mi.render(scene, spp=RENDER["spp"], seed=seed)
        mean = float(np.array(image).mean())  # forces evaluation in every variant
        times.append(time.perf_counter() - start)
    assert mean > 0.0, "Mitsuba rendered a black image"
    print(json.dumps({"first_s": times[0], "best_s": min(times[1:]), "mean": mean}))


# --- orchestration -------------------------------------------------------------------------------


def run_json(cmd, env=None):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env)
    return json.loads(out.stdout.strip().splitlines()[-1])


def cargo_build():
    subprocess.run(
        ["cargo", "build", "--release", "--bin", "obscura", "--example", "obscura-side"],
        cwd=ROOT,
        check=True,
    )


def bench_accel(results):
    side = TARGET / "release" / "examples" / "obscura-side"
    for kind, size in MESHES:
        folder = SCRATCH / f"{kind}-{size}"
        our_runs, peer_runs = [], []
        for _ in range(ACCEL_ROUNDS):
            our_runs.append(
                run_json(["taskset", "-c", "0", str(side), kind, str(size), str(folder)])
            )
            try:
                peer_runs.append(run_json([sys.executable, __file__, "--embree-worker", str(folder)]))
            except (subprocess.CalledProcessError, json.JSONDecodeError) as err:
                print(f"embreex failed on {kind}-{size}: {err}", file=sys.stderr)
                break
        ours, peer = best_of(our_runs), best_of(peer_runs)
        results["accel"].append(
            {"mesh": f"{kind}-{size}", "obscura": ours, "embree": peer, "rounds": len(our_runs)}
        )
        n = ours["triangles"]
        print(f"\n{kind} {size}: {n:,} triangles, one thread")
        print(f"  {'measure':<32}{'Obscura':>14}{'embreex':>14}{'ratio':>8}")
        row(
            "build (s, lower wins)",
            ours["build_s"],
            peer and peer["build_s"],
            invert=True,
        )
        for name in ["primary", "random", "miss"]:
            # "closest" is Obscura's full hit record; "closest, ids" its preliminary hit (t,
            # ids, barycentrics), the same information rtcIntersect1 returns. Both against
            # embreex's one closest-hit figure.
            for label, key, theirs in [
                ("closest", "closest", "closest"),
                ("closest, ids", "preliminary", "closest"),
                ("occluded", "occluded", "occluded"),
                # The batch queries (Scene::intersect_preliminary_batch, occluded_batch) take
                # an array of rays, as embreex's `run` does.
                ("closest, ids, batch", "preliminary_batch", "closest"),
                ("occluded, batch", "occluded_batch", "occluded"),
            ]:
                mine, peers = ours[f"{name}_{key}_rps"], peer and peer[f"{name}_{theirs}_rps"]
                row(f"{name} {label} (Mrays/s)", mine / 1e6, peers and peers / 1e6)
        if peer:
            overhead = 1e9 / peer["miss_closest_rps"]
            print(f"  embreex per-call overhead (miss rays): {overhead:.0f} ns/ray")


def best_of(runs):
    """Per measure, the best of several runs: the shortest time, the highest rate."""
    if not runs:
        return None
    best = dict(runs[0])
    for run in runs[1:]:
        for key, value in run.items():
            if key.endswith("_s"):
                best[key] = min(best[key], value)
            elif key.endswith("_rps"):
                best[key] = max(best[key], value)
    return best


def row(label, ours, peer, invert=False):
    if peer is None:
        print(f"  {label:<32}{ours:>14.3f}{'-':>14}")
        return
    ratio = peer / ours if invert else ours / peer
    print(f"  {label:<32}{ours:>14.3f}{peer:>14.3f}{ratio:>8.2f}")


def bench_render(results):
    binary = TARGET / "release" / "obscura"
    scene = ROOT / "scenes" / "spheres-perspective.toml"
    # The same scene with Mitsuba's sampler (independent), for a like-for-like second figure.
    SCRATCH.mkdir(parents=True, exist_ok=True)
    independent = SCRATCH / "spheres-perspective-independent.toml"
    text = scene.read_text()
    assert 'type = "sobol"' in text, "the comparison scene's sampler changed"
    independent.write_text(text.replace('type = "sobol"', 'type = "independent"'))
    r, spp = RENDER["resolution"], RENDER["spp"]
    print(f"\nspheres-perspective, {r}x{r}, {spp} spp, path max_depth {RENDER['max_depth']}")
    print(f"  {'threads':<10}{'Obscura s':>12}{'scalar_rgb s':>14}{'ratio':>8}{'llvm_ad_rgb s':>15}{'ratio':>8}")

    def obscura_best(path, threads):
        times = []
        for seed in range(3):
            start = time.perf_counter()
            subprocess.run(
                ["taskset", "-c", ",".join(str(c) for c in range(threads)), str(binary),
                 "render", str(path), "-o", str(SCRATCH / f"obscura-{threads}t.exr"),
                 "--resolution", f"{r}x{r}", "--spp", str(spp), "--seed", str(seed),
                 "--threads", str(threads)],
                check=True,
                capture_output=True,
            )
            times.append(time.perf_counter() - start)
        return min(times)

    for threads in [1, 2]:
        ours = obscura_best(scene, threads)
        ours_independent = obscura_best(independent, threads)
        entry = {"threads": threads, "obscura_s": ours, "obscura_independent_s": ours_independent}
        line = f"  {threads:<10}{ours:>12.3f}"
        line_independent = f"  {'(indep.)':<10}{ours_independent:>12.3f}"
        for variant in ["scalar_rgb", "llvm_ad_rgb"]:
            try:
                peer = run_json([sys.executable, __file__, "--mitsuba-worker", variant, str(threads)])
                entry[variant] = peer
                line += f"{peer['best_s']:>14.3f}{peer['best_s'] / ours:>8.2f}"
                line_independent += f"{'':>14}{peer['best_s'] / ours_independent:>8.2f}"
            except (subprocess.CalledProcessError, json.JSONDecodeError) as err:
                entry[variant] = None
                print(f"  mitsuba {variant} unavailable: {str(err)[:200]}", file=sys.stderr)
                line += f"{'-':>14}{'-':>8}"
                line_independent += f"{'-':>14}{'-':>8}"
        results["render"].append(entry)
        print(line)
        print(line_independent)
    one, two = results["render"][0]["obscura_s"], results["render"][1]["obscura_s"]
    print(f"  Obscura 2-thread speed-up: {one / two:.2f}x")
    print("  (indep.): Obscura with the independent sampler, as Mitsuba runs; the scene uses Sobol")


def obscura_render_time(resolution, spp, threads, runs=2):
    """Best wall time of `obscura render` of the comparison scene, pinned to `threads` cores."""
    binary = TARGET / "release" / "obscura"
    scene = ROOT / "scenes" / "spheres-perspective.toml"
    best = float("inf")
    for seed in range(runs):
        start = time.perf_counter()
        subprocess.run(
            ["taskset", "-c", ",".join(str(c) for c in range(threads)), str(binary), "render",
             str(scene), "-o", str(SCRATCH / "scaling.exr"), "--resolution",
             f"{resolution}x{resolution}", "--spp", str(spp), "--seed", str(seed),
             "--threads", str(threads)],
            check=True,
            capture_output=True,
        )
        best = min(best, time.perf_counter() - start)
    return best


def bench_scaling(results):
    """How render time grows with resolution, spp and threads; BVH cost with triangles."""
    scaling = {
        "resolution": [(r, obscura_render_time(r, 16, 1)) for r in [64, 128, 256, 512]],
        "spp": [(n, obscura_render_time(256, n, 1)) for n in [1, 4, 16, 64]],
        "threads": [(t, obscura_render_time(256, 16, t)) for t in [1, 2]],
    }
    results["scaling"] = scaling
    print("\nscaling (spheres-perspective, seconds)")
    for key, points in scaling.items():
        print(f"  {key:<11}" + "  ".join(f"{x}: {t:.3f}" for x, t in points))
    plot(results)


def plot(results):
    """A small log-log plot of every measured cost: docs/performance-scaling.png."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(11, 3.4))
    ax = axes[0]
    for kind in ["icosphere", "grid"]:
        rows = sorted(
            (e["obscura"]["triangles"], e) for e in results["accel"] if e["mesh"].startswith(kind)
        )
        if not rows:
            continue
        n = [t for t, _ in rows]
        ax.loglog(n, [e["obscura"]["build_s"] for _, e in rows], "o-", label=f"build s ({kind})")
        ax.loglog(n, [1e6 / e["obscura"]["random_closest_rps"] for _, e in rows], "s--",
                  label=f"us / incoherent ray ({kind})")
    ax.set_xlabel("triangles")
    ax.set_title("BVH (one thread)")
    ax.legend(fontsize=7)
    scaling = results.get("scaling", {})
    ax = axes[1]
    for key, label in [("resolution", "pixels (16 spp)"), ("spp", "spp (256x256)")]:
        pts = scaling.get(key, [])
        if pts:
            x = [p[0] ** 2 if key == "resolution" else p[0] for p in pts]
            ax.loglog(x, [p[1] for p in pts], "o-", label=label)
    ax.set_xlabel("pixels or samples per pixel")
    ax.set_ylabel("render s, 1 thread")
    ax.set_title("render time")
    ax.legend(fontsize=7)
    ax = axes[2]
    pts = scaling.get("threads", [])
    if pts:
        ax.loglog([p[0] for p in pts], [pts[0][1] / p[1] for p in pts], "o-", label="Obscura")
        ax.loglog([1, 2], [1, 2], ":", color="grey", label="ideal")
    ax.set_xlabel("threads")
    ax.set_ylabel("speed-up")
    ax.set_title("threads (256x256, 16 spp)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    out = ROOT / "docs" / "performance-scaling.png"
    fig.savefig(out, dpi=110)
    print(f"  plot: {out.relative_to(ROOT)}")


def main():
    if len(sys.argv) > 2 and sys.argv[1] == "--embree-worker":
        return embree_worker(sys.argv[2])
    if len(sys.argv) > 3 and sys.argv[1] == "--mitsuba-worker":
        return mitsuba_worker(sys.argv[2], int(sys.argv[3]))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", choices=["accel", "render", "scaling", "error"])
    parser.add_argument("--no-build", action="store_true", help="use the binaries as built")
    args = parser.parse_args()
    SCRATCH.mkdir(parents=True, exist_ok=True)
    if not args.no_build:
        cargo_build()
    machine = equal_error.platform_cpu()
    print(f"machine: {os.cpu_count()} CPUs, {machine}; load {os.getloadavg()}")
    # Both Embree and Obscura ask for huge pages for a large BVH; the kernel grants them only
    # when this says [always] or [madvise].
    print(f"transparent huge pages: {transparent_huge_pages()}")
    # A partial run (--only) replaces its own parts of results.json and keeps the others.
    saved = ROOT / "bench" / "results.json"
    results = json.loads(saved.read_text()) if saved.exists() else {}
    results["transparent_huge_pages"] = transparent_huge_pages()
    # Each part records the machine it ran on: a partial run replaces one part, and the peers'
    # speed depends on the host's vector ISA (llvm_ad_rgb runs 16 lanes with AVX-512, 8 with
    # AVX2), so figures from different hosts must not be read as one run.
    machines = results.setdefault("machines", {})
    if args.only in (None, "accel"):
        results["accel"] = []
        machines["accel"] = machine
        bench_accel(results)
    if args.only in (None, "render"):
        results["render"] = []
        machines["render"] = machine
        bench_render(results)
    if args.only in (None, "scaling"):
        results.setdefault("accel", [])
        machines["scaling"] = machine
        bench_scaling(results)
    if args.only in (None, "error"):
        # Time to equal error on the comparison scenes (bench/equal_error.py).
        machines["error"] = machine
        results["error"] = equal_error.run(list(equal_error.SCENES), [16, 64, 256], 2)
    saved.write_text(json.dumps(results, indent=2))


def transparent_huge_pages():
    try:
        return Path("/sys/kernel/mm/transparent_hugepage/enabled").read_text().strip()
    except OSError:
        return "unknown"


if __name__ == "__main__":
    main()
