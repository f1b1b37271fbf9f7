"""tetseg.preprocess against the `tetseg` CLI: same options and defaults give the same bytes."""

import json

import numpy as np
import pytest

from conftest import run_tool

pytestmark = pytest.mark.preprocess


@pytest.fixture(scope="module")
def pp():
    import tetseg.preprocess
    return tetseg.preprocess


@pytest.fixture(scope="module")
def sphere_mesh(bin_dir, tmp_path_factory):
    path = tmp_path_factory.mktemp("sphere") / "sphere.mesh"
    run_tool(bin_dir, "tetseg", "generate", "sphere", "-o", path, "--size", 0.5)
    return path


def cli_build(bin_dir, mesh, folder, *flags):
    asset, report = folder / "cli.tetseg", folder / "cli.json"
    run_tool(bin_dir, "tetseg", "build", mesh, "-o", asset, "--report", report, "-q", *flags)
    return asset.read_bytes(), json.loads(report.read_text())


OPTION_SETS = [
    ({}, []),
    (dict(clusters="charge", alpha=0.2, beta_divisor=200, equalization="rank", growth_bound=0.3,
          grow_through_marked=False, min_cluster_triangles=10, detector="nearest-centroid",
          solver="direct", rest_positions=False),
     ["--clusters", "charge", "--alpha", 0.2, "--beta-divisor", 200, "--equalization", "rank",
      "--growth-bound", 0.3, "--grow-through-marked", "false", "--min-cluster-triangles", 10,
      "--detector", "nearest-centroid", "--solver", "direct", "--no-rest-positions"]),
    (dict(clusters="refined", refine_visibility=0.9, refine_max_clusters=4, refine_gain=0.5,
          refine_merge=False, solver="gmres", tolerance=1e-7, equalization="log-histogram"),
     ["--clusters", "refined", "--refine-visibility", 0.9, "--refine-max-clusters", 4,
      "--refine-gain", 0.5, "--refine-merge", "false", "--solver", "gmres", "--tolerance", 1e-7,
      "--equalization", "log-histogram"]),
    (dict(clusters="single"), ["--clusters", "single"]),
]


@pytest.mark.parametrize("options,flags", OPTION_SETS)
def test_build_equals_cli(pp, bin_dir, sphere_mesh, tmp_path, options, flags):
    expected_bytes, expected_report = cli_build(bin_dir, sphere_mesh, tmp_path, *flags)
    data, report = pp.build(sphere_mesh, **options)
    assert data == expected_bytes
    for key in ("counts", "segmentation", "refinement", "clusters", "options", "asset_bytes"):
        assert report[key] == pytest.approx(expected_report[key]), key
    assert ("charge" in report) == ("charge" in expected_report)
    assert set(report["seconds"]) == set(expected_report["seconds"])
    # Memory per stage, as in the CLI report: the process peak never decreases.
    stage_names = [s[0] for s in report["stages"]]
    for key in ("peak_rss_bytes", "peak_rss_growth_bytes"):
        assert list(report[key]) == stage_names, key
        assert set(expected_report[key]) == set(expected_report["seconds"]) - {"total"}, key
    peaks = [report["peak_rss_bytes"][name] for name in stage_names]
    assert peaks[0] > 0 and peaks == sorted(peaks)
    import tetseg
    asset = tetseg.load_asset(data)
    assert asset.triangle_count == report["counts"]["surface_triangles"]
    assert (asset.rest_positions is None) == (options.get("rest_positions") is False)
    assert len(asset.boundaries) == report["counts"]["boundaries"]
    assert len(asset.clusters) == len(report["clusters"])


def test_build_from_generated_arrays_equals_cli(pp, bin_dir, sphere_mesh, tmp_path):
    expected, _ = cli_build(bin_dir, sphere_mesh, tmp_path)
    nodes, tets = pp.generate("sphere", size=0.5)
    assert nodes.shape[1] == 3 and tets.shape[1] == 4 and tets.dtype == np.uint32
    data, _ = pp.build((nodes, tets), source="sphere.mesh")
    assert data == expected
    data64, _ = pp.build((nodes.tolist(), tets.astype(np.int64)), source="sphere.mesh")
    assert data64 == expected


