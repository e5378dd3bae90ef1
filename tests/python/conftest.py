"""Shared fixtures of the Python module's tests: the misalloc program beside the module
(MISALLOC, set by ctest), and a cache folder of the session's own."""

import os
import subprocess

import numpy as np
import pytest

import misalloc

SIZE = (48, 40)


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("MISALLOC")
    if not path:
        pytest.fail("MISALLOC (the misalloc program) is not set; run these tests through ctest")

    def run(*args, check=True):
        return subprocess.run([path, *map(str, args)], check=check, capture_output=True, text=True)

    return run


@pytest.fixture(scope="session", autouse=True)
def cache_dir(tmp_path_factory):
    """The session's cache, also the default of every scene and process that names none:
    no test writes to the user's cache."""
    path = tmp_path_factory.mktemp("cache")
    os.environ["MISALLOC_CACHE_DIR"] = str(path)
    return path


def rgb(channels):
    return np.dstack([channels["R"], channels["G"], channels["B"]])
