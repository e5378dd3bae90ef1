"""A sweep from Python against the same sweep as CLI processes: what a scene built once
saves. Renders SEEDS seeds of `exact` (costs given) on forest_slope x seed000 at SIZE,
first with one misalloc.Scene, then one `misalloc render` process each, and prints the
medians per render and the ratio.

    PYTHONPATH=build/python /usr/bin/python3 bench/bench_python.py build/misalloc [SIZE] [SPP] [SEEDS]
"""

import statistics
import subprocess
import sys
import tempfile
import time

import misalloc

cli = sys.argv[1]
size = sys.argv[2] if len(sys.argv) > 2 else "128x128"
spp = int(sys.argv[3]) if len(sys.argv) > 3 else 64
seeds = int(sys.argv[4]) if len(sys.argv) > 4 else 20
options = dict(method="exact", spp=spp, cost="1e-9,2e-9", reference="none")

with tempfile.TemporaryDirectory() as cache:
    start = time.monotonic()
    scene = misalloc.Scene(size=size, cache_dir=cache)
    build = time.monotonic() - start
    python = []
    for seed in range(seeds):
        start = time.monotonic()
        scene.render(seed=seed, **options)
        python.append(time.monotonic() - start)
    processes = []
    for seed in range(seeds):
        start = time.monotonic()
        subprocess.run([cli, "render", "--size", size, "--cache-dir", cache, "--method", "exact", "--spp", str(spp),
                        "--cost", "1e-9,2e-9", "--reference", "none", "--seed", str(seed), "--out", f"{cache}/r.exr",
                        "--report", f"{cache}/r.json", "--no-preview"], check=True, capture_output=True)
        processes.append(time.monotonic() - start)

print(f"{size}, {spp} spp, exact, {seeds} seeds")
print(f"Scene(): {build:.3f} s; first render {python[0]:.3f} s")
print(f"Python, later renders: median {statistics.median(python[1:]) * 1e3:.1f} ms")
print(f"CLI processes: median {statistics.median(processes) * 1e3:.1f} ms "
      f"({statistics.median(processes) / statistics.median(python[1:]):.1f}x)")