def test_build_from_closed_surface_equals_cli(pp, bin_dir, sphere_mesh, tmp_path):
    import tetseg
    asset = tetseg.load_asset(pp.build(sphere_mesh, clusters="single")[0])
    used, triangles = np.unique(asset.triangles, return_inverse=True)
    triangles = triangles.reshape(-1, 3)
    points = asset.rest_positions[used]
    off = tmp_path / "sphere.off"
    with open(off, "w") as out:
        out.write(f"OFF\n{len(points)} {len(triangles)} 0\n")
        out.writelines(f"{x!r} {y!r} {z!r}\n" for x, y, z in points.tolist())
        out.writelines(f"3 {a} {b} {c}\n" for a, b, c in triangles.tolist())
    expected, expected_report = cli_build(bin_dir, off, tmp_path, "--cell-size", 0.2,
                                          "--no-optimize")
    data, report = pp.build(off, cell_size=0.2, optimize=False)
    assert data == expected
    assert [s[0] for s in report["stages"]][:2] == ["read", "tetrahedralize"]
    assert report["counts"] == expected_report["counts"]


def test_surface_body_build_equals_cli_and_keeps_the_arrays(pp, bin_dir, sphere_mesh, tmp_path):
    import tetseg
    asset = tetseg.load_asset(pp.build(sphere_mesh, clusters="single")[0])
    used, triangles = np.unique(asset.triangles, return_inverse=True)
    triangles = triangles.reshape(-1, 3)[::-1].copy()  # another triangle order, kept as given
    points = asset.rest_positions[used]
    off = tmp_path / "sphere.off"
    with open(off, "w") as out:
        out.write(f"OFF\n{len(points)} {len(triangles)} 0\n")
        out.writelines(f"{x!r} {y!r} {z!r}\n" for x, y, z in points.tolist())
        out.writelines(f"3 {a} {b} {c}\n" for a, b, c in triangles.tolist())
    expected, expected_report = cli_build(bin_dir, off, tmp_path, "--body", "surface")
    data, report = pp.build(off, body="surface", detectors="weights")
    assert data == expected
    assert report["body"] == expected_report["body"] == "surface"
    assert report["detectors"] == "weights"
    assert report["options"]["body"] == "surface"
    assert "tetrahedralize" not in [s[0] for s in report["stages"]]
    from_arrays, _ = pp.build((points, triangles), body="surface")
    built = tetseg.load_asset(from_arrays)
    assert np.array_equal(built.rest_positions, points)
    assert np.array_equal(built.triangles, triangles)
    with pytest.raises(ValueError, match="needs --body surface"):
        pp.build(off, detectors="weights")
    with pytest.raises(ValueError, match="body: unknown value"):
        pp.build(off, body="shell")


CUBE_OFF = """OFF
8 7 0
0 0 0
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
4 0 3 2 1
4 4 5 6 7
4 0 1 5 4
4 1 2 6 5
4 2 3 7 6
4 3 0 4 7
4 0 3 2 1
"""


def test_repaired_surface_build_reports_like_cli(pp, bin_dir, tmp_path):
    """A cube with a duplicated face: both front doors run the same job and print the same
    report, repairs and Hausdorff distances included (one writer; Python adds 'stages' and
    writes no file, so it has no 'output')."""
    off = tmp_path / "cube_dup.off"
    off.write_text(CUBE_OFF)
    flags = ["--clusters", "single", "--facet-size", 0.25, "--no-optimize"]
    expected_bytes, expected = cli_build(bin_dir, off, tmp_path, *flags)
    data, report = pp.build(off, clusters="single", facet_size=0.25, optimize=False)
    assert data == expected_bytes
    assert set(report) - {"stages"} == set(expected) - {"output"}
    assert report["repairs"] == expected["repairs"] == {"duplicate triangles removed": 2}
    assert report["hausdorff"] == pytest.approx(expected["hausdorff"])
    for key in ("counts", "clusters", "options", "input"):
        assert report[key] == expected[key], key


