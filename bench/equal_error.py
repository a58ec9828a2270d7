"""Time to equal error: Obscura against Mitsuba 3 on the comparison scenes (`compare.py --only
error`, or this file alone: `python3 bench/equal_error.py [--scenes box,env] [--spp 16,64,256]
[--seeds 2]`).

Equal samples per pixel say little when the two renderers' images are not equally noisy. Here each
scene is one Mitsuba 3 XML file that both renderers read (Obscura through its Mitsuba importer,
`obscura convert`), rendered at several spp; each image's error is measured against a converged
reference, and the figure of merit is the efficiency 1 / (time x MSE): for an unbiased renderer
MSE falls as 1/spp, so the efficiency does not depend on the spp, and the ratio of two renderers'
efficiencies is the ratio of their times to the same error.

* Error: the relative MSE mean((x - ref)^2 / (ref^2 + 0.01)) over pixels and RGB (the 0.01 keeps
  black pixels from dominating), and its square root, the relative RMSE.
* Reference: Mitsuba (llvm_ad_rgb if it loads, else scalar_rgb) at 2 x 4096 spp, each half 16
  passes of 256 spp with their own seeds, averaged; cached in the scratch folder under a hash of
  the scene text and Mitsuba's version. The two halves' difference estimates the reference's own
  error, printed beside it: it must stay far below the errors measured against it.
* Time: Obscura's own render time (the "in X s" it prints: the sample loop, without parsing, the
  BVH build and writing the EXR) and Mitsuba's `mi.render` after a first call at the same spp has
  JIT-compiled its kernels (llvm) -- each side's steady-state cost per image. Both on the same
  pinned cores, two threads by default.
* Configurations: Obscura with its default sampler (Sobol) and with the independent sampler;
  Mitsuba with its defaults (independent sampler, Russian roulette from depth 5) in scalar_rgb and
  llvm_ad_rgb, and llvm_ad_rgb with `ldsampler` and, when Obscura's roulette starts elsewhere
  than Mitsuba's default, with Obscura's start ("fair RR").
* Spread: each ratio is printed with the range of one standard error, from the scatter of the
  seeds' times and errors at each spp (`--seeds`, two by default). A scene whose error has a
  heavy tail (env: the sun seen through glass) needs more seeds than two to pin its ratio down.

Scenes: `spheres` (scenes/spheres-perspective.xml, the comparison scene of `--only render`),
`box` (bench/scenes/box.xml: a Cornell box with a quad light, diffuse, mirror and glass spheres),
`env` (bench/scenes/env.xml: lit only by the sky of scenes/sky.exr, made finer, see SKY_SIZE)
and `mesh` (bench/scenes/mesh.xml: a 999,698-triangle terrain generated here, with a glass
sphere, under the same sky).
"""

import argparse
import hashlib
import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
SCRATCH = Path(os.environ.get("OBSCURA_BENCH_DIR", "/tmp/obscura-bench")) / "error"
SCENES = {
    "spheres": ROOT / "scenes" / "spheres-perspective.xml",
    "box": ROOT / "bench" / "scenes" / "box.xml",
    "env": ROOT / "bench" / "scenes" / "env.xml",
    "mesh": ROOT / "bench" / "scenes" / "mesh.xml",
}
# The comparison renders the shipped sky's procedural function at 2048x1024: Obscura looks an
# environment map up by nearest texel (the radiance is piecewise constant like its sampling
# density), Mitsuba bilinearly, and at the shipped 256x128 their converged images differ along
# the sharp horizon by 0.05 relative RMSE, an error floor that is neither renderer's noise.
SKY_SIZE = "2048x1024"
REFERENCE_PASSES, REFERENCE_PASS_SPP = 16, 256
EPSILON = 0.01


def obscura_rr_depth():
    """Obscura's Russian-roulette start (`PathIntegrator::RR_START_DEPTH`), read from its source
    so Mitsuba's "fair RR" configuration follows it."""
    source = (ROOT / "crates" / "obscura-shade" / "src" / "integrator.rs").read_text()
    found = re.search(r"const RR_START_DEPTH: u32 = (\d+);", source)
    if not found:
        raise SystemExit("equal_error.py: RR_START_DEPTH not found in obscura-shade's integrator")
    return int(found.group(1))


