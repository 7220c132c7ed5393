"""The README's pictures, regenerated from the repository's own built-in scenes.

    .venv/bin/python docs/make_readme_figure.py [--frame 527] [--size 256] [--samples 64]

Writes, into docs/images/:
- `colon_cycles_vs_blendsynth.png`: the built-in colonoscopy scene
  (assets/doi-23843904, re-authored with bpy by its make_scenes.py) at one frame,
  Cycles (bpy 4.5.4) on the left, `blendsynth render` on the right, both at the
  scene's own view transform and denoising, at the size and samples given;
- `colon_labels.png`: `blendsynth preview` of four frames that `blendsynth generate`
  made with the scene's colonoscopy spec (render size and samples lowered as above),
  masks tinted and boxes outlined by class.

Only the repository's own scenes are used (nothing from ../shared), so the pictures may
be committed. Needs bpy (the .venv that .ci/run makes) and a release build.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
ASSETS = os.path.join(REPO, "assets", "doi-23843904")
BIN = os.path.join(REPO, "target", "release", "blendsynth")


def cycles_png(blend, frame, size, samples, out_png):
    """Cycles at the scene's settings but for size and samples, saved through its view."""
    import bpy
    bpy.ops.wm.open_mainfile(filepath=blend, load_ui=False, use_scripts=False)
    s = bpy.context.scene
    s.render.engine = "CYCLES"
    s.cycles.device = "CPU"
    s.frame_set(frame)
    s.render.resolution_x = s.render.resolution_y = size
    s.render.resolution_percentage = 100
    s.cycles.samples = samples
    st = s.render.image_settings
    st.file_format, st.color_mode, st.color_depth = "PNG", "RGB", "8"
    s.render.filepath = out_png
    bpy.ops.render.render(write_still=True)


def load_rgb(path):
    import bpy
    import numpy as np
    img = bpy.data.images.load(path, check_existing=False)
    w, h = img.size
    px = np.empty(w * h * 4, dtype=np.float32)
    img.pixels.foreach_get(px)
    return px.reshape(h, w, 4)[:, :, :3]


def save_rgb(rgb, path):
    import bpy
    import numpy as np
    h, w, _ = rgb.shape
    img = bpy.data.images.new(os.path.basename(path), w, h, alpha=False)
    rgba = np.concatenate([rgb, np.ones((h, w, 1), np.float32)], axis=2)
    img.pixels.foreach_set(rgba.astype(np.float32).ravel())
    img.filepath_raw = path
    img.file_format = "PNG"
    img.save()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--frame", type=int, default=527, help="scene frame (the spec's second dataset frame)")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--out", default=os.path.join(HERE, "images"))
    a = ap.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:])
    import numpy as np
    os.makedirs(a.out, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([sys.executable, os.path.join(ASSETS, "make_scenes.py"), tmp], check=True,
                       stdout=subprocess.DEVNULL)
        cyc = os.path.join(tmp, "cycles.png")
        cycles_png(os.path.join(tmp, "colonoscopy.blend"), a.frame, a.size, a.samples, cyc)
        ours = os.path.join(tmp, "ours.png")
        subprocess.run([BIN, "render", os.path.join(ASSETS, "colonoscopy"), "--frame", str(a.frame),
                        "--resolution", f"{a.size}x{a.size}", "--samples", str(a.samples), "-o", ours],
                       check=True)
        gap = np.ones((a.size, 4, 3), np.float32)
        save_rgb(np.concatenate([load_rgb(cyc), gap, load_rgb(ours)], axis=1),
                 os.path.join(a.out, "colon_cycles_vs_blendsynth.png"))

        # A labelled frame: the scene's own spec with a smaller render.
        spec = open(os.path.join(ASSETS, "colonoscopy.toml")).read()
        spec = re.sub(r"resolution = \[\d+, \d+\]", f"resolution = [{a.size}, {a.size}]", spec, count=1)
        spec = re.sub(r"samples = \d+", f"samples = {a.samples}", spec, count=1)
        spec_path = os.path.join(tmp, "colonoscopy.toml")
        with open(spec_path, "w") as f:
            f.write(spec)
        ds = os.path.join(tmp, "dataset")
        subprocess.run([BIN, "generate", os.path.join(ASSETS, "colonoscopy"), "--spec", spec_path,
                        "--frames", "4", "-o", ds], check=True)
        subprocess.run([BIN, "preview", ds, "-o", os.path.join(a.out, "colon_labels.png"), "--count", "4"],
                       check=True)
    print(f"wrote {a.out}/colon_cycles_vs_blendsynth.png and colon_labels.png")


if __name__ == "__main__":
    main()