def test_charge_equals_cli(pp, bin_dir, sphere_mesh, tmp_path):
    csv = tmp_path / "charge.csv"
    run_tool(bin_dir, "tetseg", "charge", sphere_mesh, "-o", csv, "--solver", "direct",
             "--equalize", "rank")
    expected = np.loadtxt(csv, delimiter=",", skiprows=1)
    result = pp.charge(sphere_mesh, solver="direct", equalize="rank")
    assert result["solver"] == "direct" and result["equalization"] == "rank"
    assert result["triangles"].shape == (len(expected), 3)
    assert np.allclose(result["density"], expected[:, 5], rtol=1e-8, atol=0)
    assert np.allclose(result["equalized"], expected[:, 6], rtol=1e-8, atol=0)
    # A sphere's relative density is 1 everywhere, up to the discretisation.
    assert abs(result["density"].mean() - 1.0) < 0.05
    nodes, tets = pp.generate("sphere", size=0.5)
    again = pp.charge((nodes, tets), solver="direct", equalize="rank")
    assert np.array_equal(again["density"], result["density"])


def test_charge_relaxed_products_like_cli(pp, bin_dir, sphere_mesh, tmp_path):
    # The fast solver relaxes its last products by default; relaxed_products=False is
    # `tetseg charge --exact-products`, and both stay within the tolerance of each other.
    relaxed = pp.charge(sphere_mesh, solver="fast")
    exact = pp.charge(sphere_mesh, solver="fast", relaxed_products=False)
    assert 0 < relaxed["relaxed_products"] < relaxed["iterations"]
    assert exact["relaxed_products"] == 0
    assert relaxed["converged"] and exact["converged"]
    assert np.allclose(relaxed["density"], exact["density"], rtol=0, atol=1e-3)
    csv = tmp_path / "exact.csv"
    run_tool(bin_dir, "tetseg", "charge", sphere_mesh, "-o", csv, "--solver", "fast",
             "--exact-products")
    cli = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert np.allclose(exact["density"], cli[:, 5], rtol=1e-8, atol=0)


def test_charge_reports_memory_like_cli(pp, bin_dir, sphere_mesh, tmp_path):
    report_path = tmp_path / "charge.json"
    run_tool(bin_dir, "tetseg", "charge", sphere_mesh, "-o", tmp_path / "charge.csv",
             "--report", report_path)
    with open(report_path) as f:
        cli = json.load(f)
    result = pp.charge(sphere_mesh)
    for key in ("peak_rss_bytes", "peak_rss_growth_bytes"):
        # The CLI's steps but its last, `write` (the module writes no file).
        assert list(result[key]) == ["read", "charge"], key
        assert list(cli[key])[:2] == ["read", "charge"], key
    peaks = result["peak_rss_bytes"]
    growths = result["peak_rss_growth_bytes"]
    # The process peak is positive and never decreases; a stage raises it by at most itself.
    assert 0 < peaks["read"] <= peaks["charge"]
    for name in ("read", "charge"):
        assert 0 <= growths[name] <= peaks[name], name
        assert isinstance(peaks[name], int) and isinstance(growths[name], int), name
    assert growths["charge"] <= peaks["charge"] - peaks["read"]


def test_on_stage_reports_every_stage(pp, sphere_mesh):
    seen = []
    _, report = pp.build(sphere_mesh, on_stage=lambda *stage: seen.append(stage))
    assert [s[0] for s in seen] == [s[0] for s in report["stages"]]
    assert {"read", "surface", "detectors", "bvh", "write"} <= {s[0] for s in seen}

    def fail(*_):
        raise ZeroDivisionError("from the callback")

    with pytest.raises(ZeroDivisionError, match="from the callback"):
        pp.build(sphere_mesh, on_stage=fail)
    assert pp.build(sphere_mesh)[0]  # still usable


