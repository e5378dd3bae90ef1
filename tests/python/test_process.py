"""What a notebook needs of a native module: Ctrl-C stops a render and leaves the
interpreter usable, other threads run while it renders, and renders in a loop do not
leak."""

import ctypes
import os
import subprocess
import sys
import textwrap
import threading

import numpy as np

import misalloc


def run_python(code, timeout=60):
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          timeout=timeout, env=dict(os.environ))


def test_keyboard_interrupt_stops_a_render_and_the_interpreter_goes_on(cache_dir):
    result = run_python(f"""
        import os, subprocess, time
        import misalloc
        scene = misalloc.Scene(envmap="forest_slope", size=(96, 96), cache_dir={str(cache_dir)!r})
        options = dict(method="exact", cost="1e-9,2e-9", reference="none")
        scene.render(spp=64, **options)  # its kernels built: a build is no launch to stop at
        # As a terminal's Ctrl-C: from outside, to a process whose one thread renders.
        subprocess.Popen(["sh", "-c", f"sleep 1; kill -INT {{os.getpid()}}"])
        start = time.monotonic()
        try:
            scene.render(spp=100000, pilot=0.001, stages=1000, **options)
            print("not interrupted")
        except KeyboardInterrupt:
            print(f"interrupted after {{time.monotonic() - start:.1f}} s")
        print("after:", scene.render(method="equal", spp=4, reference="none").image.shape)
    """)
    assert result.returncode == 0, result.stderr
    assert "interrupted after" in result.stdout and "after: (96, 96, 3)" in result.stdout, result.stdout
    seconds = float(result.stdout.split("interrupted after ")[1].split()[0])
    assert seconds < 5  # the whole render would take minutes; a stage, 0.1 s


def test_other_threads_run_while_a_render_runs(cache_dir):
    scene = misalloc.Scene(envmap="forest_slope", size=(64, 64), cache_dir=cache_dir)
    scene.render(method="equal", spp=8, reference="none")  # kernels compiled
    ticks, done = [], threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(1)
            done.wait(0.01)

    thread = threading.Thread(target=tick)
    thread.start()
    rendering = scene.render(method="equal", spp=8192, reference="none")
    done.set()
    thread.join()
    seconds = rendering.report["time_s"]["wall"]
    assert len(ticks) > 0.3 * seconds / 0.01, (len(ticks), seconds)


def resident_bytes():
    """Resident memory once glibc has returned what it keeps of freed blocks: what is
    left is in use."""
    ctypes.CDLL("libc.so.6").malloc_trim(0)
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_renders_in_a_loop_do_not_grow_resident_memory(cache_dir):
    scene = misalloc.Scene(envmap="forest_slope", size=(96, 96), cache_dir=cache_dir)
    options = dict(method="exact", spp=8, cost="1e-9,2e-9", reference="none")
    for seed in range(10):
        scene.render(seed=seed, **options)
    before = resident_bytes()
    for seed in range(100):
        image = scene.render(seed=seed, **options).image
    growth = resident_bytes() - before
    # A render's image is 108 KiB and its α map 144 KiB: leaking either, or the sampler's
    # buffers, would grow it by ≥ 10 MiB over 100 renders.
    assert growth < 8 << 20, f"{growth / 2**20:.1f} MiB"
    assert np.isfinite(image).all()


def test_a_scene_renders_in_one_thread_at_a_time(cache_dir):
    scene = misalloc.Scene(envmap="forest_slope", size=(64, 64), cache_dir=cache_dir)
    scene.render(method="equal", spp=8, reference="none")
    long_render = threading.Thread(target=scene.render, kwargs=dict(method="equal", spp=32768, reference="none"))
    long_render.start()
    refused = None
    while long_render.is_alive() and refused is None:
        try:
            scene.render(method="equal", spp=4, reference="none")
        except RuntimeError as e:
            refused = str(e)
    long_render.join()
    assert refused and "rendering in another thread" in refused
    assert scene.render(method="equal", spp=4, reference="none").image.shape == (64, 64, 3)
