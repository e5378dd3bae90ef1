"""Arrays in every supported dtype and layout are read as their values; anything else,
and every bad option, raises ValueError or TypeError naming it, never a crash."""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import misalloc

# A small map whose texels every dtype holds exactly.
TEXELS = np.random.default_rng(1).integers(0, 8, size=(16, 32, 3)).astype(np.float32)
OPTIONS = dict(method="equal", spp=8, seed=2, reference="none")


@pytest.fixture(scope="module")
def expected(cache_dir):
    return misalloc.Scene(envmap=TEXELS, size=(8, 8), cache_dir=cache_dir).render(**OPTIONS).image


@pytest.mark.parametrize("convert", [
    lambda t: t.astype(np.float64),
    lambda t: t.astype(np.float16),
    lambda t: t.astype(np.int32),
    lambda t: t.astype(np.uint8),
    lambda t: t.astype(">f4"),  # big-endian
    lambda t: np.asfortranarray(t),
    lambda t: np.repeat(t, 2, axis=1)[:, ::2],  # strided
    lambda t: t.tolist(),
], ids=["float64", "float16", "int32", "uint8", "big-endian", "fortran", "strided", "list"])
def test_envmap_dtypes_and_layouts_read_as_their_values(cache_dir, expected, convert):
    image = misalloc.Scene(envmap=convert(TEXELS), size=(8, 8), cache_dir=cache_dir).render(**OPTIONS).image
    assert np.array_equal(image, expected)


@pytest.mark.parametrize("envmap, message", [
    (TEXELS.astype(np.complex64), "envmap: dtype complex64 is not a real number type"),
    (TEXELS.astype(bool), "envmap: dtype bool is not a real number type"),
    (TEXELS[:, :, :2], r"envmap: expected an array of shape \(H, W, 3\), got shape \(16, 32, 2\)"),
    (TEXELS[0], r"envmap: expected an array of shape \(H, W, 3\)"),
    (np.full((16, 32, 3), 1e300), "envmap: values beyond float32's range"),
    (np.where(np.arange(3) == 1, np.nan, TEXELS), r"'envmap \(array\)' has 512 NaN or infinite channel values"),
], ids=["complex", "bool", "two-channels", "2d", "overflow", "nan"])
def test_bad_envmaps_raise_value_error_naming_the_argument(envmap, message):
    with pytest.raises(ValueError, match=message):
        misalloc.Scene(envmap=envmap)


def gbuffer(normal, size=(6, 5)):
    h, w = size[1], size[0]
    return {"N": np.broadcast_to(np.asarray(normal, np.float32), (h, w, 3)),
            "view": np.broadcast_to(np.float32([0, 0, 1]), (h, w, 3))}


def test_gbuffer_arrays_refused_with_the_readers_messages():
    with pytest.raises(ValueError, match=r"gbuffer \(arrays\).*N\.X"):
        misalloc.Scene(gbuffer={"normal": np.zeros((5, 6, 3))})
    with pytest.raises(ValueError, match=r"gbuffer \(arrays\).*NaN"):
        misalloc.Scene(gbuffer=gbuffer([np.nan, 0, 1]))
    with pytest.raises(ValueError, match=r"gbuffer\['view'\]: shape \(5, 7\) differs"):
        misalloc.Scene(gbuffer={"N": np.zeros((5, 6, 3)), "view": np.zeros((5, 7, 3))})
    with pytest.raises(ValueError, match="gbuffer: expected a path or a non-empty dict"):
        misalloc.Scene(gbuffer={})
    assert misalloc.Scene(gbuffer=gbuffer([0, 0, 1])).render(spp=4, method="equal", reference="none").image.shape == (5, 6, 3)


def test_options_take_the_cli_checks_and_messages():
    scene = misalloc.Scene(envmap="constant", size=(4, 4))
    with pytest.raises(ValueError, match="--spp"):
        scene.render(spp=0)
    with pytest.raises(ValueError, match="--method 'nope'|nope"):
        scene.render(method="nope")
    with pytest.raises(ValueError, match="--size 4x0"):
        misalloc.Scene(size="4x0")
    with pytest.raises(ValueError, match="--envmap"):
        misalloc.Scene(envmap="no/such/map.exr")
    with pytest.raises(ValueError, match="--gbuffer with --scene"):
        misalloc.Scene(gbuffer={"N": np.ones((2, 2, 3))}, scene="spheres")
    with pytest.raises(TypeError, match="unexpected keyword argument 'spp'"):
        misalloc.Scene(spp=10)  # a render's option, not the scene's
    with pytest.raises(TypeError, match="unexpected keyword argument 'nope'"):
        scene.render(nope=1)
    with pytest.raises(TypeError, match="split_brdf=1: expected True or False"):
        misalloc.Scene(split_brdf=1)


def test_device_failures_raise_device_error(tmp_path):
    """No OpenCL platform (an empty vendor folder): DeviceError, a RuntimeError, with the
    CLI's advice; a device that does not exist is bad input: ValueError."""
    env = dict(os.environ, OCL_ICD_VENDORS=str(tmp_path), OPENCL_VENDOR_PATH=str(tmp_path))
    code = """
        import misalloc
        scene = misalloc.Scene(envmap="constant", size=(4, 4))
        try:
            scene.render(method="equal", spp=4, reference="none")
        except misalloc.DeviceError as e:
            print("DeviceError", isinstance(e, RuntimeError), e)
    """
    result = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, env=env,
                            timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("DeviceError True") and "OpenCL" in result.stdout, result.stdout
    with pytest.raises(ValueError, match="--device '99'"):
        misalloc.Scene(envmap="constant", size=(4, 4)).render(device="99", method="equal", spp=4)


def test_help_and_stubs_show_every_parameter():
    import inspect
    import os
    stub = open(os.path.join(os.path.dirname(misalloc.__file__), "__init__.pyi")).read()
    for key in misalloc._SCENE_OPTIONS:
        assert f"    {key}:" in misalloc.Scene.__doc__ and f", {key}:" in stub
    for key in misalloc._RENDER_ONLY:
        assert f"    {key}:" in misalloc.Scene.render.__doc__ and f", {key}:" in stub
    assert "spp: Optional[Union[int, str]] = None" in stub
    assert "(default 200)" in misalloc.Scene.render.__doc__
    assert inspect.getdoc(misalloc.reference)