def test_bad_options_raise_value_errors(pp, sphere_mesh):
    cases = [
        (dict(alpha=7), r"alpha must be in \[0, 1\], got 7$"),
        (dict(alpha=float("nan")), "alpha must be in"),
        (dict(beta_divisor=0), "beta_divisor must be positive"),
        (dict(refine_max_clusters=0), "refine_max_clusters must be in"),
        (dict(tolerance=0.7), "tolerance must be in"),
        (dict(cell_size=-1), "cell_size must be in"),
        (dict(clusters="many"), r"clusters: unknown value 'many' \(single, charge, refined\)"),
        (dict(detector="x"), "detector: unknown value 'x' .nearest-centroid, visibility."),
        (dict(equalization="logarithmic"), "equalization: unknown value 'logarithmic'"),
        (dict(solver="lu"), "solver: unknown value 'lu'"),
    ]
    for options, message in cases:
        with pytest.raises(ValueError, match=message):
            pp.build(sphere_mesh, **options)
    with pytest.raises(TypeError):
        pp.build(sphere_mesh, no_such_option=1)
    for options, message in [(dict(theta=1.5), "theta must be in"),
                             (dict(bins=0), "bins must be in"),
                             (dict(equalize="logarithmic"), "equalize: unknown value")]:
        with pytest.raises(ValueError, match=message):
            pp.charge(sphere_mesh, **options)


def test_bad_meshes_raise_clear_errors(pp, sphere_mesh, tmp_path):
    nodes, tets = pp.generate("sphere", size=0.5)
    with pytest.raises(pp.InputError, match="missing.mesh: ") as error:
        pp.build(tmp_path / "missing.mesh")
    assert error.value.file.endswith("missing.mesh") and isinstance(error.value, ValueError)
    assert pp.InputError.__module__ == "tetseg.preprocess"
    broken = tmp_path / "broken.mesh"
    broken.write_text("MeshVersionFormatted 2\nDimension 3\nVertices\n2\n0 0\n")
    with pytest.raises(pp.InputError, match="broken.mesh: line"):
        pp.build(broken)
    bad = tets.copy()
    bad[0, 0] = len(nodes)
    with pytest.raises(pp.InputError, match="arrays: "):
        pp.build((nodes, bad))
    nan = nodes.copy()
    nan[3, 1] = np.nan
    with pytest.raises(pp.InputError, match="mine.mesh: "):
        pp.build((nan, tets), source="mine.mesh")
    inverted = tets.copy()
    inverted[:, [0, 1]] = inverted[:, [1, 0]]
    inverted[5:] = tets[5:]
    with pytest.raises(pp.InputError, match="inverted"):
        pp.build((nodes, inverted))
    open_surface = (nodes, np.array([[0, 1, 2], [0, 2, 3]]))
    with pytest.raises(pp.InputError, match="not closed"):
        pp.build(open_surface, repair="none")
    with pytest.raises(ValueError, match="wrap_alpha must be in"):
        pp.build(open_surface, repair="wrap", wrap_alpha=0)
    with pytest.raises(ValueError, match="wrap_sheet_offset must be in"):
        pp.build(open_surface, repair="wrap", wrap_sheet_offset=2)
    with pytest.raises(ValueError, match="outside"):
        pp.build((nodes, tets.astype(np.int64) - 1))
    with pytest.raises(TypeError, match="integer array"):
        pp.build((nodes, tets.astype(np.float64)))
    with pytest.raises(ValueError, match=r"\(M, 4\) .tets. or \(M, 3\)"):
        pp.build((nodes, tets[:, :2]))
    with pytest.raises(ValueError, match=r"nodes must be an \(N, 3\) array"):
        pp.build((nodes[:, :2], tets))
    with pytest.raises(TypeError, match="file path or a pair of arrays"):
        pp.build(42)
    with pytest.raises(ValueError, match="unknown"):
        pp.generate("cube")


def test_preprocess_module_carries_the_gpl_code(pp):
    # Positive control for test_runtime_package_does_not_load_preprocess.
    assert b"CGAL" in open(pp.__file__, "rb").read()
    assert "GPL" in pp.__doc__


