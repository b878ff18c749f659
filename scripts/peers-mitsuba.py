#!/usr/bin/env python3
"""Renders an exported view (scene.xml from `export --to mitsuba`) with Mitsuba 3.

    peers-mitsuba.py EXPORT_DIR --spp 16,64,256 --seeds 4 [--variant scalar_rgb]

Writes EXPORT_DIR/mitsuba-spp{N}-seed{K}.exr (linear float32 RGB radiance, box filter, as the
file says) for seeds 1..K of every sample count, and EXPORT_DIR/mitsuba-times.csv with each
render's wall-clock seconds. Mitsuba's own seed is K (its independent sampler), so the seeds
are independent images. EXPORT_DIR/mitsuba-pixel-centres.csv holds where Mitsuba's pixel
values are centred: the mean world position its camera rays hit (its `position` AOV, 256 samples
per pixel, the same film and filter), minus the pixel centre, in pixels along the image's x
(right) and y (down), averaged over every pixel.
"""
import argparse
import csv
import os
import time

import mitsuba as mi
import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("export_dir")
    ap.add_argument("--spp", default="16,64,256")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--variant", default="scalar_rgb")
    a = ap.parse_args()
    mi.set_variant(a.variant)
    scene_file = os.path.join(a.export_dir, "scene.xml")
    rows = []
    for spp in [int(s) for s in a.spp.split(",")]:
        for seed in range(1, a.seeds + 1):
            scene = mi.load_file(scene_file, spp=spp, seed=seed)
            t0 = time.perf_counter()
            image = mi.render(scene, spp=spp, seed=seed)
            out = os.path.join(a.export_dir, f"mitsuba-spp{spp}-seed{seed}.exr")
            mi.util.write_bitmap(out, image)
            rows.append((f"mitsuba-spp{spp}-seed{seed}.exr", spp, seed, a.variant, mi.__version__, time.perf_counter() - t0))
            print(f"wrote {out}")
    dx, dy = pixel_centres(scene_file)
    with open(os.path.join(a.export_dir, "mitsuba-pixel-centres.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["offset_x_px", "offset_y_px", "variant", "mitsuba"])
        w.writerow([f"{dx:.5f}", f"{dy:.5f}", a.variant, mi.__version__])
    with open(os.path.join(a.export_dir, "mitsuba-times.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["image", "spp", "seed", "variant", "mitsuba", "seconds"])
        w.writerows(rows)


def pixel_centres(scene_file):
    """Mean offset, in pixels (x right, y down), of Mitsuba's pixel values from its own pixel
    centres: the position AOV's per-pixel mean hit point against the hit of the camera ray
    Mitsuba generates through each pixel's centre."""
    with open(scene_file) as f:
        xml = f.read()
    start = xml.index('<integrator type="direct">')
    end = xml.index("</integrator>", start) + len("</integrator>")
    aov = '<integrator type="aov"><string name="aovs" value="p:position"/></integrator>'
    scene = mi.load_string(xml[:start] + aov + xml[end:], spp=256, seed=1)
    mean_hit = np.array(mi.render(scene, spp=256))
    sensor = scene.sensors()[0]
    w, h = sensor.film().size()
    centre = np.zeros((h, w, 3))
    for y in range(h):
        for x in range(w):
            ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f((x + 0.5) / w, (y + 0.5) / h), mi.Point2f(0.5, 0.5))
            centre[y, x] = np.array(scene.ray_intersect(ray).p)
    # World metres per pixel along the image's x and y, from neighbouring centres.
    right = (centre[:, -1] - centre[:, 0]).mean(0) / (w - 1)
    down = (centre[-1] - centre[0]).mean(0) / (h - 1)
    d = (mean_hit - centre).reshape(-1, 3).mean(0)
    return float(d @ right / (right @ right)), float(d @ down / (down @ down))


if __name__ == "__main__":
    main()
