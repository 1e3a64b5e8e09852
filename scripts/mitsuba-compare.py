#!/usr/bin/env python3
"""The path integrator beside Mitsuba 3 on the same closed room, in one run on one machine.

Reads scenes/room.toml (boxes, spheres, Lambert colours, glowing spheres, a pinhole camera; all
at rest) and builds the same room for Mitsuba 3's `path` integrator (llvm_ad_rgb: Dr.Jit's
vectorised LLVM backend, every core). Both render it at several samples per pixel; each image's
luminance RMS is taken against a Mitsuba reference of many samples. Written to
docs/bench/mitsuba.md (make docs puts it into docs/performance.md):

- agreement: the mean of rest-embree's converged picture over Mitsuba's, and over 8x8 blocks;
- per sample per pixel: the slope of each renderer's time between its two largest sample
  counts (Mitsuba's render alone, after its kernel is compiled and cached);
- noise at equal samples per pixel;
- time to Mitsuba's error at the largest count: rest-embree's time scaled by (its RMS over
  Mitsuba's)^2, against Mitsuba's whole process and its render alone.

Needs: pip install mitsuba==3.9.1 OpenEXR numpy; apt-get install libllvm19 (Dr.Jit's LLVM backend
needs LLVM 16 or newer). A bench, not a test: `make test` does not run it.

Usage (from the project root, after cargo build --release):
    python3 scripts/mitsuba-compare.py [--quick] [--out docs/bench/mitsuba.md]
"""
import json
import os
import subprocess
import sys
import tempfile
import time
import tomllib

import numpy as np


# The project's root (given to the copy of this file the Mitsuba process imports).
ROOT = os.environ.get("REST_EMBREE_ROOT") or os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "rest-embree")
SCENE = os.path.join(ROOT, "scenes", "room.toml")
QUICK = "--quick" in sys.argv
OUT = sys.argv[sys.argv.index("--out") + 1] if "--out" in sys.argv else os.path.join(ROOT, "docs", "bench", "mitsuba.md")
TMP = tempfile.mkdtemp(prefix="rest-embree-mitsuba-")
LLVM = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"


def room():
    with open(SCENE, "rb") as f:
        return tomllib.load(f)


def grey(c):
    return [float(c)] * 3 if isinstance(c, (int, float)) else [float(x) for x in c]


def mitsuba_dict(mi, s, size, spp, seed):
    """The room as Mitsuba 3 takes it: each box a `cube` scaled and moved, each sphere a
    `sphere`, each Lambert colour a `diffuse` BSDF, each glowing material an `area` emitter.
    rest-embree's max_depth counts bounces after the primary hit; Mitsuba's counts the camera
    ray and the emitter's light too: 2 more."""
    T = mi.ScalarTransform4f
    cam = s["camera"]
    mats = {m["name"]: m for m in s["material"]}
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": s["render"]["max_depth"] + 2},
        "sensor": {
            "type": "perspective", "fov": cam["fov_y"], "fov_axis": "y",
            "to_world": T().look_at(origin=cam["position"], target=cam["look_at"], up=cam["up"]),
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
            "film": {"type": "hdrfilm", "width": size, "height": size,
                     "rfilter": {"type": "box"}, "pixel_format": "rgb"},
        },
    }
    for g in s["group"]:
        for i, o in enumerate(g["object"]):
            m = mats[o["material"]]
            if "emission" in m:
                look = {"emitter": {"type": "area", "radiance": {"type": "rgb", "value": grey(m["emission"])}}}
            else:
                look = {"bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": grey(m["color"])}}}
            if o["type"] == "box":
                lo, hi = np.array(o["min"], float), np.array(o["max"], float)
                shape = {"type": "cube", "to_world": T().translate(((lo + hi) / 2).tolist()).scale(((hi - lo) / 2).tolist())}
            elif o["type"] == "sphere":
                shape = {"type": "sphere", "center": o["center"], "radius": o["radius"]}
            else:
                raise SystemExit(f"mitsuba-compare: no Mitsuba shape for a {o['type']}")
            d[f"{g['name']}-{i}"] = {**shape, **look}
    return d


MITSUBA = r'''
import json, sys, time
import numpy as np
t0 = time.perf_counter()
import mitsuba as mi
mi.set_variant("llvm_ad_rgb")
sys.path.insert(0, sys.argv[1])
import mitsuba_compare as compare
size, spp, seed, out = int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
scene = mi.load_dict(compare.mitsuba_dict(mi, compare.room(), size, spp, seed))
t1 = time.perf_counter()
img = np.array(mi.render(scene, spp=spp, seed=seed))
t2 = time.perf_counter()
np.array(mi.render(scene, spp=spp, seed=seed + 1000))
t3 = time.perf_counter()
np.save(out, img)
print(json.dumps({"load": t1 - t0, "first": t2 - t1, "warm": t3 - t2}))
'''


