"""misalloc from Python: per-pixel allocation of MIS samples for envmap x BRDF direct
lighting, with numpy arrays in and out.

    import misalloc
    scene = misalloc.Scene(scene="spheres", size=(256, 256))   # tables built once
    best = scene.render(spp=200)                                # exact, the default pdf
    equal = scene.render(method="equal", envmap_pdf="plain", spp=200)
    best.image, best.alpha, best.report, best.error

Every keyword argument is an option of `misalloc render` (or `misalloc compare`) with
its dashes written as underscores, parsed by the command line's own code: the same
defaults, the same checks, the same messages. Leaving an argument out, or passing None,
asks for the command line's default. Lists and tuples are written comma-separated
(camera_origin=(0, 1, 5)), size=(w, h) as WxH, True flags as the flag.

Bad input raises ValueError with the command line's message, OpenCL failures
misalloc.DeviceError (a RuntimeError), and Ctrl-C raises KeyboardInterrupt between
kernel launches, leaving the interpreter usable.
"""

import json
import os

import numpy as np

from . import _misalloc
from ._misalloc import DeviceError

__all__ = ["Scene", "Rendering", "Reference", "reference", "compare", "read_exr", "DeviceError"]


def _keyword(option):
    return option["name"][2:].replace("-", "_")


def _option_table(command):
    return {_keyword(o): o for o in _misalloc.options(command)}


_RENDER_OPTIONS = _option_table("render")
_SCENE_OPTIONS = {k: o for k, o in _RENDER_OPTIONS.items() if o["group"] == "Scene"}
# Given as arrays or objects rather than words, where render and Scene take them.
_SCENE_OPTIONS.pop("envmap")
_SCENE_OPTIONS.pop("gbuffer")
_RENDER_ONLY = {k: o for k, o in _RENDER_OPTIONS.items() if o["group"] == "Render"}
_RENDER_ONLY.pop("reference")
_COMPARE_OPTIONS = _option_table("compare")
_COMPARE_OPTIONS.pop("out_dir")


def _number(value):
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, bool):
        raise TypeError("expected a number, not a bool")
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)
    raise TypeError(f"expected a number, not {type(value).__name__}")


def _text(key, value):
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, str):
        return value
    try:
        if key == "size" and isinstance(value, (tuple, list)):
            width, height = value
            return f"{_number(width)}x{_number(height)}"
        if isinstance(value, (tuple, list, np.ndarray)):
            return ",".join(_number(v) for v in np.asarray(value).ravel().tolist())
        return _number(value)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{key}={value!r}: {e}") from None


def _words(options, allowed, caller):
    """The command line's words for keyword arguments; TypeError for an unknown one."""
    words = []
    for key, value in options.items():
        option = allowed.get(key)
        if option is None:
            raise TypeError(f"{caller}() got an unexpected keyword argument '{key}'")
        if value is None:
            continue
        if option["flag"]:
            if not isinstance(value, (bool, np.bool_)):
                raise TypeError(f"{key}={value!r}: expected True or False")
            if value:
                words.append(option["name"])
            continue
        words += [option["name"], _text(key, value)]
    return words


def _float32(name, value, trailing):
    """`value` as a C-contiguous float32 array of shape (H, W) + trailing: copied only
    where its dtype or layout differs; ValueError naming `name` for anything else."""
    array = np.asarray(value)
    if array.dtype.kind not in "fiu":
        raise ValueError(f"{name}: dtype {array.dtype} is not a real number type (float, int or unsigned int)")
    if array.ndim != 2 + len(trailing) or array.shape[2:] != trailing or array.shape[0] < 1 or array.shape[1] < 1:
        expected = ", ".join(["H", "W"] + [str(t) for t in trailing])
        raise ValueError(f"{name}: expected an array of shape ({expected}), got shape {array.shape}")
    if array.dtype.kind == "f" and array.dtype.itemsize > 4:
        finite = array[np.isfinite(array)]
        if finite.size and np.abs(finite).max() > np.finfo(np.float32).max:
            raise ValueError(f"{name}: values beyond float32's range ({np.abs(finite).max():g})")
    return np.ascontiguousarray(array, dtype=np.float32)


def _gbuffer_channels(gbuffer):
    """A dict of arrays as channels: (H, W, 3) under NAME gives NAME.X, .Y, .Z; (H, W)
    gives NAME; (4, 4) under a matrix's name (pbrt's worldToCamera) is that matrix."""
    if not isinstance(gbuffer, dict) or not gbuffer:
        raise ValueError("gbuffer: expected a path or a non-empty dict of arrays")
    planes, matrices, size = {}, {}, None
    for key, value in gbuffer.items():
        name = f"gbuffer[{key!r}]"
        if not isinstance(key, str):
            raise ValueError(f"{name}: channel names are strings")
        shape = np.shape(value)
        if shape == (4, 4) and key == "worldToCamera":
            matrices[key] = _float32(name, value, ())
            continue
        if len(shape) == 3:
            array = _float32(name, value, (3,))
            for axis, suffix in enumerate("XYZ"):
                planes[f"{key}.{suffix}"] = np.ascontiguousarray(array[:, :, axis])
        else:
            planes[key] = _float32(name, value, ())
        if size is None:
            size = shape[:2]
        elif shape[:2] != size:
            raise ValueError(f"{name}: shape {shape[:2]} differs from the other channels' {size}")
    return planes, matrices


