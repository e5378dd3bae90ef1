"""The Python module renders what the CLI renders, bit for bit, from files and from
arrays, and hands over what a render found."""

import numpy as np
import pytest

import misalloc
from conftest import SIZE, rgb

# Given costs, where a test compares renders of caches of their own: a calibration
# times its own launches, and two calibrations allocate differently.
COSTS = "1e-9,2e-9"
SIZE_WORD = f"{SIZE[0]}x{SIZE[1]}"


@pytest.fixture(scope="module")
def spheres_gbuffer(cli, tmp_path_factory):
    path = tmp_path_factory.mktemp("gbuffer") / "spheres.exr"
    cli("gbuffer", "--scene", "spheres:2x2", "--size", SIZE_WORD, "--out", path)
    return path


def cli_image(cli, tmp_path, *args):
    out = tmp_path / "cli.exr"
    cli("render", *args, "--out", out, "--report", tmp_path / "cli.json", "--no-preview", "--reference", "none")
    return rgb(misalloc.read_exr(out))


@pytest.mark.parametrize("method", ["equal", "exact"])
def test_render_is_the_cli_render_bit_for_bit(cli, tmp_path, cache_dir, method):
    options = dict(method=method, spp=24, seed=7, cost=COSTS)
    scene = misalloc.Scene(envmap="venice_sunset", size=SIZE, cache_dir=cache_dir)
    ours = scene.render(reference="none", **options)
    theirs = cli_image(cli, tmp_path, "--envmap", "venice_sunset", "--size", SIZE_WORD, "--cache-dir", cache_dir,
                       "--method", method, "--spp", 24, "--seed", 7, "--cost", COSTS)
    assert ours.image.dtype == np.float32 and ours.image.shape == (SIZE[1], SIZE[0], 3)
    assert np.array_equal(ours.image, theirs)
    assert ours.report["method"] == method and ours.report["spp"] == 24
    assert ours.alpha.shape == (SIZE[1], SIZE[0], 2)
    assert np.allclose(ours.alpha.sum(axis=2), 1)
    if method == "equal":
        assert np.all(ours.alpha == 0.5)
    else:
        assert ours.alpha.std() > 0.01  # the allocation differs from pixel to pixel


def test_default_costs_are_calibrated_once_and_every_render_repeats(cli, tmp_path):
    cache = tmp_path / "cache"
    options = dict(method="exact", spp=24, seed=7, reference="none")
    scene = misalloc.Scene(envmap="venice_sunset", size=SIZE, cache_dir=cache)
    first = scene.render(**options)
    again = scene.render(**options)
    assert first.report["allocation"]["costs_source"] == "calibrated"
    assert again.report["allocation"]["costs_source"] == "cache"
    assert np.array_equal(first.image, again.image)
    # The CLI reads the same cache entry: the same device, kernels and scene.
    theirs = cli_image(cli, tmp_path, "--envmap", "venice_sunset", "--size", SIZE_WORD, "--cache-dir", cache,
                       "--method", "exact", "--spp", 24, "--seed", 7)
    assert np.array_equal(first.image, theirs)


def test_gbuffer_as_a_file_and_as_arrays_is_the_cli_render(cli, tmp_path, cache_dir, spheres_gbuffer):
    options = dict(method="exact", spp=16, seed=3, cost=COSTS, reference="none")
    theirs = cli_image(cli, tmp_path, "--gbuffer", spheres_gbuffer, "--cache-dir", cache_dir, "--method", "exact",
                       "--spp", 16, "--seed", 3, "--cost", COSTS)
    from_file = misalloc.Scene(gbuffer=spheres_gbuffer, cache_dir=cache_dir).render(**options)
    assert np.array_equal(from_file.image, theirs)
    channels = misalloc.read_exr(spheres_gbuffer)
    as_planes = misalloc.Scene(gbuffer=channels, cache_dir=cache_dir).render(**options)
    assert np.array_equal(as_planes.image, theirs)
    # (H, W, 3) arrays under a prefix give its .X, .Y, .Z channels.
    stacked = {k: v for k, v in channels.items() if "." not in k}
    for prefix in ("N", "view"):
        stacked[prefix] = np.dstack([channels[f"{prefix}.{a}"] for a in "XYZ"])
    as_vectors = misalloc.Scene(gbuffer=stacked, cache_dir=cache_dir).render(**options)
    assert np.array_equal(as_vectors.image, theirs)
    assert as_vectors.coverage is not None and set(np.unique(as_vectors.coverage)) == {0.0, 1.0}
    assert np.all(as_vectors.image[as_vectors.coverage == 0] == 0)


