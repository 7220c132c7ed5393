"""Arrays from Scene.render against the files `blendsynth render` writes for the same
scene, overrides, seed and settings: bit-identical."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import blendsynth
from conftest import SCENE, read_exr, read_png, run_cli

ARGS = dict(samples=4, seed=3, resolution=(48, 32), denoise=False)
SET = 'lights["Lamp"].energy=650'


def cli_render(tmp: Path, classes: Path, out_name: str, pass_format: str) -> Path:
    passes = tmp / f"passes_{pass_format}"
    run_cli(
        "render", str(SCENE), "--samples", "4", "--seed", "3", "--resolution", "48x32",
        "--denoise", "off", "--set", SET, "--classes", str(classes),
        "--passes", str(passes), "--pass-format", pass_format, "-o", str(tmp / out_name),
    )
    return passes


def test_render_is_bit_identical_to_cli(tmp_path: Path, classes_file: Path):
    s = blendsynth.Scene.load(SCENE)
    s.set_arg(SET)
    r = s.render(passes=blendsynth.PASSES, classes=classes_file, **ARGS)
    assert (r.width, r.height) == (48, 32)
    exr_passes = cli_render(tmp_path, classes_file, "img.exr", "exr")
    png_passes = cli_render(tmp_path, classes_file, "img.png", "png")

    # The linear image: the CLI's EXR, every bit.
    img = read_exr(tmp_path / "img.exr")
    assert img.shape == r.image.shape
    assert np.array_equal(img.view(np.uint32), r.image.view(np.uint32))
    # The display image: the CLI's PNG.
    png = read_png(tmp_path / "img.png")
    assert png.dtype == r.display.dtype and png.shape == r.display.shape
    assert np.array_equal(png, r.display)

    # Float passes (EXR; the CLI stores the background's infinite depth as 1e10).
    far = lambda a: np.where(np.isinf(a), np.float32(1e10), a)  # noqa: E731
    assert np.array_equal(read_exr(exr_passes / "depth.exr")[..., 0], far(r.depth))
    assert np.array_equal(read_exr(exr_passes / "distance.exr")[..., 0], far(r.distance))
    assert np.array_equal(read_exr(exr_passes / "normal.exr"), r.normal)
    assert np.array_equal(read_exr(exr_passes / "albedo.exr"), r.albedo)
    assert np.array_equal(read_exr(exr_passes / "uv.exr")[..., :2], r.uv)
    # Id passes (16-bit PNG, exact integers).
    for name in ("object_index", "instance_id", "material_index", "semantic"):
        assert np.array_equal(read_png(png_passes / f"{name}.png"), getattr(r, name)), name
    assert r.class_names == ["ball", "box"]
    assert {r.instance_objects[i - 1] for i in np.unique(r.instance_id) if i} == {"Floor", "Sphere", "Cube"}
    # Ids agree with the class map: the Sphere's pixels are "ball".
    sphere = r.instance_objects.index("Sphere") + 1
    assert np.all(r.semantic[r.instance_id == sphere] == 1)


def test_default_passes_and_settings(tmp_path: Path):
    s = blendsynth.Scene.load(SCENE)
    r = s.render(samples=1, resolution="16x8", denoise=False)
    for name in blendsynth.DEFAULT_PASSES:
        assert r[name] is not None
    assert r.display is None
    assert r.image.dtype == np.float32 and r.image.shape == (8, 16, 4)
    assert r.image.flags.writeable
    assert r.stats["samples"] == 1


AOV_SCENE = SCENE.parent / "aov"


def test_aovs_are_bit_identical_to_cli_aovs_exr(tmp_path: Path):
    """The view layer's AOV passes (scene `aov`: a Color AOV "tint", Value AOVs "mask" and
    "unused") as arrays by name, the values `render --passes` writes to aovs.exr."""
    OpenEXR = pytest.importorskip("OpenEXR")
    args = dict(samples=2, seed=1, resolution=(40, 30), denoise=False)
    r = blendsynth.Scene.load(AOV_SCENE).render(passes=["aovs"], **args)
    assert sorted(r.aovs) == ["mask", "tint", "unused"]
    assert r.aovs["tint"].shape == (30, 40, 4) and r.aovs["mask"].shape == (30, 40)
    assert r["aovs"] is r.aovs
    passes = tmp_path / "passes"
    run_cli(
        "render", str(AOV_SCENE), "--samples", "2", "--seed", "1", "--resolution", "40x30",
        "--denoise", "off", "--passes", str(passes), "--pass-format", "exr",
        "-o", str(tmp_path / "img.exr"),
    )
    with OpenEXR.File(str(passes / "aovs.exr"), separate_channels=True) as f:
        ch = {k: np.asarray(v.pixels, dtype=np.float32) for k, v in f.channels().items()}
    layer = next(k for k in ch if k.endswith(".mask.X")).removesuffix(".mask.X")
    for name, a in r.aovs.items():
        cli = (np.stack([ch[f"{layer}.{name}.{c}"] for c in "RGBA"], axis=-1)
               if a.ndim == 3 else ch[f"{layer}.{name}.X"])
        assert np.array_equal(cli.view(np.uint32), a.view(np.uint32)), name
    # Something was written: the floor's checker into tint, the sphere's facing into mask.
    assert r.aovs["tint"][..., :3].max() > 0.3 and r.aovs["mask"].max() > 0.2
    assert not r.aovs["unused"].any()
