"""The generated skinned character (tetseg-character) built with detectors='skin' from Python:
the same asset as `tetseg build`, and its bending sequence stepped with bone-carried detectors
posed by skinned_detector_positions from the sequence's bone matrices: every step's earliest
contact and contacts at it equal the brute-force mode's."""

import numpy as np
import pytest

import tetseg
from conftest import run_tool

pytestmark = pytest.mark.preprocess


def contact_set(contacts):
    return {(int(c["kind"]), tuple(c["nodes"].tolist()), float(c["toi"])) for c in contacts}


def test_skinned_character_from_python(bin_dir, tmp_path):
    import tetseg.preprocess as pp
    run_tool(bin_dir, "tetseg-character", "-o", tmp_path / "tube", "--frames", 31)
    gltf = tmp_path / "tube.gltf"
    run_tool(bin_dir, "tetseg", "build", gltf, "--body", "surface", "--detectors", "skin", "-o",
             tmp_path / "cli.tetseg", "-q")
    data, report = pp.build(gltf, body="surface", detectors="skin")
    assert data == (tmp_path / "cli.tetseg").read_bytes()
    assert report["detectors"] == "skin" and "skin" in [s[0] for s in report["stages"]]
    asset = tetseg.load_asset(data)
    assert (asset.body_kind, asset.detector_form) == ("surface", "bones")
    assert asset.bone_names == ["bone0", "bone1", "bone2", "bone3"]
    with pytest.raises(ValueError, match="skin"):
        pp.build((asset.rest_positions, asset.triangles), body="surface", detectors="skin")

    frames = tetseg.read_frames(tmp_path / "tube.tsf")
    bones = tetseg.read_frames(tmp_path / "tube.bones.tsf").reshape(len(frames), 4, 3, 4)
    detectors = [np.ascontiguousarray(tetseg.skinned_detector_positions(asset, m)) for m in bones]
    collider, brute = tetseg.Collider(asset), tetseg.Collider(asset, mode="brute")
    contact_steps = 0
    for f in range(len(frames) - 1):
        collider.set_detector_positions(detectors[f], detectors[f + 1])
        collider.step(frames[f], frames[f + 1])
        brute.step(frames[f], frames[f + 1])
        truth = brute.earliest_toi()  # None when the step has no contact
        got = collider.earliest_toi()
        assert (got is None) == (truth is None), f
        if truth is None:
            continue
        assert float(got["toi"]) == float(truth["toi"]), f
        earliest = {c for c in contact_set(brute.contacts()) if c[2] == float(truth["toi"])}
        assert earliest <= contact_set(collider.contacts()), f
        contact_steps += 1
        break  # later steps start inside each other (the culling's premise ends)
    assert contact_steps == 1
