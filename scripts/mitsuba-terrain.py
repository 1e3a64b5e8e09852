#!/usr/bin/env python3
"""A big mesh beside Mitsuba 3: the bench's terrain, in one run on one machine.

Writes the terrain of the bench's scene-file lines (src/bench/scene_files.rs, a height field over
[-1, 1]^2 as a binary PLY of float vertices and int faces, about 10 million triangles; the same
formula) and renders it at 1024x1024, 1 sample per pixel, lit by one point light, at rest:

- rest-embree: `rest-embree render` whole (reading, building, rendering, writing the EXR), with
  the build and render times it reports, and its peak memory;
- Mitsuba 3, `direct` integrator: scalar_rgb and llvm_ad_rgb, each in a process of its own,
  its load (mi.load_dict of the PLY) and render (mi.render; llvm's includes its kernel's
  compilation, as a first render does) timed, and its peak memory.

Targets (issue 52): rest-embree's render at most Mitsuba scalar_rgb's render; its whole command
at most Mitsuba llvm_ad_rgb's load and render. Written to docs/bench/terrain.md (make docs puts it
into docs/performance.md). Needs: pip install mitsuba==3.9.1 numpy; apt-get install libllvm19.
A bench, not a test.

Usage (from the project root, after cargo build --release):
    python3 scripts/mitsuba-terrain.py [--triangles N] [--out docs/bench/terrain.md]
"""
import os
import re
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

from machine import cpu_model  # scripts/machine.py


ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "rest-embree")
OUT = sys.argv[sys.argv.index("--out") + 1] if "--out" in sys.argv else os.path.join(ROOT, "docs", "bench", "terrain.md")
TRIANGLES = int(sys.argv[sys.argv.index("--triangles") + 1]) if "--triangles" in sys.argv else 10_000_000
LLVM = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"
SIZE = 1024


