"""The options include_still_pairs and threads of tetseg.Collider and tetseg.Scene, against
behaviour: a still pair in contact is reported only with include_still_pairs (truth worked
out by hand below), and contacts on two OpenMP threads equal those on one and serial ones."""

import numpy as np
import pytest

import tetseg

# A floor square of two triangles at z = 0 (diagonal from (0, 0) to (2, 2)), and a triangle
# standing on it on one vertex, (1.5, 0.5, 0), inside floor triangle 0 (x > y) and off its
# edges: its other nodes are at z = 1. The only feature pair in contact: that vertex against
# floor triangle 0 (its edges meet the floor only at that vertex, inside the triangle).
FLOOR_POINTS = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]], dtype=np.float64)
FLOOR_TRIANGLES = np.array([[0, 1, 2], [0, 2, 3]])
STANDING = np.array([[1.5, 0.5, 0], [1.5, 0.5, 1], [1.7, 0.6, 1]], dtype=np.float64)
# (kind, bodies, nodes, triangle, toi, at_start) of that contact at the start of a step.
TOUCHING = (tetseg.VERTEX_FACE, (1, 0), (0, 0, 1, 2), 0, 0.0, True)


def records(contacts):
    return [(int(c["kind"]), tuple(c["bodies"].tolist()), tuple(c["nodes"].tolist()),
             int(c["triangle"]), float(c["toi"]), bool(c["at_start"])) for c in contacts]


def standing_scene(include_still_pairs, x0, x1):
    scene = tetseg.Scene(include_still_pairs=include_still_pairs)
    floor = scene.add_body(tetseg.BodyShape.from_triangles(FLOOR_TRIANGLES, 4), still=True,
                           self_collision=False)
    body = scene.add_body(tetseg.BodyShape.from_triangles(np.array([[0, 1, 2]]), 3))
    scene.set_positions(floor, FLOOR_POINTS)
    scene.set_positions(body, x0, x1)
    scene.step()
    return scene


def test_scene_reports_a_still_contact_only_with_include_still_pairs():
    x = np.ascontiguousarray(STANDING)
    assert records(standing_scene(False, x, x.copy()).contacts()) == []
    assert records(standing_scene(True, x, x.copy()).contacts()) == [TOUCHING]
    assert standing_scene(True, x, x.copy()).any_collision()
    assert not standing_scene(False, x, x.copy()).any_collision()
    assert standing_scene(True, x, x.copy()).options["include_still_pairs"] is True
    assert tetseg.Scene().options["include_still_pairs"] is False


def test_moving_contacts_do_not_depend_on_include_still_pairs():
    # The same triangle dropped from z + 0.5 to z - 0.5: its vertex reaches the floor at t = 0.5.
    x0 = np.ascontiguousarray(STANDING + [0, 0, 0.5])
    x1 = np.ascontiguousarray(STANDING - [0, 0, 0.5])
    for include in (False, True):
        found = records(standing_scene(include, x0, x1).contacts())
        assert len(found) == 1
        kind, bodies, nodes, triangle, toi, at_start = found[0]
        assert (kind, bodies, nodes, triangle, at_start) == TOUCHING[:4] + (False,)
        assert 0.5 - 1e-6 <= toi <= 0.5


def dumbbell_contacts(asset, frames, **options):
    collider = tetseg.Collider(asset, **options)
    out = []
    for i in range(len(frames) - 1):
        collider.step(frames[i], frames[i + 1])
        out.append((records(collider.contacts()), collider.earliest_toi() is not None))
    return out, collider.options


@pytest.mark.parametrize("mode", ["rvbc", "bvh"])
def test_contacts_on_one_and_two_threads_are_the_same(dumbbell, mode):
    asset_path, frames_path = dumbbell
    asset = tetseg.load_asset(asset_path)
    frames = tetseg.read_frames(frames_path)
    serial, _ = dumbbell_contacts(asset, frames, mode=mode)
    one, options_one = dumbbell_contacts(asset, frames, mode=mode, use_openmp=True, threads=1)
    two, options_two = dumbbell_contacts(asset, frames, mode=mode, use_openmp=True, threads=2)
    assert options_one["threads"] == 1 and options_two["threads"] == 2
    assert sum(len(c) for c, _ in serial) > 0  # the frames carry contacts
    assert one == serial and two == serial
    with pytest.raises(TypeError):
        tetseg.Collider(asset, threads=-1)


def test_scene_contacts_on_one_and_two_threads_are_the_same():
    x0 = np.ascontiguousarray(STANDING + [0, 0, 0.5])
    x1 = np.ascontiguousarray(STANDING - [0, 0, 0.5])
    found = []
    for threads in (1, 2):
        scene = tetseg.Scene(use_openmp=True, threads=threads)
        floor = scene.add_body(tetseg.BodyShape.from_triangles(FLOOR_TRIANGLES, 4), still=True)
        body = scene.add_body(tetseg.BodyShape.from_triangles(np.array([[0, 1, 2]]), 3))
        scene.set_positions(floor, FLOOR_POINTS)
        scene.set_positions(body, x0, x1)
        scene.step()
        assert scene.options["threads"] == threads
        found.append(records(scene.contacts()))
    assert len(found[0]) == 1 and found[0] == found[1]
