"""Surface bodies (asset format 1.2) from Python: the golden surface assets' new fields,
detectors carried by surface weights or by bones (set_detector_positions with NumPy arrays),
skinned_detector_positions against NumPy's own linear blend skinning, and contacts against the
brute-force mode on a vertex falling through the body."""

from pathlib import Path

import numpy as np
import pytest

import tetseg

GOLDEN = Path(__file__).resolve().parents[2] / "tests" / "golden"


@pytest.fixture
def weights_asset():
    return tetseg.load_asset(GOLDEN / "asset-v1.2.tetseg")


@pytest.fixture
def bones_asset():
    return tetseg.load_asset(GOLDEN / "asset-v1.2-bones.tetseg")


def falling_top(asset):
    """The octahedron's rest positions, and the same with its top vertex (4) moved through the
    lower half to below the body (the contacts: vertex 4 and its edges against the lower
    faces)."""
    x0 = np.ascontiguousarray(asset.rest_positions, dtype=np.float64)
    x1 = x0.copy()
    x1[4] = [0.1, 0.05, -2.0]
    return x0, x1


def contact_set(contacts):
    return {(int(c["kind"]), tuple(c["nodes"].tolist()), float(c["toi"])) for c in contacts}


def test_golden_surface_assets_expose_the_new_fields(weights_asset, bones_asset):
    a = weights_asset
    assert (a.body_kind, a.detector_form, a.bone_names) == ("surface", "surface-weights", [])
    assert a.node_count == 7 and a.triangle_count == 8
    terms = a.detector_terms
    assert terms.shape == (8,)
    assert terms["index"].tolist() == [0, 2, 1, 3, 4, 5, 0, 1]
    c = a.clusters
    assert c["detector_term_offset"].tolist() == [0, 5]
    assert c["detector_term_count"].tolist() == [5, 3]
    # Independent truth: the weighted combination of the rest positions is the stored rest.
    for k in range(2):
        lo, n = c["detector_term_offset"][k], c["detector_term_count"][k]
        t = terms[lo:lo + n]
        point = (t["weight"][:, None] * a.rest_positions[t["index"]]).sum(axis=0)
        assert np.array_equal(point, c["detector_rest"][k])
    b = bones_asset
    assert (b.body_kind, b.detector_form) == ("surface", "bones")
    assert b.bone_names == ["root", "spine", "head"]
    assert b.clusters["detector_term_count"].tolist() == [2, 0]
    assert b.clusters["flags"].tolist() == [0, 1]
    with pytest.raises(ValueError):
        b.detector_terms["weight"][0] = 1.0  # read-only view


def test_skinned_detector_positions_match_numpy(bones_asset):
    rng = np.random.default_rng(29)
    matrices = rng.normal(size=(3, 3, 4))
    got = tetseg.skinned_detector_positions(bones_asset, matrices)
    c, t = bones_asset.clusters, bones_asset.detector_terms
    rest = np.c_[c["detector_rest"], np.ones(2)]
    expected = np.array(c["detector_rest"])
    lo, n = c["detector_term_offset"][0], c["detector_term_count"][0]
    expected[0] = sum(w * (matrices[i] @ rest[0]) for i, w in zip(t["index"][lo:lo + n],
                                                                   t["weight"][lo:lo + n]))
    np.testing.assert_allclose(got, expected, rtol=1e-14, atol=1e-14)
    identity = np.tile(np.eye(3, 4), (3, 1, 1))
    assert np.array_equal(tetseg.skinned_detector_positions(bones_asset, identity),
                          c["detector_rest"])
    with pytest.raises(ValueError, match=r"\(3, 3, 4\)"):
        tetseg.skinned_detector_positions(bones_asset, np.zeros((2, 3, 4)))
    with pytest.raises(TypeError, match="float64"):
        tetseg.skinned_detector_positions(bones_asset, np.zeros((3, 3, 4), dtype=np.float32))
    # A strided array is accepted (copied).
    wide = np.zeros((3, 3, 8))
    wide[:, :, ::2] = identity
    assert np.array_equal(tetseg.skinned_detector_positions(bones_asset, wide[:, :, ::2]),
                          c["detector_rest"])


@pytest.mark.parametrize("mode", ["rvbc", "bvh", "cone"])
def test_weighted_surface_body_finds_the_brute_force_contacts(weights_asset, mode):
    x0, x1 = falling_top(weights_asset)
    brute = tetseg.Collider(weights_asset, mode="brute")
    brute.step(x0, x1)
    truth = contact_set(brute.contacts())
    assert truth, "the falling vertex must hit the lower half"
    collider = tetseg.Collider(weights_asset, mode=mode)
    collider.step(x0, x1)
    got = contact_set(collider.contacts())
    assert got <= truth
    assert collider.earliest_toi()["toi"] == brute.earliest_toi()["toi"]
    if mode != "rvbc":
        assert got == truth


