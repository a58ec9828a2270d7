#!/usr/bin/env python3
"""Thread scaling of `obscura render`, and the scaling the machine itself allows.

Run by hand from the repository root, after `cargo build --release`:

    python3 bench/threads.py [RUNS] [BINARY]

1. Renders scenes/spheres-perspective.toml at 512x512, 16 spp, alternately on 1 and 2 threads,
   RUNS times each (default 10), and prints the mean, standard deviation and minimum of the
   render time from the command's summary line, and the speed-up as a ratio of means. On a
   shared virtual machine single runs swing by 5-10%, so one run of each says little.
2. Runs the same 1-thread render alone, then as two copies at once pinned one per core, and
   prints how much throughput the two cores give together: a 2-thread render cannot beat
   that (shared caches, memory bandwidth, the hypervisor), so it is the yardstick for (1).

Needs only Python 3 and `taskset`; nothing in the test suite runs it.
"""

import re
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "scenes" / "spheres-perspective.toml"
ARGS = ["render", str(SCENE), "--resolution", "512x512", "--spp", "16"]


def start(binary, cores, threads, out):
    """Starts one render pinned to `cores`; returns the process."""
    return subprocess.Popen(
        ["taskset", "-c", cores, str(binary), *ARGS, "--threads", str(threads), "-o", out],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )


def seconds(process):
    """The render time from the summary line of a finished render."""
    out, err = process.communicate()
    if process.returncode != 0:
        sys.exit(f"render failed: {err.strip()}")
    found = re.search(r"samples in ([0-9.]+) s", out + err)
    if not found:
        sys.exit(f"no summary line in: {out + err}")
    return float(found.group(1))


def main():
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 10
    binary = Path(sys.argv[2]) if len(sys.argv) > 2 else ROOT / "target" / "release" / "obscura"
    scratch = "/tmp/obscura-threads.exr"

    times = {1: [], 2: []}
    for _ in range(runs):
        for threads in (1, 2):
            times[threads].append(seconds(start(binary, "0,1", threads, scratch)))
    for threads, t in times.items():
        print(
            f"{threads} thread(s): mean {statistics.mean(t):.3f} s, "
            f"sd {statistics.stdev(t):.3f}, min {min(t):.3f}"
        )
    speedup = statistics.mean(times[1]) / statistics.mean(times[2])
    print(f"speed-up (ratio of means): {speedup:.2f}x")

    alone, together = [], []
    for _ in range(max(runs - 2, 2)):
        alone.append(seconds(start(binary, "0", 1, scratch)))
        pair = [start(binary, str(core), 1, f"/tmp/obscura-threads-{core}.exr") for core in (0, 1)]
        together.extend(seconds(p) for p in pair)
    limit = 2 * statistics.mean(alone) / statistics.mean(together)
    print(
        f"machine: one 1-thread render alone {statistics.mean(alone):.3f} s, two at once "
        f"{statistics.mean(together):.3f} s each: the two cores give {limit:.2f}x one core"
    )


if __name__ == "__main__":
    main()
