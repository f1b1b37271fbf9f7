"""tetseg.Scene (several bodies) from Python against independent truth: the Collider on each
body alone, a NumPy brute force of a body falling through a still floor, bounding boxes."""

import gc
import sys

import numpy as np
import pytest

import tetseg
from conftest import contacts_while_polled, make_scene

BODY_MODES = ["rvbc", "bvh", "cone"]


def contact_list(contacts):
    return [(int(c["kind"]), tuple(c["bodies"].tolist()), tuple(c["nodes"].tolist()),
             int(c["triangle"]), float(c["toi"])) for c in contacts]


def floor_under(x):
    """A rectangle of two triangles in the plane z = 0, wider than x (unevenly, so that its
    diagonal misses the body's axis); its points and triangles."""
    lo, hi = x[:, :2].min(axis=0) - [1.0, 0.6], x[:, :2].max(axis=0) + [0.7, 1.3]
    points = np.array([[lo[0], lo[1], 0], [hi[0], lo[1], 0], [hi[0], hi[1], 0],
                       [lo[0], hi[1], 0]], dtype=np.float64)
    return points, np.array([[0, 1, 2], [0, 2, 3]])


def falling_body(frames, asset, drop=0.3):
    """The first frame, translated so that it starts just above z = 0 and moves down by `drop`
    times its height, and shifted so that no surface vertex lies on the floor's diagonal."""
    x = frames[0]
    height = np.ptp(x[:, 2])
    x0 = x + np.array([0.0123, -0.0071, 0.05 * height - x[:, 2].min()])
    x1 = x0 - np.array([0.0, 0.0, drop * height])
    return np.ascontiguousarray(x0), np.ascontiguousarray(x1)


def expected_floor_hits(x0, x1, surface, points):
    """NumPy brute force of vertex (body 0) against floor triangle (body 1): a surface vertex
    moving straight down crosses z = 0 at t = z0 / (z0 - z1), inside exactly one triangle."""
    z0, z1 = x0[surface, 2], x1[surface, 2]
    crossing = surface[(z0 > 0) & (z1 < 0)]
    # Triangle 0 is (p0, p1, p2): below the diagonal p0 -> p2; triangle 1 above it.
    d = points[2, :2] - points[0, :2]
    rel = x0[crossing, :2] - points[0, :2]
    side = d[0] * rel[:, 1] - d[1] * rel[:, 0]
    assert np.all(np.abs(side) > 1e-9 * np.dot(d, d)), "a vertex lies on the diagonal"
    toi = x0[crossing, 2] / (x0[crossing, 2] - x1[crossing, 2])
    return {(int(v), int(s > 0)): t for v, s, t in zip(crossing, side, toi)}


@pytest.fixture(scope="module")
def dumbbell_scene(dumbbell):
    asset_path, frames_path = dumbbell
    return tetseg.load_asset(asset_path), tetseg.read_frames(frames_path)


@pytest.mark.parametrize("mode", BODY_MODES)
def test_body_falling_through_a_still_floor_matches_numpy(dumbbell_scene, mode):
    asset, frames = dumbbell_scene
    x0, x1 = falling_body(frames, asset)
    points, floor_triangles = floor_under(x0)
    scene = tetseg.Scene()
    body = scene.add_body(tetseg.BodyShape.from_asset(asset), mode=mode)
    floor = scene.add_body(tetseg.BodyShape.from_triangles(floor_triangles, len(points)),
                           still=True, self_collision=False)
    assert (body, floor, scene.body_count) == (0, 1, 2)
    scene.set_positions(body, x0, x1)
    scene.set_positions(floor, points)
    scene.step()
    contacts = scene.contacts()
    expected = expected_floor_hits(x0, x1, np.unique(asset.triangles), points)
    assert len(expected) > 10, "the body must cross the floor"
    vertex_face = contacts[contacts["kind"] == tetseg.VERTEX_FACE]
    found = {(int(c["nodes"][0]), int(c["triangle"])): float(c["toi"]) for c in vertex_face}
    assert np.all(vertex_face["bodies"] == [0, 1]), "no floor corner is near the body"
    assert set(found) == set(expected)
    for key, toi in expected.items():
        assert toi - 1e-6 <= found[key] <= toi, key  # a lower bound within the tolerance
    for c in vertex_face:
        assert tuple(c["nodes"][1:]) == tuple(floor_triangles[c["triangle"]])
    # A rigid translation: no self contact; edge-edge contacts only against the diagonal.
    assert np.all((contacts["bodies"] == [0, 1]).all(axis=1))
    assert all(tuple(c["nodes"][2:]) == (0, 2) for c in contacts
               if c["kind"] == tetseg.EDGE_EDGE)
    earliest = scene.earliest_toi()
    assert earliest == contacts[0] and earliest["toi"] <= min(found.values())
    assert scene.any_collision()
    assert scene.pair_stats(0, 1)["contacts"] > 0 and scene.stats["contacts"] > 0
    assert scene.body_stats(0)["contacts"] == 0

    # Switching the pair off removes every contact; the floor above the body finds none.
    scene.set_pair_enabled(0, 1, False)
    assert not scene.any_collision() and len(scene.contacts()) == 0
    scene.set_pair_enabled(0, 1, True)
    scene.set_positions(floor, points - [0, 0, np.ptp(x0[:, 2])])
    scene.step()
    assert not scene.any_collision() and scene.earliest_toi() is None


