"""Reading blendsynth datasets for training.

``DetectionDataset(folder, split)`` is a map-style dataset over a ``generate`` /
``replicate`` output folder in torchvision's detection format; ``yolo_data_yaml(folder)``
is the path Ultralytics takes (``YOLO(...).train(data=yolo_data_yaml("out"))``).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np

from . import _native

__all__ = ["DetectionDataset", "yolo_data_yaml", "decode_rle", "collate"]

PathLike = Union[str, "os.PathLike[str]"]


def yolo_data_yaml(folder: PathLike) -> Path:
    """The dataset's Ultralytics ``data.yaml`` (raises FileNotFoundError if absent)."""
    p = Path(folder) / "data.yaml"
    if not p.is_file():
        raise FileNotFoundError(f"{p}: no data.yaml (is {folder} a blendsynth dataset?)")
    return p


def decode_rle(counts: str, height: int, width: int) -> np.ndarray:
    """A COCO compressed RLE string (pycocotools' format) to a uint8 (H, W) mask."""
    runs: List[int] = []
    p = 0
    while p < len(counts):
        x = 0
        k = 0
        more = True
        while more:
            c = ord(counts[p]) - 48
            x |= (c & 0x1F) << (5 * k)
            more = bool(c & 0x20)
            p += 1
            k += 1
            if not more and (c & 0x10):
                x |= -1 << (5 * k)
        if len(runs) > 2:
            x += runs[-2]
        runs.append(x)
    flat = np.zeros(height * width, dtype=np.uint8)
    pos = 0
    for i, n in enumerate(runs):
        if n < 0 or pos + n > flat.size:
            raise ValueError("RLE counts do not fit the mask size")
        if i % 2 == 1:
            flat[pos : pos + n] = 1
        pos += n
    # COCO masks run down columns (Fortran order).
    return flat.reshape(width, height).T.copy()


def _torch() -> Any:
    try:
        import torch

        return torch
    except ImportError:
        return None


def collate(batch: List[Tuple[Any, Dict[str, Any]]]) -> Tuple[Tuple[Any, ...], Tuple[Dict[str, Any], ...]]:
    """``DataLoader(collate_fn=collate)``: images and targets as tuples (detection
    models take lists of differently sized targets)."""
    images, targets = zip(*batch)
    return images, targets


class DetectionDataset:
    """A split of a blendsynth dataset as (image, target) pairs in torchvision's
    detection format.

    ``target``: ``boxes`` (N, 4) float32 XYXY pixels, ``labels`` (N,) int64 (COCO category
    id: class index + 1, 0 is background), ``masks`` (N, H, W) uint8 (classes without
    masks get their box filled), ``image_id`` (the COCO image id), ``area`` (visible
    pixels), ``iscrowd`` (zeros).

    With PyTorch installed (and ``tensors`` not False) the image is a float32 (3, H, W)
    tensor in [0, 1] and the target values are tensors; without it the image is a uint8
    (H, W, 3) NumPy array and the target values are arrays. ``transforms(image, target)``
    is applied last. Works with ``torch.utils.data.DataLoader`` (``collate_fn=collate``).
    """

    def __init__(
        self,
        folder: PathLike,
        split: str = "train",
        transforms: Optional[Callable[[Any, Dict[str, Any]], Tuple[Any, Dict[str, Any]]]] = None,
        tensors: Optional[bool] = None,
    ) -> None:
        self.root = Path(folder)
        self.split = split
        self.transforms = transforms
        ann = self.root / "annotations" / f"instances_{split}.json"
        if not ann.is_file():
            have = sorted(
                p.name[len("instances_") : -len(".json")]
                for p in (self.root / "annotations").glob("instances_*.json")
            )
            raise FileNotFoundError(f"{ann}: no split {split!r} here (splits: {', '.join(have) or 'none'})")
        with open(ann, encoding="utf-8") as f:
            coco = json.load(f)
        self.images: List[Dict[str, Any]] = sorted(coco["images"], key=lambda im: im["id"])
        self.categories: Dict[int, str] = {c["id"]: c["name"] for c in coco["categories"]}
        self._anns: Dict[int, List[Dict[str, Any]]] = {im["id"]: [] for im in self.images}
        for a in coco["annotations"]:
            self._anns.setdefault(a["image_id"], []).append(a)
        torch = _torch()
        self._torch = torch if (tensors is None or tensors) else None
        if tensors and torch is None:
            raise ImportError("tensors=True needs PyTorch")

    @property
    def classes(self) -> List[str]:
        """Class names by label - 1."""
        return [self.categories[k] for k in sorted(self.categories)]

    def __len__(self) -> int:
        return len(self.images)

    def image_path(self, index: int) -> Path:
        return self.root / "images" / self.split / self.images[index]["file_name"]

    def __getitem__(self, index: int) -> Tuple[Any, Dict[str, Any]]:
        if not -len(self) <= index < len(self):
            raise IndexError(f"index {index} out of range ({len(self)} images in {self.split!r})")
        im = self.images[index]
        buf, shape, dtype = _native.read_image(os.fspath(self.image_path(index)))
        img = np.frombuffer(buf, dtype=np.dtype(dtype)).reshape(shape)
        if img.ndim == 2:
            img = np.repeat(img[:, :, None], 3, axis=2)
        img = img[:, :, :3]
        h, w = img.shape[:2]
        anns = self._anns.get(im["id"], [])
        boxes = np.zeros((len(anns), 4), dtype=np.float32)
        masks = np.zeros((len(anns), h, w), dtype=np.uint8)
        for i, a in enumerate(anns):
            x, y, bw, bh = a["bbox"]
            boxes[i] = (x, y, x + bw, y + bh)
            seg = a.get("segmentation")
            if isinstance(seg, dict):
                masks[i] = decode_rle(seg["counts"], seg["size"][0], seg["size"][1])
            else:
                masks[i, int(y) : int(y + bh), int(x) : int(x + bw)] = 1
        target: Dict[str, Any] = {
            "boxes": boxes,
            "labels": np.array([a["category_id"] for a in anns], dtype=np.int64),
            "masks": masks,
            "image_id": int(im["id"]),
            "area": np.array([a["area"] for a in anns], dtype=np.float32),
            "iscrowd": np.zeros(len(anns), dtype=np.int64),
        }
        image: Any = img
        torch = self._torch
        if torch is not None:
            image = torch.from_numpy(np.ascontiguousarray(img.transpose(2, 0, 1))).float().div_(255.0)
            target = {
                k: (torch.from_numpy(v) if isinstance(v, np.ndarray) else torch.tensor(v))
                for k, v in target.items()
            }
        if self.transforms is not None:
            image, target = self.transforms(image, target)
        return image, target