MITSUBA_RR_DEPTH = 5  # the path integrator's documented default


def mitsuba_configs():
    """(label, variant, scene parameters) of each Mitsuba configuration measured. The fair-RR
    configuration is left out when Obscura's roulette start is Mitsuba's default: it would be
    the default configuration again."""
    configs = [
        ("mitsuba scalar_rgb", "scalar_rgb", {}),
        ("mitsuba llvm_ad_rgb", "llvm_ad_rgb", {}),
        ("mitsuba llvm, ldsampler", "llvm_ad_rgb", {"sampler": "ldsampler"}),
    ]
    if obscura_rr_depth() != MITSUBA_RR_DEPTH:
        configs.insert(2, ("mitsuba llvm, fair RR", "llvm_ad_rgb",
                           {"rr_depth": obscura_rr_depth()}))
    return configs


OBSCURA_CONFIGS = [("obscura", "sobol"), ("obscura independent", "independent")]


def pin(cores):
    os.sched_setaffinity(0, set(sorted(os.sched_getaffinity(0))[:cores]))


def set_llvm_path():
    if "DRJIT_LIBLLVM_PATH" not in os.environ:
        # drjit looks for libLLVM.so; LLVM 15 crashes llvm_ad_rgb, so take the newest.
        found = sorted(Path("/usr/lib").glob("*/libLLVM-1[6-9]*.so*")) + sorted(
            Path("/usr/lib").glob("*/libLLVM.so.1[6-9]*")
        )
        if found:
            os.environ["DRJIT_LIBLLVM_PATH"] = str(found[-1])


# --- scene files ---------------------------------------------------------------------------------


def write_terrain(path, n=708, size=6.0):
    """A rippled heightfield of (n - 1)^2 quads, two triangles each, as binary PLY."""
    import numpy as np

    xs = np.linspace(-size / 2, size / 2, n, dtype=np.float64)
    x, z = np.meshgrid(xs, xs)
    y = 0.18 * np.sin(2.3 * x) * np.cos(1.7 * z) + 0.04 * np.sin(9.0 * x + 6.0 * z)
    y += 0.015 * np.sin(31.0 * x) * np.sin(27.0 * z)
    vertices = np.stack([x, y, z], axis=-1).reshape(-1, 3).astype("<f4")
    i = np.arange(n - 1)
    a = (i[:, None] * n + i[None, :]).ravel()
    b, c, d = a + 1, a + n, a + n + 1
    # Counter-clockwise seen from +y, so the normals point up.
    tris = np.concatenate([np.stack([a, c, b], 1), np.stack([b, c, d], 1)]).astype("<u4")
    faces = np.empty(len(tris), dtype=[("n", "u1"), ("v", "<u4", (3,))])
    faces["n"], faces["v"] = 3, tris
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(vertices)}\nproperty float x\nproperty float y\nproperty float z\n"
        f"element face {len(tris)}\nproperty list uchar uint vertex_indices\nend_header\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(vertices.tobytes())
        f.write(faces.tobytes())
    return len(tris)


def sky():
    """The procedural sky at SKY_SIZE, made once by the make_sky example."""
    path = SCRATCH / f"sky-{SKY_SIZE}.exr"
    if not path.exists():
        SCRATCH.mkdir(parents=True, exist_ok=True)
        subprocess.run(["cargo", "run", "--quiet", "--release", "--example", "make_sky", "--",
                        str(path), SKY_SIZE], cwd=ROOT, check=True, capture_output=True)
    return path


