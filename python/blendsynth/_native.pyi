# Type stubs of the extension module (src/python/mod.rs). The typed public API is in
# __init__.py and data.py; these are its building blocks.
from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

__version__: str

class BlendsynthError(Exception): ...
class SceneError(BlendsynthError): ...
class UnsupportedError(BlendsynthError): ...
class RenderError(BlendsynthError): ...
class Cancelled(BlendsynthError): ...
class BlenderError(BlendsynthError): ...
class DatasetError(BlendsynthError): ...

class CancelToken:
    def __init__(self) -> None: ...
    def cancel(self) -> None: ...
    @property
    def cancelled(self) -> bool: ...
    def reset(self) -> None: ...

_Array = Tuple[bytearray, List[int], str]

class Scene:
    @staticmethod
    def load(dir: Union[str, PathLike[str]]) -> Scene: ...
    @property
    def dir(self) -> str: ...
    def set(self, path: str, value_json: str) -> None: ...
    def set_arg(self, arg: str) -> None: ...
    def get(self, path: str) -> str: ...
    def overrides(self) -> List[Tuple[str, str]]: ...
    def reset(self) -> None: ...
    frame: Optional[float]
    def objects(self) -> List[str]: ...
    def inspect(self) -> str: ...
    def mesh(self, object: str, frame: Optional[float] = ...) -> Dict[str, Any]: ...
    def render(
        self,
        passes: Sequence[str],
        samples: Optional[int] = ...,
        seed: Optional[int] = ...,
        resolution: Optional[Tuple[int, int]] = ...,
        threshold: Optional[float] = ...,
        denoise: Optional[bool] = ...,
        threads: Optional[int] = ...,
        oidn: Optional[str] = ...,
        classes: Optional[str] = ...,
        frame: Optional[float] = ...,
        cancel: Optional[CancelToken] = ...,
        progress: Optional[Callable[[int, int], Any]] = ...,
    ) -> Dict[str, Any]: ...

def convert(
    blend: str,
    out_dir: str,
    blender: Optional[str] = ...,
    frame: Optional[int] = ...,
    evaluated: bool = ...,
    allow_paths: List[str] = ...,
) -> Scene: ...
def generate(
    dir: str,
    spec: str,
    frames: int,
    out: str,
    split: str,
    seed: int,
    shard: Optional[str],
    resume: bool,
    jobs: Optional[int],
    renderer: str,
    progress: bool,
) -> Dict[str, Any]: ...
def replicate(
    dataset: str,
    out: str,
    part: str,
    frames: int,
    assets: Optional[str],
    seed: int,
    shard: Optional[str],
    resume: bool,
    jobs: Optional[int],
    renderer: str,
    progress: bool,
) -> List[Dict[str, Any]]: ...
def read_image(path: str) -> _Array: ...
