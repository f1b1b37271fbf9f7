"""Arrays handed to step are used in place and kept alive; a collider keeps its asset alive."""

import gc
import sys
import threading
import tracemalloc

import numpy as np
import pytest

import tetseg
from conftest import contacts_while_polled, make_scene


@pytest.fixture(scope="module")
def large_scene(bin_dir, tmp_path_factory):
    # 80k nodes: each position array is 1.9 MB.
    return make_scene(bin_dir, tmp_path_factory.mktemp("large"), "dumbbell", "--segments", 200,
                      "--rings", 400, "--frames", 40)


def test_step_does_not_copy_positions(large_scene):
    asset = tetseg.load_asset(large_scene[0])
    frames = tetseg.read_frames(large_scene[1])
    x0, x1 = frames[20].copy(), frames[21].copy()
    assert x0.nbytes > 1_500_000
    collider = tetseg.Collider(asset)
    collider.step(x0, x1)  # warm up (first-call allocations of the binding itself)
    collider.contacts()
    tracemalloc.start()
    try:
        base, _ = tracemalloc.get_traced_memory()
        collider.step(x0, x1)
        collider.any_collision()
        collider.earliest_toi()
        collider.contacts()
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    # NumPy reports its allocations to tracemalloc: a copy of x0 or x1 would show here.
    assert peak - base < x0.nbytes // 20, (peak - base, x0.nbytes)


def test_collider_holds_the_step_arrays(dumbbell):
    asset = tetseg.load_asset(dumbbell[0])
    frames = tetseg.read_frames(dumbbell[1])
    last = frames.shape[0] - 2
    reference = tetseg.Collider(asset)
    reference.step(frames[last], frames[last + 1])
    expected = reference.contacts()
    assert len(expected) > 0

    collider = tetseg.Collider(asset)
    x0, x1 = frames[last].copy(), frames[last + 1].copy()
    counts = sys.getrefcount(x0), sys.getrefcount(x1)
    collider.step(x0, x1)
    assert (sys.getrefcount(x0), sys.getrefcount(x1)) == (counts[0] + 1, counts[1] + 1)
    del x0, x1
    gc.collect()
    np.zeros((len(frames[0]) * 64, 3))  # reuse freed memory if it had been freed
    assert np.array_equal(collider.contacts(), expected)
    y0, y1 = frames[0].copy(), frames[1].copy()
    collider.step(y0, y1)
    collider.step(y0, y1)  # the previous step's arrays are released, not leaked
    assert sys.getrefcount(y0) == sys.getrefcount(y1) == 3


def test_collider_outlives_its_asset_object(dumbbell):
    frames = tetseg.read_frames(dumbbell[1])
    last = frames.shape[0] - 2
    asset = tetseg.load_asset(dumbbell[0].read_bytes())
    triangles = asset.triangles
    collider = tetseg.Collider(asset)
    del asset
    gc.collect()
    collider.step(frames[last], frames[last + 1])
    fresh = tetseg.Collider(tetseg.load_asset(dumbbell[0]))
    fresh.step(frames[last], frames[last + 1])
    assert np.array_equal(collider.contacts(), fresh.contacts())
    assert np.array_equal(triangles, collider.asset.triangles)


def test_asset_arrays_outlive_the_asset(dumbbell):
    asset = tetseg.load_asset(dumbbell[0])
    expected = asset.triangles.copy()
    triangles, clusters = asset.triangles, asset.clusters
    del asset
    gc.collect()
    assert np.array_equal(triangles, expected) and len(clusters) > 0


def test_colliders_on_threads_agree_with_serial(dumbbell):
    asset = tetseg.load_asset(dumbbell[0])
    frames = tetseg.read_frames(dumbbell[1])

    def run(out):
        collider = tetseg.Collider(asset)
        for f in range(frames.shape[0] - 1):
            collider.step(frames[f], frames[f + 1])
            out.append(collider.contacts())

    serial = []
    run(serial)
    outs = [[] for _ in range(4)]
    threads = [threading.Thread(target=run, args=(o,)) for o in outs]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for out in outs:
        assert len(out) == len(serial)
        assert all(np.array_equal(a, b) for a, b in zip(out, serial))


def test_gil_is_released_and_a_busy_collider_refuses_a_second_thread(bin_dir, tmp_path):
    # A query long enough to overlap: while one thread is inside contacts(), this thread
    # runs (the GIL is released) and its call on the same collider is refused cleanly.
    asset_path, frames_path = make_scene(bin_dir, tmp_path, "dumbbell", "--segments", 64,
                                         "--rings", 80, "--frames", 40)
    collider = tetseg.Collider(tetseg.load_asset(asset_path), mode="bvh")
    frames = tetseg.read_frames(frames_path)
    collider.step(frames[35], frames[36])
    count, refused = contacts_while_polled(collider)
    # Each refusal is a read made while the other thread was inside contacts(): with the GIL
    # held in C++ only a few (around the binding's Python parts); a ratio of two speeds on the
    # same machine, not a timing.
    assert len(refused) >= 20, "hardly any overlap: is the GIL held during contacts()?"
    assert all("in use by another thread" in r for r in refused)
    assert count > 0
    assert collider.stats["contacts"] > 0  # usable again
