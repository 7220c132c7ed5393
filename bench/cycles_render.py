"""One Cycles render for bench/speed.py, in a process of its own so that its wall time and
peak memory are the process's, as a user running Blender would see them.

    .venv/bin/python bench/cycles_render.py BLEND FRAME SIZE SAMPLES SEED THREADS OUT.exr

CPU, THREADS threads (0: all cores), adaptive sampling and denoising off, the scene's
other settings as the file has them (opened with its scripts disabled). Writes a 32-bit
linear RGBA EXR and prints `render_seconds S` (bpy.ops.render.render alone, which
includes Cycles' scene sync and BVH build).
"""
import os
import sys
import time

import bpy


def main():
    blend, frame, size, samples, seed, threads, out = sys.argv[-7:]
    bpy.ops.wm.open_mainfile(filepath=os.path.abspath(blend), load_ui=False, use_scripts=False)
    s = bpy.context.scene
    if frame != "-":
        s.frame_set(int(frame))
    s.render.engine = "CYCLES"
    s.cycles.device = "CPU"
    s.render.resolution_percentage = 100
    s.render.resolution_x = s.render.resolution_y = int(size)
    s.cycles.samples = int(samples)
    s.cycles.seed = int(seed)
    s.cycles.use_animated_seed = False
    s.cycles.use_adaptive_sampling = False
    s.cycles.use_denoising = False
    s.cycles.time_limit = 0.0
    if int(threads):
        s.render.threads_mode = "FIXED"
        s.render.threads = int(threads)
    else:
        s.render.threads_mode = "AUTO"
    s.render.image_settings.file_format = "OPEN_EXR"
    s.render.image_settings.color_depth = "32"
    s.render.image_settings.exr_codec = "ZIP"
    s.render.image_settings.color_mode = "RGBA"
    s.render.filepath = os.path.abspath(out)
    s.render.use_file_extension = False
    t = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    print(f"render_seconds {time.perf_counter() - t:.3f}", flush=True)


main()
sys.stdout.flush()
os._exit(0)