def test_bone_carried_detectors_need_positions_and_any_positions_are_exact(bones_asset):
    x0, x1 = falling_top(bones_asset)
    brute = tetseg.Collider(bones_asset, mode="brute")
    brute.step(x0, x1)  # brute force reads no detector
    truth = contact_set(brute.contacts())
    earliest = brute.earliest_toi()["toi"]
    collider = tetseg.Collider(bones_asset)
    with pytest.raises(tetseg.ColliderError, match="set_detector_positions") as error:
        collider.step(x0, x1)
    assert error.value.status == "null input"
    rest = np.ascontiguousarray(bones_asset.clusters["detector_rest"])
    rng = np.random.default_rng(7)
    posed = [rest, tetseg.skinned_detector_positions(bones_asset, np.tile(np.eye(3, 4), (3, 1, 1))),
             rng.normal(scale=5.0, size=(2, 3)), rest[::-1].copy()]
    for d0 in posed:
        d1 = np.ascontiguousarray(d0 + rng.normal(size=(2, 3)))
        collider.set_detector_positions(d0, d1)
        collider.step(x0, x1)
        assert contact_set(collider.contacts()) <= truth
        assert collider.earliest_toi()["toi"] == earliest
    bad = rest.copy()
    bad[0, 1] = np.nan
    collider.set_detector_positions(bad, rest)
    with pytest.raises(tetseg.ColliderError, match="non-finite"):
        collider.step(x0, x1)
    bad[0, 1] = 0.0
    bad[1] = np.nan  # cluster 1 is overlap-only: its entries are never read
    collider.set_detector_positions(bad, bad)
    collider.step(x0, x1)
    with pytest.raises(ValueError, match=r"\(2, 3\)"):
        collider.set_detector_positions(rest[:1], rest[:1])
    with pytest.raises(TypeError):
        collider.set_detector_positions(rest.tolist(), rest)


def test_other_forms_refuse_detector_positions(weights_asset):
    collider = tetseg.Collider(weights_asset)
    d = np.zeros((2, 3))
    with pytest.raises(tetseg.ColliderError, match="surface-weights") as error:
        collider.set_detector_positions(d, d)
    assert error.value.status == "invalid argument"


def test_scene_bodies_over_surface_assets(weights_asset, bones_asset):
    x0, x1 = falling_top(weights_asset)
    scene = tetseg.Scene()
    w = scene.add_body(tetseg.BodyShape.from_asset(weights_asset))
    b = scene.add_body(tetseg.BodyShape.from_asset(bones_asset))
    scene.set_pair_enabled(w, b, False)
    for body in (w, b):
        scene.set_positions(body, x0, x1)
    with pytest.raises(tetseg.ColliderError, match="body 1's detectors are carried by bones"):
        scene.step()
    with pytest.raises(tetseg.ColliderError, match="invalid argument"):
        scene.set_detector_positions(w, np.zeros((2, 3)), np.zeros((2, 3)))
    rest = np.ascontiguousarray(bones_asset.clusters["detector_rest"])
    scene.set_detector_positions(b, rest, rest)
    scene.step()
    contacts = scene.contacts()
    per_body = {body: contact_set(contacts[contacts["bodies"][:, 0] == body]) for body in (w, b)}
    brute = tetseg.Collider(weights_asset, mode="brute")
    brute.step(x0, x1)
    truth = contact_set(brute.contacts())
    for body in (w, b):
        assert per_body[body] and per_body[body] <= truth


def test_gather_node_positions_from_the_files_vertex_order(weights_asset, bones_asset):
    # The weights golden was read from 9 file vertices (seam copies of the top and +x).
    a = weights_asset
    nodes = a.source_vertex_nodes
    assert nodes.dtype == np.uint32 and nodes.tolist() == [4, 0, 1, 2, 3, 4, 5, 6, 0]
    assert a.source_vertex_count == 9
    # Independent truth: file vertex i sits at its node's rest position; gathering the file's
    # vertices, moved by any map, gives the nodes moved by the same map.
    rng = np.random.default_rng(7)
    shift = rng.normal(size=(a.node_count, 3))
    nodes_moved = a.rest_positions + shift
    source = nodes_moved[nodes]
    got = tetseg.gather_node_positions(a, source)
    assert got.shape == (7, 3) and np.array_equal(got, nodes_moved)
    # A strided view works the same.
    wide = np.zeros((9, 6))
    wide[:, ::2] = source
    assert np.array_equal(tetseg.gather_node_positions(a, wide[:, ::2]), nodes_moved)
    # No map: the positions are the nodes'.
    b = bones_asset
    assert b.source_vertex_nodes.shape == (0,) and b.source_vertex_count == 7
    assert np.array_equal(tetseg.gather_node_positions(b, nodes_moved), nodes_moved)
    with pytest.raises(ValueError, match=r"\(9, 3\)"):
        tetseg.gather_node_positions(a, nodes_moved)  # 7 rows: the nodes, not the file's
    with pytest.raises(TypeError):
        tetseg.gather_node_positions(a, source.astype(np.float32))
    with pytest.raises(TypeError):
        tetseg.gather_node_positions(a, source.tolist())
    # Stepped: gathered frames give the contacts the nodes' own frames give.
    x0, x1 = falling_top(a)
    c = tetseg.Collider(a)
    c.step(tetseg.gather_node_positions(a, x0[nodes]), tetseg.gather_node_positions(a, x1[nodes]))
    d = tetseg.Collider(a)
    d.step(x0, x1)
    assert contact_set(c.contacts()) == contact_set(d.contacts()) != set()
