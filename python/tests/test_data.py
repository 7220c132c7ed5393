"""generate() and replicate() through Python, and DetectionDataset on the result (with
NumPy only, with PyTorch when it is importable), checked against the dataset's own files."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

import blendsynth
from blendsynth.data import DetectionDataset, collate, decode_rle, yolo_data_yaml
from conftest import CLASSES_TOML, SCENE, read_png

SPEC = """[render]
resolution = [40, 32]
samples = 2
denoise = false

""" + CLASSES_TOML.replace("[[labels.class]]\nname = \"box\"", "[[labels.class]]\nname = \"box\"\nmask = false") + """
[[param]]
path = 'objects["Cube"].location'
offset = true
dist = "uniform"
min = [-0.3, -0.3, 0.0]
max = [0.3, 0.3, 0.0]
"""


@pytest.fixture(scope="module")
def dataset(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("ds")
    spec = tmp / "spec.toml"
    spec.write_text(SPEC)
    out = tmp / "out"
    s = blendsynth.generate(SCENE, spec, 5, out, split={"train": 0.6, "val": 0.4}, seed=11, jobs=2)
    assert s["rendered"] == 5 and s["complete"]
    return out


def test_generate_errors(tmp_path: Path):
    spec = tmp_path / "spec.toml"
    spec.write_text(SPEC)
    with pytest.raises(blendsynth.DatasetError, match="split"):
        blendsynth.generate(SCENE, spec, 2, tmp_path / "o", split="train=0.5")
    with pytest.raises(blendsynth.DatasetError, match="frames"):
        blendsynth.generate(SCENE, spec, 0, tmp_path / "o")
    bad = tmp_path / "bad.toml"
    bad.write_text("[[param]]\npath = 'lights[\"Nope\"].energy'\ndist = \"uniform\"\nmin = 1\nmax = 2\n")
    with pytest.raises(blendsynth.DatasetError, match="Nope"):
        blendsynth.generate(SCENE, bad, 1, tmp_path / "o2")
    with pytest.raises(blendsynth.DatasetError, match="unknown dataset"):
        blendsynth.replicate(tmp_path / "r", dataset="doi-0", frames=1)


def check_target(ds: DetectionDataset, image, target, index: int, as_np) -> None:
    im = ds.images[index]
    assert target["image_id"] == im["id"] if not hasattr(target["image_id"], "item") else target["image_id"].item() == im["id"]
    boxes, labels, masks = (as_np(target[k]) for k in ("boxes", "labels", "masks"))
    h, w = im["height"], im["width"]
    assert masks.shape == (len(boxes), h, w)
    assert set(labels.tolist()) <= set(ds.categories)
    for b, l, m in zip(boxes, labels, masks):
        assert 0 <= b[0] < b[2] <= w and 0 <= b[1] < b[3] <= h
        ys, xs = np.nonzero(m)
        # The mask's extent is the box (XYXY, pixel edges).
        assert (xs.min(), ys.min(), xs.max() + 1, ys.max() + 1) == tuple(int(v) for v in b)
    # The semantic mask file agrees with the instance masks of mask classes.
    sem = read_png(ds.root / "masks" / ds.split / im["file_name"])
    for l, m in zip(labels, masks):
        if ds.categories[int(l)] == "ball":
            assert np.all(sem[m.astype(bool)] == l)


def test_detection_dataset_numpy(dataset: Path):
    ds = DetectionDataset(dataset, "train", tensors=False)
    val = DetectionDataset(dataset, "val", tensors=False)
    assert len(ds) + len(val) == 5 and len(ds) == 3
    assert ds.classes == ["ball", "box"]
    n_boxes = 0
    for i in range(len(ds)):
        image, target = ds[i]
        assert isinstance(image, np.ndarray) and image.dtype == np.uint8 and image.shape == (32, 40, 3)
        assert np.array_equal(image, read_png(ds.image_path(i))[:, :, :3])
        check_target(ds, image, target, i, np.asarray)
        n_boxes += len(target["boxes"])
    assert n_boxes > 0
    with pytest.raises(IndexError):
        ds[len(ds)]
    with pytest.raises(FileNotFoundError, match="splits: train, val"):
        DetectionDataset(dataset, "test")
    flip = DetectionDataset(dataset, "train", tensors=False, transforms=lambda im, t: (im[:, ::-1], t))
    assert np.array_equal(flip[0][0], ds[0][0][:, ::-1])


def test_rle_matches_pycocotools(dataset: Path):
    mask_util = pytest.importorskip("pycocotools.mask")
    coco = json.loads((dataset / "annotations" / "instances_train.json").read_text())
    rles = [a["segmentation"] for a in coco["annotations"] if isinstance(a["segmentation"], dict)]
    assert rles
    for seg in rles:
        ref = mask_util.decode({"size": seg["size"], "counts": seg["counts"].encode()})
        assert np.array_equal(decode_rle(seg["counts"], *seg["size"]), ref)


def test_detection_dataset_torch(dataset: Path):
    # CI sets BLENDSYNTH_REQUIRE_TORCH=1 in its PyTorch environment: a missing torch
    # fails there instead of skipping.
    if os.environ.get("BLENDSYNTH_REQUIRE_TORCH") == "1":
        import torch
    else:
        torch = pytest.importorskip("torch")
    ds = DetectionDataset(dataset, "train")
    image, target = ds[0]
    assert isinstance(image, torch.Tensor) and image.dtype == torch.float32 and image.shape == (3, 32, 40)
    assert target["boxes"].dtype == torch.float32 and target["labels"].dtype == torch.int64
    check_target(ds, image, target, 0, lambda t: t.numpy())
    loader = torch.utils.data.DataLoader(ds, batch_size=2, collate_fn=collate)
    images, targets = next(iter(loader))
    assert len(images) == 2 and len(targets) == 2


def test_yolo_data_yaml(dataset: Path, tmp_path: Path):
    p = yolo_data_yaml(dataset)
    assert p == dataset / "data.yaml" and "names" in p.read_text()
    with pytest.raises(FileNotFoundError):
        yolo_data_yaml(tmp_path)


def test_replicate_bounds(tmp_path: Path):
    # The built-in scenes through replicate(), with the quick debugging renderer.
    out = tmp_path / "rep"
    s = blendsynth.replicate(out, part="laparoscopy", frames=2, renderer="bounds", jobs=1)
    assert len(s) == 1 and s[0]["rendered"] == 2
    assert len(DetectionDataset(out, "train", tensors=False)) + len(DetectionDataset(out, "val", tensors=False)) == 2
