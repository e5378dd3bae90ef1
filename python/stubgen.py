"""Writes the type stubs of the package misalloc (argv[1]: the .pyi file) from the
options of the module just built, so that an editor shows every parameter of Scene,
Scene.render, reference and compare, with the command line's defaults."""

import sys

# The built package (PYTHONPATH), not the sources beside this script.
sys.path.remove(sys.path[0])
import misalloc  # noqa: E402

HEADER = '''# Written by python/stubgen.py from the options of misalloc's command line.
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

_Value = Union[str, float, Sequence[float], "os.PathLike[str]"]

class DeviceError(RuntimeError): ...

class Rendering:
    image: np.ndarray
    alpha: np.ndarray
    coverage: Optional[np.ndarray]
    report: Dict[str, Any]
    @property
    def error(self) -> Optional[Dict[str, float]]: ...
    @property
    def techniques(self) -> List[str]: ...

class Reference:
    image: np.ndarray
    standard_error: Optional[np.ndarray]
    source: str
    path: str
'''


def annotation(option):
    if option["flag"]:
        return "Optional[bool]"
    default = option["default"]
    for kind in (int, float):
        try:
            kind(default)
            return f"Optional[Union[{kind.__name__}, str]]"
        except ValueError:
            pass
    return "Optional[_Value]"


def parameters(table):
    return "".join(f", {key}: {annotation(o)} = None" for key, o in table.items())


def main():
    lines = [HEADER]
    lines.append("class Scene:")
    lines.append(
        "    def __init__(self, envmap: Optional[Union[str, 'os.PathLike[str]', np.ndarray]] = None, "
        "gbuffer: Optional[Union[str, 'os.PathLike[str]', Dict[str, np.ndarray]]] = None, *"
        + parameters(misalloc._SCENE_OPTIONS) + ") -> None: ...")
    lines.append(
        "    def render(self, reference: Optional[Union[str, 'os.PathLike[str]', np.ndarray, Reference]] = None, *"
        + parameters(misalloc._RENDER_ONLY) + ") -> Rendering: ...")
    lines.append("")
    lines.append("def reference(scene: Scene, spp: Optional[int] = None, device: Optional[str] = None, "
                 "local_size: Optional[int] = None) -> Reference: ...")
    lines.append("def compare(out_dir: Union[str, 'os.PathLike[str]'], *" + parameters(misalloc._COMPARE_OPTIONS)
                 + ") -> Dict[str, Any]: ...")
    lines.append("def read_exr(path: Union[str, 'os.PathLike[str]']) -> Dict[str, np.ndarray]: ...")
    with open(sys.argv[1], "w") as f:
        f.write("\n".join(lines) + "\n")


main()
