"""Throughput of obscura.Camera.generate_rays and project through the bindings (run by hand).

    python crates/obscura-py/bench_rays.py [N]

Prints rays per second for N (default 1,000,000) pixel-centre rays of a 1920x1080 perspective
camera, best of five calls, with the time numpy needs to build the input excluded: once into
fresh arrays (the first write to each page of a new array costs a page fault) and once into
`out=` arrays made beforehand, as a loop over batches would reuse them.
"""

import sys
import time

import numpy as np

import obscura

TOML = """
[film]
resolution = [1920, 1080]
[camera]
type = "perspective"
fov = 50.0
eye = [0.0, 1.0, 5.0]
target = [0.0, 0.0, 0.0]
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
"""


def best(f, repeats=5):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000
    cam = obscura.Camera.from_toml(TOML)
    i = np.arange(n)
    xy = np.column_stack([i % 1920 + 0.5, (i // 1920) % 1080 + 0.5]).astype(np.float32)
    o, d, _ = cam.generate_rays(xy)
    p = o + 3.0 * d
    rays = (np.empty((n, 3), np.float32), np.empty((n, 3), np.float32), np.empty(n, bool))
    px = (np.empty((n, 2), np.float32), np.empty(n, bool))
    for name, f, what in [
        ("generate_rays", lambda: cam.generate_rays(xy), "rays"),
        ("generate_rays out=", lambda: cam.generate_rays(xy, out=rays), "rays"),
        ("project", lambda: cam.project(p), "points"),
        ("project out=", lambda: cam.project(p, out=px), "points"),
    ]:
        t = best(f)
        print(f"{name:<19} {n} {what} in {t * 1e3:6.1f} ms = {n / t / 1e6:6.1f} M {what}/s")


if __name__ == "__main__":
    main()
