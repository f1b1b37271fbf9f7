"""Collision queries from Python against tetseg-run (the C++ tool) on generated scenes."""

import subprocess
import sys

import numpy as np
import pytest

import tetseg
from conftest import make_scene, python_env, read_frames_numpy, tetseg_run_json


def python_frames(collider, frames):
    """Per step: (any, earliest contact or None, contacts array)."""
    results = []
    for f in range(frames.shape[0] - 1):
        collider.step(frames[f], frames[f + 1])
        results.append((collider.any_collision(), collider.earliest_toi(), collider.contacts()))
    return results


SCENES = {
    "dumbbell": ["--segments", 16, "--rings", 20, "--frames", 10],
    "sphere": ["--segments", 12, "--rings", 8, "--frames", 6],
    # Over 256 contacts per step: contacts() grows its buffer and traverses again.
    "dumbbell-fine": ["--segments", 24, "--rings", 30, "--frames", 10],
}


@pytest.mark.parametrize("mode", ["rvbc", "bvh", "brute", "cone", "features"])
@pytest.mark.parametrize("scene", sorted(SCENES))
def test_contacts_equal_tetseg_run_step_by_step(bin_dir, tmp_path, mode, scene):
    shape = scene.split("-")[0]
    asset_path, frames_path = make_scene(bin_dir, tmp_path, shape, *SCENES[scene])
    expected = tetseg_run_json(bin_dir, asset_path, frames_path, mode)["frames"]
    frames = read_frames_numpy(frames_path)
    assert np.array_equal(frames, tetseg.read_frames(frames_path))
    collider = tetseg.Collider(tetseg.load_asset(asset_path), mode=mode)
    got = python_frames(collider, frames)
    assert len(got) == len(expected) == frames.shape[0] - 1
    assert any(e["any"] for e in expected), "the scene must reach a contact"
    if scene == "dumbbell-fine":
        assert max(e["contacts"] for e in expected) > 256
    for step, ((any_hit, earliest, contacts), e) in enumerate(zip(got, expected)):
        assert any_hit == e["any"], step
        assert len(contacts) == e["contacts"], step
        if e["earliest_toi"] is None:
            assert earliest is None, step
        else:
            assert earliest["toi"] == e["earliest_toi"], step  # printed with 17 digits
            assert contacts[0] == earliest, step  # sorted, earliest first
        assert np.all(np.diff(contacts["toi"]) >= 0), step
        assert set(np.unique(contacts["kind"])) <= {tetseg.VERTEX_FACE, tetseg.EDGE_EDGE}
        assert np.array_equal(contacts["at_start"], contacts["toi"] == 0) or not len(contacts)


def test_any_query_alone_matches_tetseg_run(bin_dir, dumbbell):
    asset_path, frames_path = dumbbell
    expected = tetseg_run_json(bin_dir, asset_path, frames_path, "rvbc", "any")["frames"]
    frames = tetseg.read_frames(frames_path)
    collider = tetseg.Collider(tetseg.load_asset(asset_path))
    for f, e in enumerate(expected):
        collider.step(frames[f], frames[f + 1])
        assert collider.any_collision() == e["any"], f


def test_contact_records_name_real_features(dumbbell):
    asset_path, frames_path = dumbbell
    asset = tetseg.load_asset(asset_path)
    frames = tetseg.read_frames(frames_path)
    collider = tetseg.Collider(asset, mode="brute")
    tri_set = {tuple(t) for t in asset.triangles.tolist()}
    edges = {tuple(sorted((t[i], t[(i + 1) % 3]))) for t in tri_set for i in range(3)}
    seen = 0
    for f in range(frames.shape[0] - 1):
        collider.step(frames[f], frames[f + 1])
        for c in collider.contacts():
            n = [int(v) for v in c["nodes"]]
            assert len(set(n)) == 4
            if c["kind"] == tetseg.VERTEX_FACE:
                assert tuple(asset.triangles[c["triangle"]]) == tuple(n[1:])
            else:
                assert tuple(n[:2]) in edges and tuple(n[2:]) in edges
            assert 0.0 <= c["toi"] <= 1.0
            seen += 1
    assert seen > 0


def test_options_and_stats(dumbbell):
    asset_path, frames_path = dumbbell
    frames = tetseg.read_frames(frames_path)
    collider = tetseg.Collider(tetseg.load_asset(asset_path), mode="bvh", min_separation=1e-3,
                               time_tolerance=1e-6, max_intervals=512, bvh_leaf_size=2,
                               use_openmp=True, check_first_step=True, time_tests=False)
    assert collider.options == {"mode": "bvh", "min_separation": 1e-3, "time_tolerance": 1e-6,
                                "max_intervals": 512, "bvh_leaf_size": 2, "use_openmp": True,
                                "check_first_step": True, "time_tests": False,
                                "include_still_pairs": False, "threads": 0}
    collider.step(frames[5], frames[6])
    assert collider.rest_intersection["intersecting"] is False
    collider.any_collision()
    stats = collider.stats
    assert stats["nodes_moved"] > 0 and stats["tests_ms"] == 0.0
    assert collider.check_rest_intersection(frames[0]) == {
        "intersecting": False, "triangle_a": 0, "triangle_b": 0, "bodies": (0, 0)}
    with pytest.raises(tetseg.ColliderError, match="reused the step scratch") as error:
        collider.any_collision()  # the check invalidated the step
    assert error.value.status == "no valid step"
    assert set(stats) >= {"refit_ms", "traversal_ms", "feature_tests", "contacts", "full_traversal"}
    defaults = tetseg.Collider(tetseg.load_asset(asset_path)).options
    assert defaults["mode"] == "rvbc" and defaults["max_intervals"] == 2048


