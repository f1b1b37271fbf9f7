"""Shared fixtures. Run through ctest ("python: pytest") or scripts/test.sh, which set:

TETSEG_BIN_DIR            folder of the built tools (tetseg-scene, tetseg-run, tetseg, ...)
TETSEG_PYTHON_PREPROCESS  1 when tetseg.preprocess was built (its tests run), 0 when not
                          (they are deselected, and a test checks that the module is absent)
PYTHONPATH                <build>/python, or nothing after `pip install`
"""

import json
import os
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import tetseg


def preprocess_built():
    return os.environ.get("TETSEG_PYTHON_PREPROCESS", "1") != "0"


def pytest_configure(config):
    config.addinivalue_line("markers", "preprocess: needs the tetseg.preprocess module")
    config.addinivalue_line("markers", "no_preprocess: only when tetseg.preprocess is not built")


def pytest_collection_modifyitems(config, items):
    # Deselect (never skip) the tests that do not apply to this build.
    unwanted = "no_preprocess" if preprocess_built() else "preprocess"
    kept = [i for i in items if unwanted not in i.keywords]
    dropped = [i for i in items if unwanted in i.keywords]
    if dropped:
        config.hook.pytest_deselected(items=dropped)
        items[:] = kept


@pytest.fixture(scope="session")
def bin_dir():
    path = os.environ.get("TETSEG_BIN_DIR")
    if not path or not (Path(path) / "tetseg-run").exists():
        pytest.fail("TETSEG_BIN_DIR must name the folder of the built tools (tetseg-run, "
                    "tetseg-scene); run the tests through ctest or scripts/test.sh")
    return Path(path)


def python_env():
    """Environment for a child Python that imports the same tetseg as this process."""
    package_parent = str(Path(tetseg.__file__).resolve().parents[1])
    path = os.environ.get("PYTHONPATH")
    return dict(os.environ, PYTHONPATH=package_parent + (os.pathsep + path if path else ""))


def run_tool(bin_dir, *args, cwd=None):
    result = subprocess.run([str(bin_dir / args[0]), *map(str, args[1:])], cwd=cwd,
                            capture_output=True, text=True)
    assert result.returncode == 0, f"{args[0]} failed: {result.stderr}"
    return result.stdout


def make_scene(bin_dir, folder, shape, *options):
    """tetseg-scene output: (asset path, frames path)."""
    asset, frames = folder / f"{shape}.tetseg", folder / f"{shape}.tsf"
    run_tool(bin_dir, "tetseg-scene", shape, asset, frames, *options)
    return asset, frames


@pytest.fixture(scope="session")
def dumbbell(bin_dir, tmp_path_factory):
    """A small generated scene that ends in self-contact."""
    return make_scene(bin_dir, tmp_path_factory.mktemp("dumbbell"), "dumbbell", "--segments",
                      16, "--rings", 20, "--frames", 10)


def read_frames_numpy(path):
    """Frames decoded with NumPy alone (docs/format.md, "Frame sequences")."""
    header = np.fromfile(path, dtype="<u4", count=6)
    nodes, count = int(header[3]), int(header[4])
    return np.fromfile(path, dtype="<f8", offset=24).reshape(count, nodes, 3)


def tetseg_run_json(bin_dir, asset, frames, mode, query="all"):
    out = run_tool(bin_dir, "tetseg-run", asset, frames, "--mode", mode, "--query", query,
                   "--json")
    return json.loads(out)


def contacts_while_polled(engine):
    """Runs one engine.contacts() on a thread while this thread reads engine.stats in a loop
    (no sleep: each read takes microseconds, the query many milliseconds, on any machine).
    Returns (the contact count, the messages of the RuntimeErrors the reads got): with the GIL
    released during the query nearly every read meanwhile is refused; with the GIL held this
    thread cannot run while the query does (only a few reads, around its Python parts)."""
    started, result, refused = threading.Event(), [], []
    engine.contacts()  # the first call sizes the result array (numpy may yield the GIL there)

    def query():
        started.set()
        result.append(len(engine.contacts()))

    worker = threading.Thread(target=query)
    worker.start()
    started.wait()
    while worker.is_alive():
        try:
            engine.stats
        except RuntimeError as error:
            refused.append(str(error))
    worker.join()
    assert result, "contacts() failed on the worker thread"
    return result[0], refused