class Rendering:
    """A render: `image` (float32 [h, w, 3], linear RGB), `alpha` (float64 [h, w, M],
    each technique's share of the pixel's samples), `coverage` (float32 [h, w], 1 where a
    surface is seen, 0 for background; None without background), `report` (the dict of
    the CLI's JSON report), and `error` (the RMSE x1000, corrected for the reference's own
    error, and the relative MSE, against the reference; None without one)."""

    def __init__(self, native):
        self.image = native["image"]
        self.alpha = native["alpha"]
        self.coverage = native["coverage"]
        self.report = json.loads(native["report"])

    @property
    def error(self):
        keys = ("rmse_x1000", "rmse_x1000_corrected", "relative_mse")
        if "rmse_x1000" not in self.report:
            return None
        return {k: self.report[k] for k in keys}

    @property
    def techniques(self):
        """The names of the techniques along alpha's last axis."""
        return self.report["scene"]["techniques"]

    def __repr__(self):
        shape = "x".join(str(n) for n in self.image.shape[1::-1])
        return f"<misalloc.Rendering {self.report['method']} {shape} {self.report['spp']} spp>"


class Reference:
    """A converged image: `image` (float32 [h, w, 3]), `standard_error` (its own error
    per pixel and channel; None for an analytic one), `source` (how it was found) and
    `path` (its cache file, if any)."""

    def __init__(self, native):
        self.image = native["image"]
        self.standard_error = native["standard_error"]
        self.source = native["source"]
        self.path = native["path"]

    def __repr__(self):
        return f"<misalloc.Reference {self.source}>"


class Scene:
    def __init__(self, envmap=None, gbuffer=None, **options):
        words = _words(options, _SCENE_OPTIONS, "Scene")
        texels, envmap_name = None, ""
        if isinstance(envmap, (str, os.PathLike)):
            words += ["--envmap", os.fspath(envmap)]
        elif envmap is not None:
            texels, envmap_name = _float32("envmap", envmap, (3,)), "envmap (array)"
        planes, matrices, gbuffer_name = None, {}, ""
        if isinstance(gbuffer, (str, os.PathLike)):
            words += ["--gbuffer", os.fspath(gbuffer)]
        elif gbuffer is not None:
            (planes, matrices), gbuffer_name = _gbuffer_channels(gbuffer), "gbuffer (arrays)"
        self._native = _misalloc.Scene(words, texels, envmap_name, planes, matrices, gbuffer_name)

    def render(self, reference=None, **options):
        words = _words(options, _RENDER_ONLY, "render")
        array = None
        if isinstance(reference, Reference):
            reference = reference.image
        if isinstance(reference, (str, os.PathLike)):
            words += ["--reference", os.fspath(reference)]
        elif reference is not None:
            array = _float32("reference", reference, (3,))
            words += ["--reference", "none"]
        return Rendering(self._native.render(words, array))


def reference(scene, spp=None, device=None, local_size=None):
    """The scene's converged reference: analytic where there is one, else cached, else
    computed (equal counts with the best unbiased estimator) and cached in the scene's
    cache_dir. spp is render's reference_spp."""
    words = _words({"reference_spp": spp, "device": device, "local_size": local_size}, _RENDER_ONLY, "reference")
    return Reference(scene._native.reference(words))


def compare(out_dir, **options):
    """`misalloc compare --out-dir OUT_DIR ...`: runs the comparison and writes its folder
    as the CLI does, and returns what it wrote: {"summary": summary.json, "runs":
    runs.json, "out_dir": the folder}. Raises KeyboardInterrupt after Ctrl-C, the folder
    holding the runs that finished."""
    words = ["--out-dir", os.fspath(out_dir)] + _words(options, _COMPARE_OPTIONS, "compare")
    code = _misalloc.compare(words)
    if code == 130:
        raise KeyboardInterrupt(f"misalloc.compare interrupted; {os.fspath(out_dir)} holds the runs that finished")
    with open(os.path.join(out_dir, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(out_dir, "runs.json")) as f:
        runs = json.load(f)
    return {"summary": summary, "runs": runs, "out_dir": os.fspath(out_dir)}


def read_exr(path):
    """Every channel of an OpenEXR file as {name: float32 [h, w]}, read as misalloc reads
    its inputs: a renderer's G-buffer ("sh_normal.X", ...), ready for Scene(gbuffer=...),
    or an image (np.dstack([c["R"], c["G"], c["B"]]) for an envmap or a reference)."""
    return _misalloc.read_exr(os.fspath(path))


def _option_doc(table):
    lines = []
    for key, o in table.items():
        default = " (a flag)" if o["flag"] else (f" (default {o['default']})" if o["default"] else "")
        lines.append(f"    {key}: {o['help']}{default}")
    return "\n".join(lines)


Scene.__doc__ = f"""A scene built once and rendered many times: the map's tables, the BRDFs, each
pixel's geometry, and the tables of every envmap pdf a render asks for.

    envmap: a path, a shipped map's name, a procedural spec (constant, cosk:K, sun...),
        or an array [H, W, 3] of linear RGB texels (lat-long, row 0 the zenith)
    gbuffer: an EXR path, or a dict of arrays: (H, W, 3) under NAME gives the channels
        NAME.X/Y/Z (e.g. "sh_normal", "position" for convention="mitsuba"), (H, W) the
        channel NAME ("A", "rho_d", ...), (4, 4) under "worldToCamera" pbrt's matrix
{_option_doc(_SCENE_OPTIONS)}
"""
Scene.render.__doc__ = f"""Renders the scene and returns a Rendering.

    reference: None (the default, auto), "auto", "none", an EXR path, an array [h, w, 3]
        or a Reference, against which the error is reported
{_option_doc(_RENDER_ONLY)}
"""
compare.__doc__ += "\n\n" + _option_doc(_COMPARE_OPTIONS) + "\n"