def test_wrap_repair_is_recorded_in_the_provenance(pp):
    """repair="wrap" meshes the alpha wrap of the input; the wrap options reach the
    provenance, as with `tetseg build --repair wrap` (an open box is refused without repair)."""
    import tetseg
    corners = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
    quads = [(0, 2, 3, 1), (0, 1, 5, 4), (1, 3, 7, 5), (3, 2, 6, 7), (2, 0, 4, 6), (4, 5, 7, 6)]
    triangles = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    with pytest.raises(pp.InputError, match="not closed"):
        pp.build((corners, triangles[:-2]), repair="none")  # no top
    data, report = pp.build((corners, triangles), repair="wrap", wrap_alpha=0.1, cell_size=0.2)
    provenance = tetseg.load_asset(data).provenance["options"]
    assert provenance["meshing.repair"] == "wrap"
    assert float(provenance["meshing.wrap_alpha"]) == 0.1
    assert report["counts"]["surface_triangles"] > 12  # the wrap, not the 12 input triangles


def test_wrap_meshes_a_flat_sheet_as_a_slab(pp):
    """A square of two triangles encloses no volume: repair="wrap" meshes it as a slab
    2 x wrap_sheet_offset thick and records that repair in the provenance."""
    import tetseg
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    triangles = np.array([[0, 1, 2], [0, 2, 3]])
    data, _ = pp.build((square, triangles), repair="wrap", wrap_sheet_offset=0.02,
                       clusters="single")
    kind = "surface wrapped as a slab this many ten thousandths of the diagonal thick"
    provenance = tetseg.load_asset(data).provenance["options"]
    assert float(provenance["meshing.wrap_sheet_offset"]) == 0.02
    assert provenance["repairs." + kind.replace(" ", "_")] == "400"


def test_deviation_is_reported_for_every_build(pp, sphere_mesh):
    """The deviation (two-sided Hausdorff distance, relative and absolute) is in every build's
    report and provenance: 0 for a tet mesh, measured (not 0: Mesh_3 rounds the corners a
    little) for a closed box that needs no repair. At max_deviation 0.05: under the default
    0.01 the rounding is over it, and the deviation retry protects the box's edges (exact,
    0; tests/preprocess/deviation_retry_test.cpp)."""
    import tetseg
    data, report = pp.build(sphere_mesh, clusters="single")
    assert report["hausdorff"]["input_to_mesh"] == 0 == report["hausdorff"]["mesh_to_input"]
    assert tetseg.load_asset(data).provenance["options"]["deviation.input_to_asset"] == "0"
    corners = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
    quads = [(0, 2, 3, 1), (0, 1, 5, 4), (1, 3, 7, 5), (3, 2, 6, 7), (2, 0, 4, 6), (4, 5, 7, 6)]
    triangles = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    data, report = pp.build(
        (corners, triangles), clusters="single", cell_size=0.2, max_deviation=0.05
    )
    assert report["repairs"] == {}
    assert report["deviation_retries"] == 0
    h = report["hausdorff"]
    assert 0 < h["input_to_mesh"] < 0.05 and 0 <= h["mesh_to_input"] < 0.05
    assert h["input_to_mesh_absolute"] == pytest.approx(h["input_to_mesh"] * 3 ** 0.5)
    provenance = tetseg.load_asset(data).provenance["options"]
    assert float(provenance["deviation.input_to_asset"]) == pytest.approx(h["input_to_mesh"])


def test_time_limit_refuses_with_the_stage_named(pp, sphere_mesh):
    """time_limit as `tetseg build --time-limit`: past it InputError names the stage; it is
    range-checked (ValueError)."""
    with pytest.raises(pp.InputError, match="time limit of 1e-09 s reached in stage read"):
        pp.build(sphere_mesh, time_limit=1e-9)
    with pytest.raises(ValueError, match="time_limit"):
        pp.build(sphere_mesh, time_limit=-1)
