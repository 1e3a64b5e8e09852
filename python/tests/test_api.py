"""The Python package against the command line (docs/python.md): the same scene renders the
same pixels in every pass, errors carry the same messages, renders stop on Ctrl-C, memory
stays flat over many renders, and the notebook runs top to bottom."""

import os
import re as regex
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import rest_embree as re

ROOT = Path(__file__).resolve().parents[2]
EXE = Path(os.environ.get("REST_EMBREE", ROOT / "target" / "release" / "rest-embree"))
LATTICE = ROOT / "scenes" / "lattice.toml"

CUBE = {
    "camera": {"position": [0, 0, 0], "look_at": [0, 10, 0], "time": 10, "fov_y": 30},
    "image": {"width": 64, "height": 48},
    "material": [{"name": "white", "color": [0.8, 0.8, 0.8]}],
    "light": [{"position": [0, 0, 20], "color": {"blackbody": 5800, "luminance": 1}}],
    "group": [{"name": "cube", "velocity": [0.5, 0, 0],
               "object": [{"type": "box", "min": [-1, 9, -1], "max": [1, 11, 1], "material": "white"}]}],
}


def cli(*args):
    """The command's exit status and standard error."""
    p = subprocess.run([str(EXE), *map(str, args)], capture_output=True, text=True)
    return p.returncode, p.stderr


def test_the_version_is_the_crates():
    text = (ROOT / "Cargo.toml").read_text()
    version = regex.search(r'^version = "([^"]+)"', text, regex.M).group(1)
    assert re.__version__ == version
    py = (ROOT / "python" / "Cargo.toml").read_text()
    assert regex.search(r'^version = "([^"]+)"', py, regex.M).group(1) == version


def test_every_pass_equals_the_command_lines(tmp_path):
    sets = {"group.lattice.velocity": [-0.9, 0, 0], "image.width": 96, "image.height": 72}
    for backend in re.backends():
        scene = re.Scene.load(LATTICE)
        for k, v in sets.items():
            scene.set(k, v)
        image = re.render(scene, backend=backend)
        out = tmp_path / f"cli-{backend}.exr"
        code, err = cli("render", LATTICE, "-o", out, "--backend", backend,
                        *[f"--set={k}={re._literal(v)}" for k, v in sets.items()])
        assert code == 0, err
        theirs = re.read_exr(out)
        image.save(tmp_path / "py.exr")
        # The same file, header and all.
        assert (tmp_path / "py.exr").read_bytes() == out.read_bytes()
        ours = re.read_exr(tmp_path / "py.exr")
        assert sorted(ours) == sorted(theirs)
        for name in theirs:
            assert np.array_equal(ours[name], theirs[name], equal_nan=True), f"{backend}: {name}"
        # The arrays are the file's channels.
        assert np.array_equal(image.rgba[..., 0], theirs["R"])
        assert np.array_equal(image.rgba[..., 3], theirs["A"])
        assert np.array_equal(image["doppler"], theirs["doppler.V"])
        assert np.array_equal(image["lookback"], theirs["lookback.V"])
        assert np.array_equal(image["depth"], theirs["Z"])
        assert np.array_equal(image["object_id"].astype(np.float32), theirs["object_id.V"])
        assert np.array_equal(image["normal"][..., 1], theirs["N.Y"])
        assert image.rgba.dtype == np.float32 and image["object_id"].dtype == np.uint32
        # The lattice approaches at 0.9c: blue-shifted, D up to sqrt(1.9 / 0.1).
        d = image["doppler"][image["object_id"] > 0]
        assert d.size > 100 and 1.0 < d.max() <= np.sqrt(1.9 / 0.1) + 1e-3