def test_self_contacts_equal_the_collider_on_each_body_alone(dumbbell_scene):
    # Two bodies at the same positions with their pair switched off: each body's contacts
    # are exactly the collider's (bodies (0, 0) and (1, 1)), and nothing between them.
    asset, frames = dumbbell_scene
    shape = tetseg.BodyShape.from_asset(asset)
    for mode in BODY_MODES:
        scene = tetseg.Scene()
        scene.add_body(shape, mode=mode)
        scene.add_body(shape, mode=mode)  # the same shape, shared
        scene.set_pair_enabled(1, 0, False)
        collider = tetseg.Collider(asset, mode=mode)
        seen = 0
        for f in range(frames.shape[0] - 1):
            scene.set_positions(0, frames[f], frames[f + 1])
            scene.set_positions(1, frames[f], frames[f + 1])
            scene.step()
            contacts = scene.contacts()
            collider.step(frames[f], frames[f + 1])
            expected = collider.contacts()
            assert np.array_equal(contacts[(contacts["bodies"] == 0).all(axis=1)], expected)
            ones = contacts[(contacts["bodies"] == 1).all(axis=1)]
            expected["bodies"] = 1
            assert np.array_equal(ones, expected)
            assert len(contacts) == 2 * len(expected)
            assert scene.any_collision() == collider.any_collision()
            earliest = scene.earliest_toi()
            assert (earliest is None) == (collider.earliest_toi() is None)
            if earliest is not None:
                assert earliest["toi"] == collider.earliest_toi()["toi"]
            assert scene.stats["body_pairs_skipped"] == 1
            assert scene.pair_stats(0, 1)["feature_tests"] == 0
            seen += len(expected)
        assert seen > 0, (mode, "the frames must reach a self contact")


def test_bodies_moving_through_each_other(dumbbell_scene):
    # Body 1 (a copy of body 0) starts `gap` away along x and moves by 2 * (gap + width):
    # the bodies cannot touch before their boxes meet, and must touch before they coincide.
    asset, frames = dumbbell_scene
    x = frames[0]
    width, gap = np.ptp(x[:, 0]), 0.25 * np.ptp(x[:, 0])
    start = x + [width + gap, 0.0, 0.0]
    end = start - [2.0 * (width + gap), 0.0, 0.0]
    scene = tetseg.Scene()
    shape = tetseg.BodyShape.from_asset(asset)
    scene.add_body(shape, still=True)
    scene.add_body(shape)
    scene.set_positions(0, x)
    scene.set_positions(1, start, end)
    scene.step()
    contacts = scene.contacts()
    earliest = scene.earliest_toi()
    travel = 2.0 * (width + gap)
    assert scene.any_collision() and earliest is not None
    assert gap / travel - 1e-6 <= earliest["toi"] <= (width + gap) / travel
    assert earliest == contacts[0]
    assert np.all(contacts["bodies"][:, 0] != contacts["bodies"][:, 1]), "rigid copies"
    # Body 0 is still: switching its self-collision off changes nothing; body 1's neither.
    scene.set_self_collision(0, False)
    scene.set_self_collision(1, False)
    assert np.array_equal(scene.contacts(), contacts)


