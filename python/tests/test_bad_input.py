"""Bad input raises an exception with a clear message; nothing crashes."""

import numpy as np
import pytest

import tetseg


@pytest.fixture()
def collider_and_frames(dumbbell):
    asset_path, frames_path = dumbbell
    return tetseg.Collider(tetseg.load_asset(asset_path)), tetseg.read_frames(frames_path)


def test_wrong_shape_is_a_value_error(collider_and_frames):
    collider, frames = collider_and_frames
    x = frames[0]
    n = collider.node_count
    for bad in (x.reshape(-1), x[:-1].copy(), np.zeros((n, 2)), np.zeros((n, 3, 1)),
                np.zeros((n + 1, 3))):
        with pytest.raises(ValueError, match=rf"x1 must have shape \({n}, 3\)"):
            collider.step(x, bad)


def test_wrong_dtype_or_type_is_a_type_error(collider_and_frames):
    collider, frames = collider_and_frames
    x = frames[0]
    for bad in (x.astype(np.float32), x.astype(np.int64), x.astype(">f8"),
                x.astype(np.complex128)):
        with pytest.raises(TypeError, match="x0 must have dtype float64"):
            collider.step(bad, x)
    for bad in (x.tolist(), None, 3.0, memoryview(x)):
        with pytest.raises(TypeError, match="x0 must be a numpy.ndarray of float64"):
            collider.step(bad, x)


def test_non_contiguous_is_a_value_error(collider_and_frames):
    collider, frames = collider_and_frames
    x = frames[0]
    wide = np.zeros((x.shape[0], 6))
    wide[:, :3] = x
    for bad in (wide[:, :3], np.asfortranarray(x), np.concatenate([x, x])[::2], x[::-1]):
        with pytest.raises(ValueError, match="C-contiguous"):
            collider.step(x, bad)


def test_nan_is_rejected_and_queries_refuse_to_answer(collider_and_frames):
    collider, frames = collider_and_frames
    asset = collider.asset
    x1 = frames[1].copy()
    x1[asset.triangles[0, 0], 1] = np.nan
    with pytest.raises(tetseg.ColliderError, match="non-finite") as error:
        collider.step(frames[0], x1)
    assert error.value.status == "non-finite position"
    for query in (collider.any_collision, collider.earliest_toi, collider.contacts):
        with pytest.raises(tetseg.ColliderError, match="last step failed") as error:
            query()
        assert error.value.status == "no valid step"
    x1[asset.triangles[0, 0], 1] = np.inf
    with pytest.raises(tetseg.ColliderError, match="non-finite"):
        collider.step(frames[0], x1)
    collider.step(frames[0], frames[1])  # recovers with valid input
    assert collider.any_collision() is False


def test_query_before_any_step(dumbbell):
    collider = tetseg.Collider(tetseg.load_asset(dumbbell[0]))
    with pytest.raises(tetseg.ColliderError, match="no step yet"):
        collider.any_collision()


def test_asset_with_any_flipped_byte_is_refused(dumbbell):
    data = bytearray(dumbbell[0].read_bytes())
    statuses = set()
    for i in range(len(data)):
        data[i] ^= 0x10
        with pytest.raises(tetseg.AssetError, match=r"^asset bytes: ") as error:
            tetseg.load_asset(bytes(data))
        statuses.add(error.value.status)
        data[i] ^= 0x10
    tetseg.load_asset(bytes(data))  # the unmodified bytes still load
    assert statuses <= {"bad magic", "unsupported version", "header checksum", "payload size",
                        "payload checksum"}, statuses
    assert "payload checksum" in statuses and "header checksum" in statuses


def test_other_bad_assets(tmp_path, dumbbell):
    data = dumbbell[0].read_bytes()
    for bad, status in ((b"", "too short"), (data[:100], "payload size"),
                        (b"x" * 100, "bad magic"), (data + b"\0", "payload size")):
        with pytest.raises(tetseg.AssetError) as error:
            tetseg.load_asset(bad)
        assert error.value.status == status
        assert str(error.value).startswith("asset bytes: " + status)
    missing = tmp_path / "missing.tetseg"
    with pytest.raises(tetseg.AssetError, match="missing.tetseg: i/o error") as error:
        tetseg.load_asset(missing)
    assert error.value.status == "i/o error" and isinstance(error.value, ValueError)
    assert tetseg.AssetError.__module__ == "tetseg"
    with pytest.raises(TypeError, match="path .* or bytes"):
        tetseg.load_asset(42)
    with pytest.raises(TypeError):
        tetseg.Asset.from_file(b"bytes are not a path")


def test_bad_collider_arguments(dumbbell):
    asset = tetseg.load_asset(dumbbell[0])
    with pytest.raises(TypeError, match="tetseg.Asset"):
        tetseg.Collider("not an asset")
    with pytest.raises(ValueError, match="unknown mode 'fast'"):
        tetseg.Collider(asset, mode="fast")
    with pytest.raises(TypeError):
        tetseg.Collider(asset, max_intervals=-1)
    with pytest.raises(TypeError):
        tetseg.Collider(asset, "bvh")  # options are keyword-only
    with pytest.raises(IndexError):
        tetseg.Collider(asset).triangle_class(asset.triangle_count)


def test_bad_frame_files(tmp_path):
    short = tmp_path / "short.tsf"
    short.write_bytes(b"TSFRAMES\1\0\0\0")
    with pytest.raises(tetseg.FramesError, match="short.tsf: too short") as error:
        tetseg.read_frames(short)
    assert error.value.status == "too short"
    with pytest.raises(tetseg.FramesError, match="i/o error"):
        tetseg.read_frames(tmp_path / "missing.tsf")