def test_asset_arrays_agree_with_tetseg_dump(bin_dir, dumbbell):
    import json

    from conftest import run_tool
    asset_path, _ = dumbbell
    dump = json.loads(run_tool(bin_dir, "tetseg-dump", asset_path, "--json"))
    asset = tetseg.load_asset(asset_path)
    assert asset.node_count == dump["nodes"]
    assert asset.triangle_count == dump["surface_triangles"] == asset.triangles.shape[0]
    assert asset.triangles.shape == (asset.triangle_count, 3) and asset.triangles.dtype == np.uint32
    assert [c["triangles"] for c in dump["clusters"]] == asset.clusters["triangle_count"].tolist()
    assert np.array_equal(asset.detectors, asset.clusters["detector_nodes"])
    assert asset.detectors.shape == (len(asset.clusters), 4)
    assert np.allclose(asset.clusters["detector_weights"].sum(axis=1), 1.0)
    assert np.array_equal(np.sort(asset.cluster_triangles), np.arange(asset.triangle_count))
    for c, cl in enumerate(asset.clusters):
        ids = asset.cluster_triangles[cl["triangle_offset"]:cl["triangle_offset"] + cl["triangle_count"]]
        assert np.all(asset.triangle_cluster[ids] == c)
    assert asset.rest_positions.shape == (asset.node_count, 3)
    for array in (asset.triangles, asset.clusters, asset.detectors, asset.rest_positions):
        assert not array.flags.writeable
        with pytest.raises(ValueError):
            array[0] = array[1]
    assert set(asset.provenance) == {"tool_version", "source", "options"}


def test_load_from_path_pathlike_and_bytes_agree(dumbbell):
    asset_path, _ = dumbbell
    a = tetseg.load_asset(str(asset_path))
    b = tetseg.load_asset(asset_path)  # pathlib.Path
    c = tetseg.load_asset(asset_path.read_bytes())
    d = tetseg.Asset.from_bytes(bytearray(asset_path.read_bytes()))
    e = tetseg.Asset.from_file(asset_path)
    for other in (b, c, d, e):
        assert np.array_equal(a.triangles, other.triangles)
        assert np.array_equal(a.clusters, other.clusters)


def test_runtime_package_does_not_load_preprocess(dumbbell):
    asset_path, frames_path = dumbbell
    code = (
        "import sys, tetseg\n"
        f"a = tetseg.load_asset({str(asset_path)!r}); f = tetseg.read_frames({str(frames_path)!r})\n"
        "c = tetseg.Collider(a); c.step(f[0], f[1]); c.contacts()\n"
        "assert 'tetseg.preprocess' not in sys.modules, sorted(sys.modules)\n")
    subprocess.run([sys.executable, "-c", code], check=True, env=python_env())
    # Static linking: the runtime extension carries no CGAL code at all.
    assert b"CGAL" not in open(tetseg._runtime.__file__, "rb").read()


def test_help_shows_docstrings():
    assert "C-contiguous" in tetseg.Collider.step.__doc__
    assert "min_separation" in tetseg.Collider.__init__.__doc__
    assert "AssetError" in tetseg.load_asset.__doc__


def contact_map(contacts):
    return {(int(c["kind"]), tuple(c["nodes"].tolist())): float(c["toi"]) for c in contacts}


@pytest.mark.parametrize("shape,options", [
    ("dumbbell", ["--segments", 16, "--rings", 20, "--frames", 10]),
    ("sphere", ["--segments", 12, "--rings", 8, "--frames", 6]),
    ("pawn", ["--segments", 16, "--rings", 24, "--frames", 12]),
])
def test_modes_agree_with_brute_force_up_to_the_first_contact(bin_dir, tmp_path, shape, options):
    # docs/runtime.md, "Guarantees and limits": every mode finds the first contact with
    # brute force's earliest toi, bvh finds exactly its contact set, and rvbc every
    # brute-force contact at the earliest toi. Comparisons stop at the first contact step.
    asset_path, frames_path = make_scene(bin_dir, tmp_path, shape, *options)
    asset = tetseg.load_asset(asset_path)
    frames = tetseg.read_frames(frames_path)
    colliders = {mode: tetseg.Collider(asset, mode=mode) for mode in tetseg.MODES}
    for step in range(frames.shape[0] - 1):
        found = {}
        for mode, collider in colliders.items():
            collider.step(frames[step], frames[step + 1])
            found[mode] = (collider.any_collision(), collider.earliest_toi(),
                           contact_map(collider.contacts()))
        brute_any, brute_earliest, brute = found["brute"]
        for mode, (any_hit, earliest, contacts) in found.items():
            assert any_hit == brute_any, (mode, step)
            assert (earliest is None) == (brute_earliest is None), (mode, step)
            if earliest is not None:
                assert earliest["toi"] == brute_earliest["toi"], (mode, step)
        assert found["bvh"][2] == brute, step
        assert found["features"][2] == brute, step
        if brute_any:
            first = brute_earliest["toi"]
            at_first = {k: t for k, t in brute.items() if t == first}
            assert at_first.items() <= found["rvbc"][2].items(), step
            return
    pytest.fail("the scene must reach a contact")