def global_and_own_scenes(asset, x0, x1, points, floor_triangles):
    """The falling body and the floor, once with own arrays and once from global arrays with
    an unused NaN gap between the two bodies' ranges (never read)."""
    shape = tetseg.BodyShape.from_asset(asset)
    floor = tetseg.BodyShape.from_triangles(floor_triangles, len(points))
    own = tetseg.Scene()
    own.add_body(shape)
    own.add_body(floor, still=True)
    own.set_positions(0, x0, x1)
    own.set_positions(1, points)
    n, gap = len(x0), 5
    g0 = np.full((n + gap + len(points), 3), np.nan)
    g1 = g0.copy()
    g0[:n], g1[:n] = x0, x1
    g0[n + gap:] = points
    shared = tetseg.Scene()
    shared.add_body(shape, global_offset=0)
    shared.add_body(floor, still=True, global_offset=n + gap)
    return own, shared, g0, g1


def test_global_layout_gives_the_same_contacts_as_own_arrays(dumbbell_scene):
    asset, frames = dumbbell_scene
    x0, x1 = falling_body(frames, asset)
    points, floor_triangles = floor_under(x0)
    own, shared, g0, g1 = global_and_own_scenes(asset, x0, x1, points, floor_triangles)
    own.step()
    shared.step(g0, g1)
    expected = own.contacts()
    assert len(expected) > 10
    assert np.array_equal(shared.contacts(), expected)
    assert shared.earliest_toi() == own.earliest_toi()
    assert shared.check_rest_intersection(g0) == own.check_rest_intersection()
    # A mixed scene: the floor in its own array, the body in the global one.
    mixed = tetseg.Scene()
    mixed.add_body(tetseg.BodyShape.from_asset(asset), global_offset=3)
    mixed.add_body(tetseg.BodyShape.from_triangles(floor_triangles, 4), still=True)
    mixed.set_positions(1, points)
    pad = np.zeros((3, 3))
    mixed.step(np.concatenate([pad, x0]), np.concatenate([pad, x1]))
    assert np.array_equal(mixed.contacts(), expected)
    # Only still bodies in the global arrays: x1 is not needed.
    still = tetseg.Scene()
    still.add_body(tetseg.BodyShape.from_asset(asset), still=True, global_offset=0)
    still.add_body(tetseg.BodyShape.from_triangles(floor_triangles, 4), still=True,
                   global_offset=len(x0) + 5)
    still.step(g0)
    assert len(still.contacts()) == 0 and still.stats["body_pairs_skipped"] == 1


def test_still_bodies_read_x0_only(dumbbell_scene):
    asset, frames = dumbbell_scene
    x0, x1 = falling_body(frames, asset)
    points, floor_triangles = floor_under(x0)
    floor = tetseg.BodyShape.from_triangles(floor_triangles, 4)
    results = []
    for floor_x1 in (None, points + [0.0, 0.0, -100.0]):
        scene = tetseg.Scene()
        scene.add_body(tetseg.BodyShape.from_asset(asset))
        scene.add_body(floor, still=True)
        scene.set_positions(0, x0, x1)
        scene.set_positions(1, points, floor_x1)
        scene.step()
        results.append(scene.contacts())
    assert len(results[0]) > 0 and np.array_equal(results[0], results[1])
    # Two still bodies: their pair costs nothing, and nothing is found.
    scene = tetseg.Scene()
    scene.add_body(tetseg.BodyShape.from_asset(asset), still=True)
    scene.add_body(floor, still=True)
    scene.set_positions(0, x0)
    scene.set_positions(1, points)
    scene.step()
    assert not scene.any_collision() and len(scene.contacts()) == 0
    assert scene.stats["body_pairs_skipped"] == 1 and scene.stats["body_pairs_tested"] == 0


def test_rest_intersection_names_the_bodies(dumbbell_scene):
    asset, frames = dumbbell_scene
    x0, _ = falling_body(frames, asset)
    points, floor_triangles = floor_under(x0)
    scene = tetseg.Scene()
    scene.add_body(tetseg.BodyShape.from_asset(asset))
    scene.add_body(tetseg.BodyShape.from_triangles(floor_triangles, 4), still=True)
    scene.set_positions(0, x0, x0)
    scene.set_positions(1, points)
    assert scene.check_rest_intersection()["intersecting"] is False
    scene.set_positions(1, points + [0.0, 0.0, np.median(x0[:, 2])])  # through the body
    check = scene.check_rest_intersection()
    assert check["intersecting"] is True and sorted(check["bodies"]) == [0, 1]
    with pytest.raises(tetseg.ColliderError, match="step") as error:
        scene.contacts()  # the check reused the step scratch
    assert error.value.status == "no valid step"


