"""blendsynth: render Blender scenes without Blender, to make labelled synthetic
training datasets, from Python.

The same Rust library as the ``blendsynth`` command, called in-process::

    import blendsynth
    scene = blendsynth.Scene.load("colon")            # a folder made by convert()
    scene.set('lights["Spot"].energy', 90)            # the CLI's --set data paths
    scene.frame = 120
    r = scene.render(samples=64, seed=1, resolution=(256, 256))
    r.image        # float32 (H, W, 4), linear, what `render -o X.exr` writes
    r.depth        # float32 (H, W), inf where nothing was hit

Every error is a :class:`BlendsynthError` subclass carrying the CLI's message:
:class:`SceneError` (bad folder, file, data path or value), :class:`UnsupportedError`
(something blendsynth does not evaluate), :class:`RenderError`, :class:`Cancelled`,
:class:`BlenderError` (convert), :class:`DatasetError` (generate, replicate, specs).
See docs/python.md.
"""

from __future__ import annotations

import json
import os
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from ._native import (
    BlenderError,
    BlendsynthError,
    CancelToken,
    Cancelled,
    DatasetError,
    RenderError,
    SceneError,
    UnsupportedError,
)

__version__: str = _native.__version__

__all__ = [
    "Scene",
    "RenderResult",
    "Mesh",
    "CancelToken",
    "convert",
    "generate",
    "replicate",
    "PASSES",
    "DEFAULT_PASSES",
    "BlendsynthError",
    "SceneError",
    "UnsupportedError",
    "RenderError",
    "Cancelled",
    "BlenderError",
    "DatasetError",
]

PathLike = Union[str, "os.PathLike[str]"]

#: Every pass ``Scene.render`` can return (see :class:`RenderResult`).
PASSES: Tuple[str, ...] = (
    "image",
    "display",
    "depth",
    "distance",
    "normal",
    "albedo",
    "uv",
    "object_index",
    "instance_id",
    "material_index",
    "semantic",
    "sample_count",
    "aovs",
)
#: What ``Scene.render`` returns when ``passes`` is not given.
DEFAULT_PASSES: Tuple[str, ...] = ("image", "depth", "normal", "instance_id", "semantic")


@dataclass
class RenderResult:
    """A rendered frame. Passes not asked for are ``None``.

    - ``image``: float32 (H, W, 4) linear RGBA, premultiplied, denoised when asked: the
      pixels ``blendsynth render -o X.exr`` writes.
    - ``display``: uint8 or uint16 (H, W, 3 or 4) through the scene's colour management and
      output format: the pixels ``render -o X.png`` writes.
    - ``depth``: float32 (H, W), camera-space Z (Cycles' Z pass), ``inf`` where the pixel
      centre hits nothing (the CLI's EXR pass stores 1e10 there); ``distance`` the same
      along the ray.
    - ``normal``, ``albedo``: float32 (H, W, 3); ``uv``: float32 (H, W, 2).
    - ``object_index``, ``instance_id``, ``material_index``: uint32 (H, W), 0 for none,
      else index + 1 (``instance_objects[id - 1]`` names an instance's object).
    - ``semantic``: uint32 (H, W), 0 background, else class index + 1
      (``class_names[id - 1]``).
    - ``sample_count``: uint32 (H, W), samples taken per pixel.
    - ``aovs``: the view layer's shader AOVs by name (what AOV Output nodes write), float32
      (H, W) for a Value AOV, (H, W, 4) for a Color AOV: the values ``render --passes``
      writes to aovs.exr. Empty when the view layer has none.
    """

    width: int
    height: int
    image: Optional[np.ndarray] = None
    display: Optional[np.ndarray] = None
    depth: Optional[np.ndarray] = None
    distance: Optional[np.ndarray] = None
    normal: Optional[np.ndarray] = None
    albedo: Optional[np.ndarray] = None
    uv: Optional[np.ndarray] = None
    object_index: Optional[np.ndarray] = None
    instance_id: Optional[np.ndarray] = None
    material_index: Optional[np.ndarray] = None
    semantic: Optional[np.ndarray] = None
    sample_count: Optional[np.ndarray] = None
    aovs: Optional[Dict[str, np.ndarray]] = None
    instance_objects: List[str] = field(default_factory=list)
    class_names: List[str] = field(default_factory=list)
    denoised: bool = False
    #: samples, samples_taken, seconds, setup_seconds, triangles
    stats: Dict[str, Any] = field(default_factory=dict)

    def __getitem__(self, name: str) -> Any:
        if name not in PASSES:
            raise KeyError(name)
        v = getattr(self, name)
        if v is None:
            raise KeyError(f"{name} (not rendered: add it to passes=)")
        return v