def prepare(name):
    """The scene's XML copied to the scratch folder, with the fine sky in place of the shipped
    one (and the mesh written beside it); returns the copy's path."""
    folder = SCRATCH / name
    folder.mkdir(parents=True, exist_ok=True)
    text = SCENES[name].read_text()
    if "../../scenes/sky.exr" in text:
        text = text.replace('value="../../scenes/sky.exr"', f'value="{sky()}"')
    if name == "mesh" and not (folder / "terrain.ply").exists():
        write_terrain(folder / "terrain.ply")
    path = folder / f"{name}.xml"
    path.write_text(text)
    return path


def obscura_scene(xml, sampler):
    """`obscura convert` of the XML, with the sampler set to `sampler`."""
    binary = TARGET / "release" / "obscura"
    out = xml.with_name(f"{xml.stem}-{sampler}.toml")
    subprocess.run([str(binary), "convert", str(xml), "-o", str(out)], check=True,
                   capture_output=True)
    text = out.read_text()
    text, count = re.subn(r'(\[sampler\]\ntype = )"[a-z]+"', rf'\1"{sampler}"', text)
    assert count == 1, f"no [sampler] type in {out}"
    out.write_text(text)
    return out


# --- renders -------------------------------------------------------------------------------------


def read_exr(path):
    import mitsuba as mi
    import numpy as np

    if not mi.variant():
        mi.set_variant("scalar_rgb")
    return np.array(mi.Bitmap(str(path)), dtype=np.float64)[:, :, :3]


def obscura_render(toml, spp, seed, threads, binary=None, out=None):
    """Renders `toml` with `binary` (this checkout's release build by default) pinned to the
    first `threads` cores; returns the image, the render time it prints and the wall time."""
    binary = binary or TARGET / "release" / "obscura"
    out = out or toml.with_name(f"{toml.stem}-{spp}-{seed}.exr")
    cores = ",".join(str(c) for c in range(threads))
    start = time.perf_counter()
    run = subprocess.run(
        ["taskset", "-c", cores, str(binary), "render", str(toml), "-o", str(out), "--spp",
         str(spp), "--seed", str(seed), "--threads", str(threads)],
        check=True, capture_output=True, text=True,
    )
    wall = time.perf_counter() - start
    found = re.search(r" in ([0-9.]+) s ", run.stdout)
    assert found, run.stdout
    return read_exr(out), float(found.group(1)), wall


def mitsuba_worker(variant, xml, spp, seeds, params, out, threads):
    """Renders `xml` once per seed (after one untimed call that compiles the kernels) and saves
    the images as one .npy; prints the times as JSON."""
    pin(threads)
    set_llvm_path()
    import drjit as dr
    import mitsuba as mi
    import numpy as np

    mi.set_variant(variant)
    dr.set_thread_count(threads)
    start = time.perf_counter()
    scene = mi.load_file(xml, spp=spp, **params)
    load = time.perf_counter() - start
    start = time.perf_counter()
    np.array(mi.render(scene, spp=spp, seed=10_000))
    first = time.perf_counter() - start
    images, times = [], []
    for seed in seeds:
        start = time.perf_counter()
        image = np.array(mi.render(scene, spp=spp, seed=seed))  # forces evaluation
        times.append(time.perf_counter() - start)
        images.append(image[:, :, :3])
    np.save(out, np.stack(images))
    print(json.dumps({"load_s": load, "first_s": first, "times": times}))


def mitsuba_render(variant, xml, spp, seeds, params, threads):
    # A stable name per configuration (Python's own hash of a string changes per process).
    key = hashlib.sha256(json.dumps(params, sort_keys=True).encode()).hexdigest()[:8]
    out = xml.with_name(f"mi-{variant}-{spp}-{key}.npy")
    run = subprocess.run(
        [sys.executable, __file__, "--mitsuba-worker", variant, str(xml), str(spp),
         json.dumps(list(seeds)), json.dumps(params), str(out), str(threads)],
        check=True, capture_output=True, text=True,
    )
    import numpy as np

    info = json.loads(run.stdout.strip().splitlines()[-1])
    return np.load(out).astype(np.float64), info