def test_bad_input_raises(dumbbell_scene):
    asset, frames = dumbbell_scene
    x = frames[0]
    n = asset.node_count
    scene = tetseg.Scene()
    for query in (scene.any_collision, scene.earliest_toi, scene.contacts):
        with pytest.raises(tetseg.ColliderError, match="no step yet") as error:
            query()
        assert error.value.status == "no valid step"
    body = scene.add_body(tetseg.BodyShape.from_asset(asset))
    with pytest.raises(tetseg.ColliderError, match="body 0 has no positions") as error:
        scene.step()
    assert error.value.status == "null input"
    for bad in (x[:-1].copy(), np.zeros((n, 2)), x.reshape(-1)):
        with pytest.raises(ValueError, match=rf"x0 must have shape \({n}, 3\)"):
            scene.set_positions(body, bad, x)
    for bad in (x.astype(np.float32), x.tolist()):
        with pytest.raises(TypeError, match="x1 must"):
            scene.set_positions(body, x, bad)
    with pytest.raises(ValueError, match="C-contiguous"):
        scene.set_positions(body, x, np.asfortranarray(x))
    with pytest.raises(ValueError, match="x1 is required: body 0 is not still"):
        scene.set_positions(body, x)
    for call in (lambda: scene.set_positions(1, x, x), lambda: scene.set_positions(-1, x, x),
                 lambda: scene.body_stats(7), lambda: scene.pair_stats(0, 3),
                 lambda: scene.pair_stats(0, 0), lambda: scene.set_self_collision(2, True),
                 lambda: scene.set_pair_enabled(0, 0, False)):
        with pytest.raises(tetseg.ColliderError) as error:
            call()
        assert error.value.status == "invalid argument"
    with pytest.raises(tetseg.ColliderError, match="unknown body 1"):
        scene.set_positions(1, x, x)

    nan = x.copy()
    nan[asset.triangles[0, 0], 2] = np.nan
    scene.set_positions(body, x, nan)
    with pytest.raises(tetseg.ColliderError, match="NaN") as error:
        scene.step()
    assert error.value.status == "non-finite position"
    with pytest.raises(tetseg.ColliderError, match="last step failed"):
        scene.contacts()
    scene.set_positions(body, frames[0], frames[1])
    scene.step()
    scene.contacts()
    scene.set_positions(body, frames[1], frames[2])
    with pytest.raises(tetseg.ColliderError, match="call step"):
        scene.any_collision()  # new positions, no step yet: never the old step's answer

    # Global layout: missing, short or mismatched arrays.
    shared = tetseg.Scene()
    shared.add_body(tetseg.BodyShape.from_asset(asset), global_offset=2)
    with pytest.raises(tetseg.ColliderError, match=rf"body 0 reads global rows \[2, {n + 2}\) "
                       "but the global arrays have 0 rows") as error:
        shared.step()
    assert error.value.status == "size mismatch"
    with pytest.raises(tetseg.ColliderError, match="not still") as error:
        shared.step(np.zeros((n + 2, 3)))
    assert error.value.status == "null input"
    with pytest.raises(tetseg.ColliderError, match=f"have {n} rows") as error:
        shared.step(x, x)  # rows 2 .. n + 2 do not fit
    assert error.value.status == "size mismatch"
    with pytest.raises(ValueError, match=r"x1 must have shape \(12, 3\)"):
        shared.step(np.zeros((12, 3)), np.zeros((11, 3)))
    with pytest.raises(tetseg.ColliderError, match="global arrays") as error:
        shared.set_positions(0, x, x)
    assert error.value.status == "invalid argument"

    # Shapes and bodies.
    with pytest.raises(ValueError, match="triangle 1 has node id 4"):
        tetseg.BodyShape.from_triangles([[0, 1, 2], [1, 2, 4]], 4)
    with pytest.raises(ValueError, match="triangle 0 repeats a node"):
        tetseg.BodyShape.from_triangles([[0, 1, 1]], 4)
    with pytest.raises(ValueError, match=r"shape \(M, 3\)"):
        tetseg.BodyShape.from_triangles([0, 1, 2], 4)
    with pytest.raises(TypeError, match="integer"):
        tetseg.BodyShape.from_triangles([[0.0, 1.0, 2.0]], 4)
    with pytest.raises(TypeError, match="Asset"):
        tetseg.BodyShape.from_asset(x)
    with pytest.raises(TypeError, match="BodyShape"):
        scene.add_body(asset)
    with pytest.raises(ValueError, match="unknown mode"):
        scene.add_body(tetseg.BodyShape.from_asset(asset), mode="fast")
    with pytest.raises(tetseg.ColliderError, match="brute") as error:
        scene.add_body(tetseg.BodyShape.from_asset(asset), mode="brute")
    assert error.value.status == "invalid argument"
    with pytest.raises(ValueError, match="global_offset"):
        scene.add_body(tetseg.BodyShape.from_asset(asset), global_offset=-1)
    with pytest.raises(TypeError, match="global_offset"):
        scene.add_body(tetseg.BodyShape.from_asset(asset), global_offset=1.5)
    assert scene.body_count == 1