def test_a_png_is_the_command_lines(tmp_path):
    scene = re.Scene.load(LATTICE).set("image.width", 80).set("image.height", 60)
    image = re.render(scene, passes=False, transparent=False)
    image.save(tmp_path / "py.png")
    code, err = cli("render", LATTICE, "-o", tmp_path / "cli.png", "--set", "image.width=80",
                    "--set", "image.height=60", "--set", "image.transparent=false")
    assert code == 0, err
    png = (tmp_path / "py.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert png == (tmp_path / "cli.png").read_bytes()
    assert image._repr_png_() == png


def test_errors_are_the_command_lines(tmp_path):
    scene = re.Scene.load(LATTICE)
    with pytest.raises(ValueError) as e:
        scene.set("group.lattice.velocity", [2, 0, 0])
    code, err = cli("render", LATTICE, "-o", tmp_path / "x.png", "--set", "group.lattice.velocity=[2, 0, 0]")
    assert code == 1
    assert str(e.value) in err, (str(e.value), err)
    # The scene is as it was.
    assert scene.velocities["lattice"] == [0.0, 0.0, 0.0]
    with pytest.raises(ValueError) as e:
        scene.set("group.nothing.velocity", [0.1, 0, 0])
    assert "nothing" in str(e.value)
    bad = tmp_path / "bad.toml"
    bad.write_text("[camera]\nposition = [0, 0, 0]\n")
    with pytest.raises(ValueError) as e:
        re.Scene.load(bad)
    code, err = cli("render", bad, "-o", tmp_path / "x.png")
    assert code == 1 and str(e.value) in err and "bad.toml:1" in str(e.value)
    with pytest.raises(ValueError, match="scene.toml:2"):
        re.Scene.from_toml("[camera]\nposition = [0, 0, nan]\nlook_at = [0, 1, 0]\n")
    with pytest.raises(OSError):
        re.read_exr(tmp_path / "none.exr")
    with pytest.raises(OSError, match="none.toml"):
        re.Scene.load(tmp_path / "none.toml")
    with pytest.raises(OSError):
        re.Scene.load(tmp_path)
    with pytest.raises(ValueError, match="backend"):
        re.render(re.Scene.from_dict(CUBE), backend="nope")
    with pytest.raises(TypeError):
        re.Scene.from_dict({"camera": {"position": object()}})
    # Arguments of the wrong kind say which, before any render.
    cube = re.Scene.from_dict(CUBE)
    with pytest.raises(TypeError, match="passes must be True"):
        re.render(cube, width=8, height=8, passes="depth")
    with pytest.raises(TypeError, match="progress"):
        re.render(cube, width=8, height=8, progress=5)
    with pytest.raises(ValueError, match="threads"):
        re.render(cube, width=8, height=8, threads=-1)
    with pytest.raises(ValueError, match="port"):
        re.view(cube, port=-1)
    plain = re.render(cube, width=8, height=8, passes=False)
    with pytest.raises(KeyError, match="passes=False"):
        plain["depth"]
    with pytest.raises(TypeError, match="x must be a whole pixel"):
        re.probe(cube, 3.7, 5, image=plain)
    with pytest.raises(TypeError, match="image must be an Image"):
        re.probe(cube, 3, 5, image=5)
    # save makes the folders of its path, as the command line's -o does.
    plain.save(tmp_path / "new" / "dir" / "x.png")
    assert (tmp_path / "new" / "dir" / "x.png").stat().st_size > 0


def test_scenes_from_dicts_and_text_are_the_files():
    a = re.render(re.Scene.from_dict(CUBE))
    b = re.render(re.Scene.from_toml(re.to_toml(CUBE)))
    assert np.array_equal(a.rgba, b.rgba)
    assert a.rgba[..., 3].sum() > 50
    s = re.Scene.from_dict(CUBE)
    assert s.size == (64, 48) and s.groups == ["cube"] and s.time == 10.0
    assert s.objects == [(None, "box", "cube")] and s.materials[1] == "white"
    # A worldline, inline tables and strings with quotes survive the trip.
    d = dict(CUBE, group=[dict(CUBE["group"][0], worldline=[{"until": 5, "velocity": [0.5, 0, 0]},
                                                            {"velocity": [-0.5, 0, 0]}])])
    del d["group"][0]["velocity"]
    d["light"] = [{"position": [0, 0, 20]}]
    v = re.Scene.from_dict(d).velocities["cube"]
    assert abs(abs(v[0]) - 0.5) < 1e-12 and v[1:] == [0.0, 0.0], v


def test_threads_progress_and_seeds():
    scene = re.Scene.from_dict(CUBE)
    one = re.render(scene, threads=1, samples=4)
    two = re.render(scene, threads=2, samples=4)
    assert np.array_equal(one.rgba, two.rgba)
    seen = []
    re.render(scene, width=256, height=192, progress=lambda d, t: seen.append((d, t)))
    assert seen and seen[-1] == (256 * 192, 256 * 192)
    assert all(a[0] <= b[0] for a, b in zip(seen, seen[1:]))
    # A progress callback that raises stops the render with its exception.
    def boom(d, t):
        raise RuntimeError("stop here")
    with pytest.raises(RuntimeError, match="stop here"):
        re.render(scene, width=256, height=192, progress=boom)
    # The command line's limit on threads, at once (a million took minutes to start).
    with pytest.raises(ValueError, match="threads=1000000: .* per core"):
        re.render(scene, width=8, height=8, threads=10**6)


def test_ctrl_c_stops_a_render():
    import _thread

    scene = re.Scene.load(LATTICE).set("group.lattice.velocity", [-0.9, 0, 0])
    # Started as a background job (`make test &`), the interpreter inherits SIGINT ignored,
    # and then interrupt_main does nothing: Python's own handler is put back for the test.
    old_handler = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.3, _thread.interrupt_main)
    try:
        start = time.monotonic()
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            re.render(scene, width=2048, height=2048, samples=16)
        took = time.monotonic() - start
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, old_handler)
    assert took < 10, f"stopped after {took:.1f} s"
    # And the next render runs.
    assert re.render(scene, width=32, height=32).width == 32