@dataclass
class Mesh:
    """An object's evaluated geometry (``blendsynth mesh``): Blender's vertices one to
    one. ``vertices`` float32 (N, 3); faces as ``face_offsets`` (F + 1,) into
    ``corner_verts``; ``faces`` is an (F, k) array when every face has k corners, else a
    list of arrays."""

    vertices: np.ndarray
    face_offsets: np.ndarray
    corner_verts: np.ndarray

    @property
    def faces(self) -> Union[np.ndarray, List[np.ndarray]]:
        sizes = np.diff(self.face_offsets)
        if len(sizes) and np.all(sizes == sizes[0]):
            return self.corner_verts.reshape(-1, int(sizes[0]))
        return np.split(self.corner_verts, self.face_offsets[1:-1])

    def triangles(self) -> np.ndarray:
        """(T, 3) fan triangulation of every face (for plotting, not Blender's)."""
        tris = []
        for a, b in zip(self.face_offsets[:-1], self.face_offsets[1:]):
            f = self.corner_verts[a:b]
            for i in range(1, len(f) - 1):
                tris.append((f[0], f[i], f[i + 1]))
        return np.asarray(tris, dtype=np.uint32).reshape(-1, 3)


def _array(item: Tuple[bytearray, Sequence[int], str]) -> np.ndarray:
    buf, shape, dtype = item
    return np.frombuffer(buf, dtype=np.dtype(dtype)).reshape(shape)


def _json_value(path: str, value: Any) -> str:
    if isinstance(value, np.ndarray):
        value = value.tolist()
    elif isinstance(value, np.generic):
        value = value.item()
    elif isinstance(value, tuple):
        value = list(value)
    try:
        return json.dumps(value, allow_nan=False)
    except ValueError:
        raise SceneError(f"override {path}: value must be finite") from None
    except TypeError as e:
        raise TypeError(f"override {path}: {e}") from None


def _resolution(res: Any) -> Optional[Tuple[int, int]]:
    if res is None:
        return None
    if isinstance(res, str):
        a, sep, b = res.lower().partition("x")
        if not sep:
            raise ValueError(f"{res!r}: expected WxH, e.g. 640x480")
        return int(a), int(b)
    w, h = res
    return int(w), int(h)


class _Bar:
    """``progress=True``: a tqdm bar when tqdm is installed, else nothing."""

    def __init__(self) -> None:
        try:
            from tqdm.auto import tqdm
        except ImportError:  # pragma: no cover - depends on the environment
            tqdm = None
        self._tqdm = tqdm
        self._bar: Any = None

    def __call__(self, done: int, total: int) -> None:
        if self._tqdm is None:
            return
        if self._bar is None:
            self._bar = self._tqdm(total=total, unit="px-samples", unit_scale=True, leave=False)
        self._bar.update(done - self._bar.n)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()


