"""Shared fixtures of the Python suite: the committed fixture scene, the CLI binary to
compare with, a class mapping, and helpers to read the CLI's EXR/PNG output."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
SCENE = REPO / "fixtures" / "render" / "scenes" / "diffuse_point"
GEONODES = REPO / "fixtures" / "scenes" / "geonodes"
MATERIAL_ZOO = REPO / "fixtures" / "scenes" / "material_zoo"
CLASSES_TOML = """[labels]
[[labels.class]]
name = "ball"
objects = ["Sph*"]
[[labels.class]]
name = "box"
objects = ["Cube"]
"""


def cli_path() -> str:
    """The CLI to compare with: $BLENDSYNTH_CLI, the wheel's `blendsynth` command, or the
    repository's release build."""
    env = os.environ.get("BLENDSYNTH_CLI")
    if env:
        return env
    found = shutil.which("blendsynth")
    if found:
        return found
    built = REPO / "target" / "release" / "blendsynth"
    if built.is_file():
        return str(built)
    pytest.fail("no blendsynth CLI found (set BLENDSYNTH_CLI)")


@pytest.fixture(scope="session")
def cli() -> str:
    return cli_path()


def run_cli(*args: str) -> subprocess.CompletedProcess:
    r = subprocess.run([cli_path(), *args], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r


@pytest.fixture()
def classes_file(tmp_path: Path) -> Path:
    p = tmp_path / "classes.toml"
    p.write_text(CLASSES_TOML)
    return p


def read_exr(path: Path) -> np.ndarray:
    """(H, W, C) float32 from an EXR file, with the `openexr` package."""
    OpenEXR = pytest.importorskip("OpenEXR")
    with OpenEXR.File(str(path)) as f:
        ch = f.channels()
        for group in ("RGBA", "RGB"):
            if group in ch:
                return np.asarray(ch[group].pixels, dtype=np.float32)
        names = [c for c in ("R", "G", "B", "A") if c in ch]
        return np.stack([np.asarray(ch[c].pixels, dtype=np.float32) for c in names], axis=-1)


def read_png(path: Path) -> np.ndarray:
    """(H, W) or (H, W, C) uint8/uint16 from a PNG, with the pure-Python `pypng` (which,
    unlike Pillow, keeps 16-bit colour)."""
    png = pytest.importorskip("png")
    w, h, rows, info = png.Reader(filename=str(path)).read()
    dtype = np.uint16 if info["bitdepth"] > 8 else np.uint8
    a = np.vstack([np.asarray(r, dtype=dtype) for r in rows])
    planes = info["planes"]
    return a.reshape(h, w, planes) if planes > 1 else a.reshape(h, w)