def llvm_works():
    set_llvm_path()
    probe = ("import mitsuba as mi; mi.set_variant('llvm_ad_rgb'); "
             "import drjit as dr; print(dr.sum(mi.Float([1, 2])))")
    run = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    return run.returncode == 0


def reference(name, xml, threads, variant):
    """The converged image (2 x 4096 spp by default) and an estimate of its own relative MSE."""
    import mitsuba as mi
    import numpy as np

    key = hashlib.sha256(
        (xml.read_text() + mi.__version__ + variant + f"{REFERENCE_PASSES}x{REFERENCE_PASS_SPP}")
        .encode()
    ).hexdigest()[:16]
    cache = SCRATCH / f"reference-{name}-{key}.npz"
    if not cache.exists():
        halves = []
        for half in range(2):
            seeds = range(1000 * (half + 1), 1000 * (half + 1) + REFERENCE_PASSES)
            images, _ = mitsuba_render(variant, xml, REFERENCE_PASS_SPP, seeds, {}, threads)
            halves.append(images.mean(axis=0))
        np.savez(cache, a=halves[0], b=halves[1])
    data = np.load(cache)
    ref = 0.5 * (data["a"] + data["b"])
    # Var(mean of halves) = Var(a - b) / 4 for independent halves of equal variance.
    own = rel_mse(data["a"], data["b"], ref) / 4.0
    return ref, own


def relative_variance_of_mean(values):
    """The squared standard error of the values' mean over the mean (0 for one value)."""
    import numpy as np

    if len(values) < 2:
        return 0.0
    mean = float(np.mean(values))
    return float(np.var(values, ddof=1) / len(values)) / (mean * mean)


def rel_mse(image, other, ref):
    import numpy as np

    return float(np.mean((image - other) ** 2 / (ref**2 + EPSILON)))


# --- orchestration -------------------------------------------------------------------------------