class Scene:
    """An exported scene folder (``convert`` output) with overrides and a frame."""

    def __init__(self, native: "_native.Scene") -> None:
        self._s = native

    @classmethod
    def load(cls, dir: PathLike) -> "Scene":
        """Reads and validates ``DIR/scene.json``; raises :class:`SceneError`."""
        return cls(_native.Scene.load(os.fspath(dir)))

    @property
    def dir(self) -> Path:
        return Path(self._s.dir)

    def __repr__(self) -> str:
        return f"blendsynth.Scene({str(self.dir)!r}, frame={self.frame}, overrides={len(self.overrides)})"

    # -- parameters -------------------------------------------------------------------
    def set(self, path: str, value: Any) -> None:
        """Overrides a property by Blender data path, as ``--set PATH=VALUE`` does
        (``bpy.data.`` optional). The value keeps the type of what it replaces (a
        number fills a vector). Raises :class:`SceneError` naming the path."""
        self._s.set(path, _json_value(path, value))

    def set_arg(self, arg: str) -> None:
        """One ``PATH=VALUE`` string, parsed exactly as the CLI's ``--set``."""
        self._s.set_arg(arg)

    def get(self, path: str) -> Any:
        """The current value at a data path (overrides included)."""
        return json.loads(self._s.get(path))

    def __setitem__(self, path: str, value: Any) -> None:
        self.set(path, value)

    def __getitem__(self, path: str) -> Any:
        return self.get(path)

    @property
    def overrides(self) -> List[Tuple[str, Any]]:
        """The overrides set so far, in order."""
        return [(p, json.loads(v)) for p, v in self._s.overrides()]

    def reset(self) -> None:
        """Drops every override (the frame stays)."""
        self._s.reset()

    @property
    def frame(self) -> float:
        """The frame ``render`` and ``mesh`` evaluate (default: the file's current frame).
        Assign ``None`` to go back to the default."""
        return self._s.frame

    @frame.setter
    def frame(self, value: Optional[float]) -> None:
        self._s.frame = None if value is None else float(value)

    def objects(self) -> List[str]:
        return self._s.objects()

    # -- evaluation -------------------------------------------------------------------
    def inspect(self) -> Dict[str, Any]:
        """``blendsynth inspect --json`` as a dict (``all_supported``, node coverage)."""
        return json.loads(self._s.inspect())

    def mesh(self, object: str, frame: Optional[float] = None) -> Mesh:
        """``blendsynth mesh``: the object's geometry at the frame, modifiers and Geometry
        Nodes evaluated with the overrides, instances realised."""
        d = self._s.mesh(object, None if frame is None else float(frame))
        v = np.frombuffer(d["positions"], dtype=np.float32).reshape(-1, 3)
        off = np.frombuffer(d["face_offsets"], dtype=np.uint32)
        cv = np.frombuffer(d["corner_verts"], dtype=np.uint32)
        return Mesh(vertices=v, face_offsets=off, corner_verts=cv)

    def render(
        self,
        *,
        samples: Optional[int] = None,
        seed: Optional[int] = None,
        resolution: Union[None, str, Tuple[int, int]] = None,
        denoise: Optional[bool] = None,
        passes: Sequence[str] = DEFAULT_PASSES,
        threshold: Optional[float] = None,
        threads: Optional[int] = None,
        frame: Optional[float] = None,
        classes: Optional[PathLike] = None,
        oidn: Optional[PathLike] = None,
        progress: Union[None, bool, Callable[[int, int], Any]] = None,
        cancel: Optional[CancelToken] = None,
    ) -> RenderResult:
        """Renders the scene's camera as ``blendsynth render`` does (same defaults: the
        scene's samples, seed, resolution, threshold and denoising), returning arrays.

        ``passes``: names from :data:`PASSES`. ``threads``: worker threads (default all
        cores; the image is the same for any count). ``classes``: a dataset spec whose
        [labels] section maps objects to classes for ``semantic`` (else the objects'
        ``class`` custom property). ``progress``: ``True`` for a tqdm bar, or a callable
        ``f(done, total)`` called from this thread about every 0.1 s. ``cancel``: a
        :class:`CancelToken` another thread may cancel (raises :class:`Cancelled`).
        Ctrl-C stops the render cleanly and raises ``KeyboardInterrupt``. The GIL is
        released while rendering.
        """
        passes = list(passes)
        bar = _Bar() if progress is True else None
        cb = bar if bar is not None else (progress or None)
        try:
            d = self._s.render(
                passes,
                samples=samples,
                seed=seed,
                resolution=_resolution(resolution),
                threshold=threshold,
                denoise=denoise,
                threads=threads,
                oidn=None if oidn is None else os.fspath(oidn),
                classes=None if classes is None else os.fspath(classes),
                frame=None if frame is None else float(frame),
                cancel=cancel,
                progress=cb,
            )
        finally:
            if bar is not None:
                bar.close()
        meta = d.pop("_meta")
        if meta.get("notice"):
            print(f"notice: {meta['notice']}", file=sys.stderr)
        arrays: Dict[str, Any] = {
            k: {n: _array(a) for n, a in v.items()} if k == "aovs" else _array(v)
            for k, v in d.items()
        }
        return RenderResult(
            width=meta["width"],
            height=meta["height"],
            instance_objects=list(meta["instance_objects"]),
            class_names=list(meta.get("class_names", [])),
            denoised=meta["denoised"],
            stats={
                k: meta[k]
                for k in ("samples", "samples_taken", "seconds", "setup_seconds", "triangles")
            },
            **arrays,
        )


