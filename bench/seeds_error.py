#!/usr/bin/env python3
"""Obscura's error at one spp over many seeds, for work on variance: A/B two builds or samplers.

    python3 bench/seeds_error.py --scenes spheres,mesh --spp 64 --seeds 8 \
        [--sampler sobol] [--build old=/path/to/obscura --build new=target/release/obscura]

For each scene of `bench/equal_error.py` and each build (default: `target/release/obscura`),
renders the scene at `--spp` with seeds 100, 101, ... on `--threads` pinned cores (the
harness's own render call) and prints the relative RMSE against that harness's converged
Mitsuba reference (built and cached the first time, as the harness does), the standard error
of the mean MSE as a relative figure of the RMSE, and the median render time. Builds are run seed by seed in turn, so a machine that slows
down slows them alike. The scenes and the error measure are the harness's own (imported).
"""

import argparse
import statistics
from pathlib import Path

import equal_error as harness


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default=",".join(harness.SCENES))
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--sampler", default="sobol")
    parser.add_argument("--build", action="append", default=[],
                        help="NAME=PATH of an obscura binary (repeatable)")
    args = parser.parse_args()
    builds = [b.split("=", 1) for b in args.build] or [
        ["this", str(harness.TARGET / "release" / "obscura")]
    ]
    variant = "llvm_ad_rgb" if harness.llvm_works() else "scalar_rgb"
    for name in args.scenes.split(","):
        xml = harness.prepare(name)
        toml = harness.obscura_scene(xml, args.sampler)
        ref, _ = harness.reference(name, xml, args.threads, variant)
        mses = {label: [] for label, _ in builds}
        times = {label: [] for label, _ in builds}
        for seed in range(100, 100 + args.seeds):
            for label, binary in builds:
                out = Path(toml).with_name(f"{Path(toml).stem}-{label}-{seed}.exr")
                image, seconds, _ = harness.obscura_render(
                    Path(toml), args.spp, seed, args.threads, binary=binary, out=out)
                mses[label].append(harness.rel_mse(image, ref, ref))
                times[label].append(seconds)
        for label, _ in builds:
            m = statistics.fmean(mses[label])
            # The mean MSE's relative standard error, halved: that of its square root.
            spread = harness.relative_variance_of_mean(mses[label]) ** 0.5 / 2
            print(f"{name} {label}: {args.sampler}, {args.spp} spp, {args.seeds} seeds: "
                  f"rel RMSE {m ** 0.5:.4f} +- {100 * spread:.1f}%, "
                  f"median time {statistics.median(times[label]):.3f} s")


if __name__ == "__main__":
    main()
