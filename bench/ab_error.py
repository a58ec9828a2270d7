"""Error at equal spp, and time, of two or more Obscura binaries on one comparison scene, seed by
seed in turns: `python3 bench/ab_error.py box --spp 64 --seeds 8 BINARY_A BINARY_B [...]`.

For a change to the estimator: the harness's scenes and cached references
(`equal_error.py`), each binary rendering the same seeds with the default (Sobol) sampler,
pinned to the same cores, alternating so that the host's drift falls on all of them alike.
Prints per binary the relative MSE at that spp (mean and standard error over the seeds), the
mean render time it prints, the efficiency 1 / (time x MSE), and the relative MSE of the seeds'
mean image (for an unbiased renderer it falls as 1 / seeds, down to the reference's own error).
A binary may be a script that sets the environment and runs a build (for throwaway knobs).
"""

import argparse
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import equal_error as ee  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", choices=sorted(ee.SCENES))
    parser.add_argument("binaries", nargs="+")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()
    import numpy as np

    ee.set_llvm_path()
    xml = ee.prepare(args.scene)
    toml = ee.obscura_scene(xml, "sobol")
    variant = "llvm_ad_rgb" if ee.llvm_works() else "scalar_rgb"
    ref, own = ee.reference(args.scene, xml, args.threads, variant)
    runs = {b: ([], [], []) for b in args.binaries}
    for seed in range(args.seeds):
        for k, binary in enumerate(args.binaries):
            out = ee.SCRATCH / f"ab-{k}-{seed}.exr"
            image, seconds, _ = ee.obscura_render(toml, args.spp, 100 + seed, args.threads,
                                                  binary=binary, out=out)
            runs[binary][0].append(ee.rel_mse(image, ref, ref))
            runs[binary][1].append(seconds)
            runs[binary][2].append(image)
    print(f"{args.scene}: {args.spp} spp, {args.seeds} seeds, {args.threads} threads; "
          f"reference's own rel. MSE {own:.2e}")
    for binary, (errors, times, images) in runs.items():
        mse = statistics.mean(errors)
        spread = statistics.stdev(errors) / len(errors) ** 0.5 if len(errors) > 1 else 0.0
        seconds = statistics.mean(times)
        of_mean = ee.rel_mse(np.mean(images, axis=0), ref, ref)
        print(f"  {binary}: rel MSE {mse:.6f} +- {spread:.6f}, time {seconds:.3f} s, "
              f"efficiency {1 / (mse * seconds):.1f}; mean image {of_mean:.6f}")


if __name__ == "__main__":
    main()