def convert(
    blend: PathLike,
    out_dir: PathLike,
    blender: Optional[PathLike] = None,
    *,
    frame: Optional[int] = None,
    evaluated: bool = True,
    allow_paths: Sequence[PathLike] = (),
) -> Scene:
    """``blendsynth convert``: exports a .blend with Blender (``blender``: an executable or
    a Python with bpy; default $BLENDSYNTH_BLENDER, $BLENDSYNTH_BPY_PYTHON, ``blender``
    on PATH) into ``out_dir`` and loads it. Image files outside the .blend's folder are
    copied only from the folders in ``allow_paths`` (the CLI's ``--allow-path``).
    Raises :class:`BlenderError`."""
    return Scene(
        _native.convert(
            os.fspath(blend),
            os.fspath(out_dir),
            None if blender is None else os.fspath(blender),
            frame,
            evaluated,
            [os.fspath(p) for p in allow_paths],
        )
    )


def _shard(shard: Union[None, str, Tuple[int, int]]) -> Optional[str]:
    if shard is None or isinstance(shard, str):
        return shard
    i, n = shard
    return f"{int(i)}/{int(n)}"


def _split(split: Union[str, Dict[str, float]]) -> str:
    if isinstance(split, str):
        return split
    return ",".join(f"{k}={v!r}" for k, v in split.items())


def _scene_dir(scene: Union[PathLike, Scene]) -> str:
    if isinstance(scene, Scene):
        if scene.overrides:
            raise ValueError(
                "generate() reads the scene folder; put overrides in the spec, not on the Scene"
            )
        return os.fspath(scene.dir)
    return os.fspath(scene)


def generate(
    scene: Union[PathLike, Scene],
    spec: PathLike,
    frames: int,
    out: PathLike,
    *,
    split: Union[str, Dict[str, float]] = "train=1",
    seed: int = 0,
    shard: Union[None, str, Tuple[int, int]] = None,
    resume: bool = False,
    jobs: Optional[int] = None,
    renderer: str = "path",
    progress: bool = False,
) -> Dict[str, Any]:
    """``blendsynth generate``: a labelled dataset in ``out`` (COCO, YOLO, masks), frames
    drawn from the randomisation ``spec``. Returns the summary (``out``, ``rendered``,
    ``skipped``, ``seconds``, ``complete``). Raises :class:`DatasetError`."""
    return _native.generate(
        _scene_dir(scene),
        os.fspath(spec),
        int(frames),
        os.fspath(out),
        _split(split),
        int(seed),
        _shard(shard),
        bool(resume),
        jobs,
        renderer,
        bool(progress),
    )


def replicate(
    out: PathLike,
    *,
    dataset: str = "doi-23843904",
    part: str = "all",
    frames: int = 50000,
    assets: Optional[PathLike] = None,
    seed: int = 0,
    shard: Union[None, str, Tuple[int, int]] = None,
    resume: bool = False,
    jobs: Optional[int] = None,
    renderer: str = "path",
    progress: bool = False,
) -> List[Dict[str, Any]]:
    """``blendsynth replicate``: regenerates a published dataset (the CLI's defaults:
    50,000 frames per part). Returns one summary per part."""
    return _native.replicate(
        dataset,
        os.fspath(out),
        part,
        int(frames),
        None if assets is None else os.fspath(assets),
        int(seed),
        _shard(shard),
        bool(resume),
        jobs,
        renderer,
        bool(progress),
    )

