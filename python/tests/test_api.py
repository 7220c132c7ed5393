"""The API on the committed fixture scene: loading, data paths, frame, inspect, mesh,
and bad input raising the documented exceptions with the CLI's messages."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import blendsynth
from conftest import GEONODES, MATERIAL_ZOO, SCENE, run_cli


def test_load_and_describe():
    s = blendsynth.Scene.load(SCENE)
    assert s.dir == SCENE
    assert set(s.objects()) == {"Cam", "Cube", "Floor", "Lamp", "Sphere"}
    info = s.inspect()
    assert isinstance(info, dict) and info["all_supported"] is True


def test_get_set_frame():
    s = blendsynth.Scene.load(SCENE)
    assert s.get('lights["Lamp"].energy') == 800.0
    s.set('bpy.data.lights["Lamp"].energy', 90)
    assert s.get('lights["Lamp"].energy') == 90.0
    s['lights["Lamp"].color'] = 0.5  # a number fills a colour, as --set does
    assert s['lights["Lamp"].color'] == [0.5, 0.5, 0.5]
    s.set_arg('lights["Lamp"].energy=120')
    assert [p for p, _ in s.overrides] == ['lights["Lamp"].energy', 'lights["Lamp"].color', 'lights["Lamp"].energy']
    s.reset()
    assert s.get('lights["Lamp"].energy') == 800.0
    assert s.frame == 1.0
    s.frame = 7
    assert s.frame == 7.0
    s.frame = None
    assert s.frame == 1.0


def test_bad_input_raises_documented_exceptions(tmp_path: Path):
    with pytest.raises(blendsynth.SceneError, match="not a folder"):
        blendsynth.Scene.load(tmp_path / "missing")
    s = blendsynth.Scene.load(SCENE)
    with pytest.raises(blendsynth.SceneError, match=r'override lights\["Nope"\].energy'):
        s.set('lights["Nope"].energy', 1)
    with pytest.raises(blendsynth.SceneError, match="expects a number"):
        s.set('lights["Lamp"].energy', "bright")
    with pytest.raises(blendsynth.SceneError, match="finite"):
        s.set('lights["Lamp"].energy', float("nan"))
    with pytest.raises(blendsynth.SceneError, match="no property"):
        s.get('lights["Lamp"].wattage')
    # A failed set leaves the scene as it was.
    assert s.overrides == []
    with pytest.raises(blendsynth.RenderError, match="resolution 0x4"):
        s.render(resolution=(0, 4), samples=1)
    with pytest.raises(ValueError, match="unknown pass"):
        s.render(passes=["beauty"], samples=1)
    with pytest.raises(blendsynth.SceneError):
        s.mesh("NoSuchObject")
    with pytest.raises(blendsynth.BlenderError, match="nothing.blend"):
        blendsynth.convert(tmp_path / "nothing.blend", tmp_path / "out")
    # Every error type is a BlendsynthError.
    for e in (blendsynth.SceneError, blendsynth.UnsupportedError, blendsynth.RenderError,
              blendsynth.Cancelled, blendsynth.BlenderError, blendsynth.DatasetError):
        assert issubclass(e, blendsynth.BlendsynthError)


def test_mesh_matches_cli(tmp_path: Path):
    s = blendsynth.Scene.load(GEONODES)
    obj = "Terrain"  # Geometry Nodes on a grid
    m = s.mesh(obj)
    out = tmp_path / "m.obj"
    r = run_cli("mesh", str(GEONODES), "--object", obj, "-o", str(out))
    # "NAME at frame F: V vertices, E edges, F faces -> ..."
    words = r.stdout.split()
    nv = int(words[words.index("vertices,") - 1])
    nf = int(words[words.index("faces") - 1])
    assert m.vertices.shape == (nv, 3)
    assert len(m.face_offsets) == nf + 1
    v = np.array(
        [[float(x) for x in line.split()[1:4]] for line in out.read_text().splitlines() if line.startswith("v ")],
        dtype=np.float64,
    )
    assert v.shape == m.vertices.shape
    assert np.allclose(v, m.vertices, atol=1e-5)
    tris = m.triangles()
    assert tris.shape[1] == 3 and tris.max() < nv


def test_unsupported_raises_unsupported_error():
    # An option value blendsynth does not evaluate is an error naming it, never a stand-in.
    s = blendsynth.Scene.load(MATERIAL_ZOO)
    s.set('materials["Zoo"].node_tree.nodes["Color Ramp"].color_ramp.interpolation', "WIGGLY")
    with pytest.raises(blendsynth.UnsupportedError, match='interpolation "WIGGLY" is not supported'):
        s.render(samples=1, resolution=(4, 4), denoise=False)