def test_traversal_overflow_is_an_error_not_an_answer(dumbbell_scene):
    asset, frames = dumbbell_scene
    x0, x1 = falling_body(frames, asset)
    points, floor_triangles = floor_under(x0)
    scene = tetseg.Scene(traversal_stack=1)
    assert scene.options["traversal_stack"] == 1
    scene.add_body(tetseg.BodyShape.from_asset(asset), mode="bvh")
    scene.add_body(tetseg.BodyShape.from_triangles(floor_triangles, 4), still=True)
    scene.set_positions(0, x0, x1)
    scene.set_positions(1, points)
    scene.step()
    for query in (scene.any_collision, scene.earliest_toi, scene.contacts):
        with pytest.raises(tetseg.ColliderError, match="traversal_stack") as error:
            query()
        assert error.value.status == "traversal stack overflow"


def test_scene_outlives_its_shapes_assets_and_arrays(dumbbell, dumbbell_scene):
    _, frames = dumbbell_scene
    last = frames.shape[0] - 2
    reference = tetseg.Collider(tetseg.load_asset(dumbbell[0]))
    reference.step(frames[last], frames[last + 1])
    expected = reference.contacts()
    assert len(expected) > 0

    asset = tetseg.load_asset(dumbbell[0].read_bytes())
    shape = tetseg.BodyShape.from_asset(asset)
    assert shape.asset is asset and shape.has_clusters and shape.node_count == asset.node_count
    scene = tetseg.Scene()
    scene.add_body(shape)
    x0, x1 = frames[last].copy(), frames[last + 1].copy()
    counts = sys.getrefcount(x0), sys.getrefcount(x1)
    scene.set_positions(0, x0, x1)
    assert (sys.getrefcount(x0), sys.getrefcount(x1)) == (counts[0] + 1, counts[1] + 1)
    del asset, shape, x0, x1
    gc.collect()
    np.zeros((len(frames[0]) * 64, 3))  # reuse freed memory if it had been freed
    scene.step()
    assert np.array_equal(scene.contacts(), expected)
    y0, y1 = frames[0].copy(), frames[1].copy()
    scene.set_positions(0, y0, y1)
    scene.set_positions(0, y0, y1)  # the replaced arrays are released, not leaked
    assert sys.getrefcount(y0) == sys.getrefcount(y1) == 3
    g0, g1 = np.zeros((4, 3)), np.zeros((4, 3))
    scene.step(g0, g1)  # global arrays (unused here) are held until the next step
    assert sys.getrefcount(g0) == sys.getrefcount(g1) == 3


def test_gil_is_released_and_a_busy_scene_refuses_a_second_thread(bin_dir, tmp_path):
    asset_path, frames_path = make_scene(bin_dir, tmp_path, "dumbbell", "--segments", 64,
                                         "--rings", 80, "--frames", 40)
    asset = tetseg.load_asset(asset_path)
    frames = tetseg.read_frames(frames_path)
    scene = tetseg.Scene()
    scene.add_body(tetseg.BodyShape.from_asset(asset), mode="bvh")
    scene.set_positions(0, frames[35], frames[36])
    scene.step()
    count, refused = contacts_while_polled(scene)
    assert len(refused) >= 20, "hardly any overlap: is the GIL held during contacts()?"
    assert all("this Scene is in use by another thread" in r for r in refused)
    assert count > 0 and scene.stats["contacts"] > 0