def rss_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def test_no_leak_over_200_renders():
    scene = re.Scene.from_dict(CUBE)
    for _ in range(20):
        re.render(scene).rgba
    before = rss_mb()
    for _ in range(200):
        img = re.render(scene)
        img.rgba, img["doppler"], img["object_id"]
    grown = rss_mb() - before
    assert grown < 20, f"RSS grew {grown:.1f} MB over 200 renders"


def test_a_film_yields_its_frames_and_probe_tells_a_pixel():
    d = dict(CUBE, film={"start": 9, "end": 11, "fps": 1})
    scene = re.Scene.from_dict(d)
    assert scene.frame_count == 3
    frames = list(re.film(scene, width=32, height=24))
    assert [t for t, _ in frames] == [9.0, 10.0, 11.0]
    assert all(img.width == 32 for _, img in frames)
    # The box moves along +x between frames: its pixels shift.
    xs = [np.argwhere(img["object_id"] > 0)[:, 1].mean() for _, img in frames]
    assert xs[0] < xs[1] < xs[2], xs
    with pytest.raises(ValueError, match="film"):
        next(re.film(re.Scene.from_dict(CUBE)))
    scene = re.Scene.from_dict(CUBE)
    img = re.render(scene)
    p = re.probe(scene, 32, 24, image=img)
    assert p["hit"] and p["object_id"] == 1 and p["group"] == "cube" and p["kind"] == "box"
    assert abs(p["emission"]["t"] - (10 - p["lookback"])) < 1e-9
    assert abs(p["lookback"] - 9.0) < 1.0 and p["doppler"] > 0
    assert re.probe(scene, 0, 0, image=img) == {"hit": False, "pixel": [0, 0]}
    with pytest.raises(ValueError):
        re.probe(scene, 999, 0, image=img)


def test_the_viewer_serves_the_scene_with_its_overrides(capfd):
    import json
    import urllib.error
    import urllib.request
    from urllib.parse import parse_qs, urlparse

    scene = re.Scene.load(LATTICE).set("group.lattice.velocity", [-0.5, 0, 0])
    viewer = re.view(scene)
    try:
        u = urlparse(viewer.url)
        token = parse_qs(u.query)["token"][0]
        base = f"{u.scheme}://{u.netloc}"
        assert "<iframe" in viewer._repr_html_() and token in viewer._repr_html_()
        info = json.load(urllib.request.urlopen(f"{base}/api/scene?token={token}"))
        text = json.dumps(info)
        assert "lattice" in text and "0.5" in text, text
        with pytest.raises(urllib.error.HTTPError) as e:
            urllib.request.urlopen(f"{base}/api/scene")
        assert e.value.code == 403
        with pytest.raises(RuntimeError, match="already"):
            re.view(scene)
    finally:
        viewer.stop()
    # It said where it served (before serving the requests above), but not "Ctrl-C stops
    # it": here .stop() does.
    said = capfd.readouterr()
    assert viewer.url in said.out and "Ctrl-C" not in said.out + said.err, said
    # Stopped, another starts: a scene given as a dict (its text served, named scene.toml).
    again = re.view(re.Scene.from_dict(CUBE))
    try:
        u = urlparse(again.url)
        token = parse_qs(u.query)["token"][0]
        info = json.load(urllib.request.urlopen(f"{u.scheme}://{u.netloc}/api/scene?token={token}"))
        assert "cube" in json.dumps(info)
    finally:
        again.stop()
    # A stop with none running does nothing.
    again.stop()


def test_the_notebook_runs(tmp_path):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.read(ROOT / "examples" / "relativity.ipynb", as_version=4)
    assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code"), "outputs stripped"
    client = nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                                     resources={"metadata": {"path": str(ROOT)}})
    client.execute()
    text = "".join(o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.outputs)
    assert "closed form" in text, text


def test_the_readmes_example_runs(tmp_path):
    """The README's "From Python" snippet as written, in a folder with the project's scenes."""
    text = (ROOT / "README.md").read_text()
    part = text[text.index("## From Python"):]
    code = part[part.index("```python") + len("```python"):]
    code = code[:code.index("```")]
    (tmp_path / "scenes").symlink_to(ROOT / "scenes")
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        exec(compile(code, "README.md", "exec"), {})
    finally:
        os.chdir(cwd)
    assert (tmp_path / "lattice.exr").stat().st_size > 0