def mitsuba(size, spp, seed):
    """Mitsuba in a process of its own: the image, and its times (whole process, load, first
    render, warm render)."""
    # The module name Python can import (a copy of this file without the dash).
    mod = os.path.join(TMP, "mitsuba_compare.py")
    if not os.path.exists(mod):
        with open(__file__) as src, open(mod, "w") as dst:
            dst.write(src.read())
    script = os.path.join(TMP, "run_mitsuba.py")
    with open(script, "w") as f:
        f.write(MITSUBA)
    out = os.path.join(TMP, f"mts-{spp}-{seed}.npy")
    env = dict(os.environ, REST_EMBREE_ROOT=ROOT)
    if os.path.exists(LLVM):
        env.setdefault("DRJIT_LIBLLVM_PATH", LLVM)
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, script, TMP, str(size), str(spp), str(seed), out],
                       capture_output=True, text=True, env=env)
    whole = time.perf_counter() - t0
    if r.returncode != 0:
        raise SystemExit("mitsuba-compare: Mitsuba failed: " + r.stderr[-600:])
    t = json.loads(r.stdout.strip().splitlines()[-1])
    t["whole"] = whole
    return np.load(out), t


def rest(size, spp, seed):
    """rest-embree's whole command: the image and its seconds."""
    import OpenEXR
    out = os.path.join(TMP, f"rest-{spp}-{seed}.exr")
    args = [BIN, "render", SCENE, "-o", out, "--width", str(size), "--height", str(size),
            "--samples", str(spp), "--set", f"render.seed={seed}", "--passes", "none", "--quiet"]
    t0 = time.perf_counter()
    subprocess.run(args, check=True)
    dt = time.perf_counter() - t0
    with OpenEXR.File(out, separate_channels=True) as f:
        ch = f.channels()
        img = np.stack([np.asarray(ch[c].pixels, dtype=np.float64) for c in "RGB"], -1)
    return img, dt


def lum(img):
    return img @ np.array([0.2126, 0.7152, 0.0722])


def main():
    # Here, not at the top: the Mitsuba process imports a copy of this file from elsewhere.
    from machine import cpu_model  # scripts/machine.py

    size = 128 if QUICK else 192
    ref_spp = 512 if QUICK else 2048
    counts = (4, 16, 64) if QUICK else (4, 16, 64, 256)
    ref, tref = mitsuba(size, ref_spp, 7)
    lr = lum(ref)
    mine, _ = rest(size, 256 if QUICK else 1024, 3)
    # The same picture or its mirror image (the two cameras' x axes).
    flip = np.abs(lum(mine[:, ::-1]) - lr).mean() < np.abs(lum(mine) - lr).mean()
    orient = (lambda a: a[:, ::-1]) if flip else (lambda a: a)
    mine = orient(mine)
    overall = lum(mine).mean() / lr.mean() - 1
    b = 8
    bm = lum(mine).reshape(size // b, b, size // b, b).mean((1, 3))
    br = lr.reshape(size // b, b, size // b, b).mean((1, 3))
    lit = br > 0.05 * br.mean()
    blocks = np.abs(bm[lit] / br[lit] - 1)
    rows = []
    for spp in counts:
        img, dt = rest(size, spp, 11)
        rms = float(np.sqrt(((lum(orient(img)) - lr) ** 2).mean()))
        mimg, mt = mitsuba(size, spp, 11)
        mrms = float(np.sqrt(((lum(mimg) - lr) ** 2).mean()))
        rows.append((spp, dt, rms, mt["whole"], mt["warm"], mrms))
    (s1, d1, *_), (s2, d2, r2, mw2_whole, mw2, mr2) = rows[-2], rows[-1]
    mw1 = rows[-2][4]
    per = (d2 - d1) / (s2 - s1)
    mper = (mw2 - mw1) / (s2 - s1)
    to_error = d2 * (r2 / mr2) ** 2
    lines = [
        f"Measured with `python3 scripts/mitsuba-compare.py{' --quick' if QUICK else ''}` "
        f"(scenes/room.toml at {size}x{size}, Mitsuba {__import__('mitsuba').__version__} llvm_ad_rgb `path`, "
        f"{os.cpu_count()} cores{cpu_model()}, one run):",
        "",
        f"- Agreement with Mitsuba's {ref_spp}-spp picture: mean {overall:+.4f}; 8x8 blocks "
        f"median {np.median(blocks):.4f}, 95th percentile {np.percentile(blocks, 95):.4f}.",
        f"- Per sample per pixel over the image: rest-embree {per * 1e3:.2f} ms, Mitsuba "
        f"{mper * 1e3:.2f} ms (its render alone, kernel cached): {per / mper:.2f}x.",
        f"- Time to Mitsuba's {s2}-spp error: rest-embree {to_error:.2f} s, against Mitsuba's "
        f"whole process {mw2_whole:.2f} s ({to_error / mw2_whole:.2f}x) and its render alone "
        f"{mw2:.2f} s ({to_error / mw2:.2f}x).",
        "",
        "| spp | rest-embree whole s | rest-embree RMS | Mitsuba whole s | Mitsuba render s | Mitsuba RMS | RMS ratio |",
        "|---|---|---|---|---|---|---|",
    ]
    for spp, dt, rms, mwhole, mwarm, mrms in rows:
        lines.append(f"| {spp} | {dt:.2f} | {rms:.4f} | {mwhole:.2f} | {mwarm:.2f} | {mrms:.4f} | {rms / mrms:.3f} |")
    text = "\n".join(lines) + "\n"
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        f.write(text)
    print(text)


if __name__ == "__main__":
    main()
