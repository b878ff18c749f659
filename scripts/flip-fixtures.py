#!/usr/bin/env python3
"""Regenerates tests/fixtures/flip: image pairs and the FLIP that NVIDIA's official implementation
(the `flip-evaluator` package on PyPI) gives them, which tests/it/flip_official.rs compares with
the project's FLIP (src/metrics/flip.rs).

    python3 -m venv /tmp/flip && /tmp/flip/bin/pip install flip-evaluator numpy pillow
    /tmp/flip/bin/python scripts/flip-fixtures.py

Each pair is 8-bit sRGB RGB, 61 x 43 pixels (odd and unequal, so a transposed or padded reading
shows). For each pair and viewing condition the fixture records the official mean error and its
whole per-pixel map. Images are drawn from fixed seeds; the fixture's files are what the test
reads, so regenerating with another numpy only changes which images are checked.
"""
import csv
import sys
from pathlib import Path

import flip_evaluator as flip
import numpy as np
from PIL import Image

OUT = Path(__file__).resolve().parent.parent / "tests" / "fixtures" / "flip"
W, H = 61, 43
# Viewing conditions: (name, parameters). `default` is the project's PIXELS_PER_DEGREE: a
# 0.7 m wide monitor of 3840 pixels seen from 0.7 m.
CONDITIONS = [("default", {"vc": [0.7, 3840, 0.7]}), ("ppd30", {"ppd": 30.0})]


def penumbra(rng, width_px, noise):
    """A grey shadow edge (a linear ramp of `width_px` pixels across a tilted line) with
    independent per-pixel noise of standard deviation `noise`, as the experiments' grey
    pictures show a penumbra."""
    y, x = np.mgrid[0:H, 0:W].astype(np.float64)
    d = (x - W / 2) * np.cos(0.3) + (y - H / 2) * np.sin(0.3)
    v = np.clip(d / width_px + 0.5, 0.0, 1.0)
    v = np.clip(v + noise * rng.standard_normal(v.shape), 0.0, 1.0)
    return np.repeat(v[:, :, None], 3, axis=2)


def colour(rng):
    """A colour picture with edges and isolated points: blocks of random colours with a few
    bright dots, what FLIP's feature (edge and point) term responds to."""
    blocks = rng.random((H // 8 + 1, W // 8 + 1, 3))
    img = np.kron(blocks, np.ones((8, 8, 1)))[:H, :W]
    for _ in range(12):
        img[rng.integers(0, H), rng.integers(0, W)] = rng.random(3)
    return img


def to8(img):
    return np.round(np.clip(img, 0.0, 1.0) * 255.0).astype(np.uint8)


def pairs():
    rng = np.random.default_rng(2020)
    ref = penumbra(rng, 6.0, 0.0)
    yield "penumbra_noisy", ref, penumbra(rng, 6.0, 0.08)
    yield "penumbra_wider", ref, penumbra(rng, 9.0, 0.0)
    a = colour(rng)
    yield "colour_shifted", a, np.clip(a + 0.05 * rng.standard_normal(a.shape), 0.0, 1.0)
    yield "colour_against_grey", a, np.full_like(a, 0.5)
    yield "uniform", np.full((H, W, 3), 0.2), np.full((H, W, 3), 0.35)


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    rows = []
    for name, ref, test in pairs():
        r8, t8 = to8(ref), to8(test)
        Image.fromarray(r8).save(OUT / f"{name}_reference.png")
        Image.fromarray(t8).save(OUT / f"{name}_test.png")
        for cond, params in CONDITIONS:
            error_map, mean, used = flip.evaluate(
                r8.astype(np.float32) / 255.0,
                t8.astype(np.float32) / 255.0,
                "LDR",
                inputsRGB=True,
                applyMagma=False,
                computeMeanError=True,
                parameters=dict(params),
            )
            error_map = np.asarray(error_map, dtype=np.float64).reshape(H, W)
            np.savetxt(OUT / f"{name}_{cond}_map.txt", error_map, fmt="%.9e")
            rows.append({"pair": name, "condition": cond, "ppd": f"{used['ppd']:.9g}", "mean": f"{mean:.9e}"})
    with open(OUT / "official.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["pair", "condition", "ppd", "mean"])
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {len(rows)} values into {OUT} with flip-evaluator {version()}", file=sys.stderr)


def version():
    from importlib.metadata import version as v

    return v("flip-evaluator")


if __name__ == "__main__":
    main()