def test_envmap_as_an_array_is_the_shipped_map(cache_dir):
    texels = rgb(misalloc.read_exr(misalloc_envmap("rooitou_park")))
    options = dict(method="equal", spp=16, seed=5, reference="none")
    by_name = misalloc.Scene(envmap="rooitou_park", size=SIZE, cache_dir=cache_dir).render(**options)
    by_array = misalloc.Scene(envmap=texels, size=SIZE, cache_dir=cache_dir).render(**options)
    assert np.array_equal(by_name.image, by_array.image)
    assert by_array.report["scene"]["envmap"].startswith("envmap (array)")


def misalloc_envmap(name):
    import os
    return os.path.join(os.path.dirname(__file__), "..", "..", "data", "envmaps", name + ".exr")


def test_one_scene_serves_every_pdf_and_method(cache_dir):
    scene = misalloc.Scene(envmap="cosk:4", size=(16, 16), cache_dir=cache_dir)
    plain = scene.render(method="equal", envmap_pdf="plain", spp=64)
    optimal = scene.render(method="equal", spp=64)
    envmap_only = scene.render(method="envmap", spp=64)
    assert plain.report["scene"]["envmap_pdf"]["used"] == "plain"
    assert optimal.report["scene"]["envmap_pdf"]["used"] == "optimal"
    assert envmap_only.report["scene"]["envmap_pdf"]["used"] == "plain"  # the CLI's default for envmap alone
    assert not np.array_equal(plain.image, optimal.image)
    # cos^K lighting has [HS14] eq. 6.17's analytic reference: every render is judged.
    assert optimal.error["rmse_x1000_corrected"] < plain.error["rmse_x1000_corrected"] * 2


def test_reference_given_as_an_array_judges_as_the_analytic_one(cache_dir):
    scene = misalloc.Scene(envmap="cosk:2", size=(16, 16), cache_dir=cache_dir)
    ref = misalloc.reference(scene)
    assert ref.source.startswith("analytic") and ref.standard_error is None
    auto = scene.render(method="equal", spp=32)
    given = scene.render(method="equal", spp=32, reference=ref.image)
    assert np.array_equal(auto.image, given.image)
    assert given.error["rmse_x1000"] == pytest.approx(auto.error["rmse_x1000"], rel=1e-12)
    assert scene.render(method="equal", spp=32, reference="none").error is None


def test_sampled_reference_is_cached(cache_dir):
    scene = misalloc.Scene(envmap="forest_slope", size=(16, 16), cache_dir=cache_dir)
    first = misalloc.reference(scene, spp=64)
    again = misalloc.reference(scene, spp=64)
    assert first.standard_error.shape == (16, 16, 3) and first.path
    assert np.array_equal(first.image, again.image) and "cache" in again.source


def test_compare_returns_what_it_wrote(tmp_path, cache_dir):
    out = tmp_path / "compare"
    result = misalloc.compare(out, envmap="cosk:2", size=(16, 16), methods="equal,exact", budgets="8,16",
                              envmap_pdfs="plain", cache_dir=cache_dir, cost=COSTS)
    assert (out / "index.html").exists() and result["out_dir"] == str(out)
    assert {r["method"] for r in result["runs"]["runs"]} == {"equal", "exact"}
    assert result["summary"]["budgets"] == [8, 16]