def write_terrain(path, triangles):
    """The bench's terrain (write_ply_terrain): (n+1)^2 float vertices, 2 n^2 int faces."""
    n = max(1, int(np.ceil(np.sqrt(triangles // 2))))
    i = np.arange(n + 1)
    x, y = np.meshgrid(2.0 * i / n - 1.0, 2.0 * i / n - 1.0)
    z = 0.08 * (np.sin(7.0 * x) * np.cos(5.0 * y)) + 0.03 * np.sin(23.0 * (x + y))
    v = np.stack([x, y, z], -1).reshape(-1, 3).astype("<f4")
    at = lambda a, b: b * (n + 1) + a
    jj, ii = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    t1 = np.stack([at(ii, jj), at(ii + 1, jj), at(ii + 1, jj + 1)], -1)
    t2 = np.stack([at(ii, jj), at(ii + 1, jj + 1), at(ii, jj + 1)], -1)
    faces = np.stack([t1, t2], 2).reshape(-1, 3)
    rec = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
    rec["n"], rec["i"] = 3, faces
    with open(path, "wb") as f:
        f.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(v)}\n"
                 "property float x\nproperty float y\nproperty float z\n"
                 f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n").encode())
        f.write(v.tobytes())
        f.write(rec.tobytes())
    return len(faces)


SCENE = """[camera]
position = [0, -2.2, 1.4]
look_at = [0, 0, 0]
up = [0, 0, 1]
fov_y = 40

[image]
width = {size}
height = {size}

[[light]]
position = [2, -2, 4]

[[group]]
name = "terrain"

[[group.object]]
type = "mesh"
file = "terrain.ply"
"""

MITSUBA = r'''
import resource, sys, time
t0 = time.perf_counter()
import mitsuba as mi
mi.set_variant(sys.argv[1])
ply, size = sys.argv[2], int(sys.argv[3])
t1 = time.perf_counter()
scene = mi.load_dict({
    "type": "scene",
    "integrator": {"type": "direct"},
    "sensor": {
        "type": "perspective", "fov": 40, "fov_axis": "y",
        "to_world": mi.ScalarTransform4f().look_at(origin=[0, -2.2, 1.4], target=[0, 0, 0], up=[0, 0, 1]),
        "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"}},
        "sampler": {"type": "independent", "sample_count": 1},
    },
    "light": {"type": "point", "position": [2, -2, 4], "intensity": {"type": "rgb", "value": 10.0}},
    "terrain": {"type": "ply", "filename": ply, "bsdf": {"type": "diffuse"}},
})
t2 = time.perf_counter()
img = mi.render(scene)
lit = int((mi.TensorXf(img).numpy()[..., 0] > 0).sum())
t3 = time.perf_counter()
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(f"import {t1 - t0:.3f} load {t2 - t1:.3f} render {t3 - t2:.3f} lit {lit} peak {peak:.0f}")
'''


def mitsuba(variant, ply, tmp):
    script = os.path.join(tmp, "mitsuba_terrain.py")
    with open(script, "w") as f:
        f.write(MITSUBA)
    env = dict(os.environ)
    if os.path.exists(LLVM):
        env.setdefault("DRJIT_LIBLLVM_PATH", LLVM)
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, script, variant, ply, str(SIZE)], capture_output=True, text=True, env=env)
    whole = time.perf_counter() - t0
    if r.returncode != 0:
        raise SystemExit(f"mitsuba {variant} failed:\n{r.stderr}")
    m = dict(zip(*[iter(r.stdout.split())] * 2))
    return {k: float(v) for k, v in m.items()} | {"whole": whole}


def rest(tmp, passes):
    toml = os.path.join(tmp, "terrain.toml")
    with open(toml, "w") as f:
        f.write(SCENE.format(size=SIZE))
    out = os.path.join(tmp, "terrain.exr")
    t0 = time.perf_counter()
    r = subprocess.run(["/usr/bin/time", "-f", "%M", BIN, "render", toml, "-o", out, "--passes", passes],
                       capture_output=True, text=True, check=True)
    whole = time.perf_counter() - t0
    line = r.stderr.strip().splitlines()
    peak = float(line[-1]) / 1024
    said = next(l for l in line if "build" in l)
    build = float(re.search(r"build ([0-9.]+) s", said).group(1))
    render = float(re.search(r"render ([0-9.]+) s", said).group(1))
    return {"whole": whole, "build": build, "render": render, "peak": peak}


def main():
    tmp = tempfile.mkdtemp(prefix="rest-embree-terrain-")
    ply = os.path.join(tmp, "terrain.ply")
    faces = write_terrain(ply, TRIANGLES)
    r = rest(tmp, "all")
    c = rest(tmp, "none")
    s = mitsuba("scalar_rgb", ply, tmp)
    l = mitsuba("llvm_ad_rgb", ply, tmp)
    nproc = os.cpu_count()
    met = lambda ok: "**met**" if ok else "**not met**"
    lines = [
        f"The bench's terrain, a binary PLY of {faces:,} triangles, rendered at {SIZE}² with 1 sample",
        f"per pixel and one point light, at rest, on {nproc} cores{cpu_model()}, each renderer in",
        "a process of its own (scripts/mitsuba-terrain.py). Mitsuba's render of llvm_ad_rgb includes its kernel's",
        "compilation, as a first render does; its load includes its import. rest-embree's render",
        "includes writing its EXR (its strips are compressed and written as they are rendered):",
        "with every pass, as by default, and with colour and alpha alone (`--passes none`), the",
        "image Mitsuba's render makes.",
        "",
        "| | load (read and build) | render | whole process | peak memory |",
        "|---|---|---|---|---|",
        f"| rest-embree (embree), every pass | {r['whole'] - r['render']:.2f} s (build {r['build']:.2f} s) | {r['render']:.2f} s | {r['whole']:.2f} s | {r['peak']:.0f} MiB |",
        f"| rest-embree (embree), `--passes none` | {c['whole'] - c['render']:.2f} s (build {c['build']:.2f} s) | {c['render']:.2f} s | {c['whole']:.2f} s | {c['peak']:.0f} MiB |",
        f"| Mitsuba 3 scalar_rgb, direct | {s['import'] + s['load']:.2f} s | {s['render']:.2f} s | {s['whole']:.2f} s | {s['peak']:.0f} MiB |",
        f"| Mitsuba 3 llvm_ad_rgb, direct | {l['import'] + l['load']:.2f} s | {l['render']:.2f} s | {l['whole']:.2f} s | {l['peak']:.0f} MiB |",
        "",
        f"- render against Mitsuba scalar_rgb's (target: at most 1x): with every pass {r['render']:.2f} s "
        f"against {s['render']:.2f} s ({r['render'] / s['render']:.2f}x): {met(r['render'] <= s['render'])}; "
        f"colour and alpha alone {c['render']:.2f} s ({c['render'] / s['render']:.2f}x): {met(c['render'] <= s['render'])};",
        f"- whole command against Mitsuba llvm_ad_rgb's load and render: {r['whole']:.2f} s against "
        f"{l['import'] + l['load'] + l['render']:.2f} s ({r['whole'] / (l['import'] + l['load'] + l['render']):.2f}x): "
        f"{met(r['whole'] <= l['import'] + l['load'] + l['render'])} (target: at most 1x);",
        f"- peak memory: {r['peak'] * 1048576 / faces:.0f} bytes a triangle with every pass, {c['peak'] * 1048576 / faces:.0f} with colour and alpha alone (the whole process; target 64).",
    ]
    text = "\n".join(lines) + "\n"
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        f.write(text)
    print(text)


if __name__ == "__main__":
    main()