def run(scenes, spps, threads, seeds_per_spp=2):
    """Measures every configuration on every scene; returns the results as a dict and prints
    one table per scene."""
    import numpy as np

    variant_ref = "llvm_ad_rgb" if llvm_works() else "scalar_rgb"
    configs = mitsuba_configs()
    if variant_ref != "llvm_ad_rgb":
        print("  llvm_ad_rgb does not load here (see bench/setup.sh); scalar_rgb only",
              file=sys.stderr)
        configs = [c for c in configs if c[1] != "llvm_ad_rgb"]
    results = []
    machine = platform_cpu()
    print(f"machine: {os.cpu_count()} CPUs, {machine}")
    for name in scenes:
        xml = prepare(name)
        ref, ref_mse = reference(name, xml, threads, variant_ref)
        print(f"\n{name}: {ref.shape[1]}x{ref.shape[0]}, {threads} threads; reference "
              f"{variant_ref} 2x{REFERENCE_PASSES * REFERENCE_PASS_SPP} spp, own rel. RMSE "
              f"{ref_mse ** 0.5:.4f}")
        print(f"  {'configuration':<26}{'spp':>6}{'time s':>9}{'rel RMSE':>10}{'efficiency':>12}")
        scene_result = {"scene": name, "machine": machine, "reference_rel_mse": ref_mse,
                        "configs": []}
        # One spp at a time, every configuration at it: the host's speed drifts over the
        # minutes a scene takes, and this way the drift falls on every configuration alike,
        # not on whichever ran last.
        tomls = {label: obscura_scene(xml, sampler) for label, sampler in OBSCURA_CONFIGS}
        points = {label: [] for label in [*tomls, *(label for label, _, _ in configs)]}
        for spp in spps:
            for label, toml in tomls.items():
                for seed in range(seeds_per_spp):
                    image, render_s, wall_s = obscura_render(toml, spp, seed, threads)
                    points[label].append({"spp": spp, "seed": seed, "time_s": render_s,
                                          "wall_s": wall_s, "rel_mse": rel_mse(image, ref, ref)})
            for label, variant, params in configs:
                seeds = list(range(seeds_per_spp))
                images, info = mitsuba_render(variant, xml, spp, seeds, params, threads)
                for seed, image, t in zip(seeds, images, info["times"]):
                    points[label].append({"spp": spp, "seed": seed, "time_s": t,
                                          "load_s": info["load_s"], "first_s": info["first_s"],
                                          "rel_mse": rel_mse(image, ref, ref)})
        scene_result["configs"] = [{"label": label, "points": pts} for label, pts in points.items()]
        for config in scene_result["configs"]:
            for spp in spps:
                pts = [p for p in config["points"] if p["spp"] == spp]
                t = float(np.mean([p["time_s"] for p in pts]))
                mse = float(np.mean([p["rel_mse"] for p in pts]))
                print(f"  {config['label']:<26}{spp:>6}{t:>9.3f}{mse ** 0.5:>10.4f}"
                      f"{1.0 / (t * mse):>12.1f}")
            # The efficiency of a configuration: total samples' time over total error, each
            # spp weighted alike (times and MSEs averaged over the seeds first).
            effs = []
            log_variances = []
            for spp in spps:
                pts = [p for p in config["points"] if p["spp"] == spp]
                times = [p["time_s"] for p in pts]
                mses = [p["rel_mse"] for p in pts]
                effs.append(1.0 / (np.mean(times) * np.mean(mses)))
                log_variances.append(relative_variance_of_mean(times)
                                     + relative_variance_of_mean(mses))
            config["efficiency"] = float(np.exp(np.mean(np.log(effs))))
            # The standard error of log(efficiency): the mean of the spps' logs, each log's
            # variance about the squared relative standard error of its seeds' mean (delta
            # method). From two seeds it is itself rough; it says which ratios are ties.
            config["log_efficiency_se"] = float(np.sqrt(np.sum(log_variances)) / len(spps))
        ours = scene_result["configs"][0]
        print("  time to equal error, Obscura (Sobol) / peer (below 1.0: Obscura is faster),")
        print("  with the range of one standard error from the seeds' scatter:")
        for config in scene_result["configs"][1:]:
            ratio = config["efficiency"] / ours["efficiency"]
            se = float(np.hypot(config["log_efficiency_se"], ours["log_efficiency_se"]))
            config["obscura_time_ratio"] = ratio
            config["obscura_time_ratio_range"] = [ratio * np.exp(-se), ratio * np.exp(se)]
            print(f"    {config['label']:<28}{ratio:>7.2f}  "
                  f"({ratio * np.exp(-se):.2f}-{ratio * np.exp(se):.2f})")
        results.append(scene_result)
    return results


# /proc/cpuinfo's flags of the vector extensions, widest first, with the names printed.
VECTOR_ISAS = [("avx512f", "AVX-512"), ("avx2", "AVX2"), ("avx", "AVX"), ("sse4_2", "SSE4.2")]


def platform_cpu():
    """The CPU as /proc/cpuinfo names it, with its family and model (a virtual machine's model
    name may say only "AMD EPYC") and the widest vector instructions it has."""
    fields = {}
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            fields.setdefault(key.strip(), value.strip())
    except OSError:
        return "unknown CPU"
    flags = set(fields.get("flags", "").split())
    isa = next((name for flag, name in VECTOR_ISAS if flag in flags), "SSE2")
    return (
        f"{fields.get('model name', 'unknown CPU')} (family {fields.get('cpu family', '?')} "
        f"model {fields.get('model', '?')}, {isa})"
    )


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--mitsuba-worker":
        variant, xml, spp, seeds, params, out, threads = sys.argv[2:9]
        return mitsuba_worker(variant, xml, int(spp), json.loads(seeds), json.loads(params),
                              out, int(threads))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--spp", default="16,64,256")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--seeds", type=int, default=2,
                        help="renders per configuration and spp (seeds 0, 1, ...)")
    parser.add_argument("--out", default=str(ROOT / "bench" / "results-error.json"))
    args = parser.parse_args()
    results = run(args.scenes.split(","), [int(s) for s in args.spp.split(",")], args.threads,
                  args.seeds)
    Path(args.out).write_text(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
