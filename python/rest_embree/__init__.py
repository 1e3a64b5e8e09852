"""rest-embree from Python: special-relativistic renders as NumPy arrays.

A camera records what a scene moving at a large fraction of the speed of light looks like:
light that left each object on the camera's past light cone, seen Doppler-shifted and
aberrated (Hsiung & Dunn's REST-frame algorithm). Scenes are the command line's TOML files,
TOML text, or Python dicts of the same tables; ``scene.set`` is the command line's ``--set``.

>>> import rest_embree as re
>>> scene = re.Scene.load("scenes/lattice.toml")
>>> scene.set("group.lattice.velocity", [-0.9, 0, 0])
>>> image = re.render(scene, width=320, height=240)
>>> image.rgba.shape, image["doppler"].max()
((240, 320, 4), ...)
>>> image.save("lattice.exr")          # every pass, as `rest-embree render` writes it

A bad scene, key or value raises ``ValueError`` with the command line's message (file, line,
key); a file that cannot be read or written raises ``OSError``.
"""

from __future__ import annotations

import json
import math
import os
import sys
import tempfile
from typing import Any, Callable, Iterator, Optional

import numpy as np

from . import _native

__version__: str = _native.__version__

__all__ = ["Scene", "Image", "Viewer", "render", "film", "probe", "view", "read_exr", "backends",
           "to_toml"]


def backends() -> list:
    """The backends this build has, the default first (``"embree"``, ``"bvh"``)."""
    return list(_native.backends())


# --- TOML text from Python values --------------------------------------------------------


def _literal(v: Any) -> str:
    """A TOML value: numbers, booleans, strings, lists and dicts (inline), NumPy arrays."""
    if hasattr(v, "tolist") and not isinstance(v, (str, bytes)):
        v = v.tolist()
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        # TOML's basic strings take JSON's escapes; DEL, which JSON leaves as it is, too.
        return json.dumps(v, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_literal(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_literal(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {type(v).__name__} {v!r} as a scene value")


def _key(k: Any) -> str:
    if not isinstance(k, str):
        raise TypeError(f"scene keys are strings, not {type(k).__name__} {k!r}")
    # TOML's bare keys are ASCII letters, digits, _ and -.
    bare = k and all((c.isascii() and c.isalnum()) or c in "_-" for c in k)
    return k if bare else json.dumps(k)


def _is_tables(v: Any) -> bool:
    return isinstance(v, (list, tuple)) and len(v) > 0 and all(isinstance(x, dict) for x in v)


def to_toml(d: dict) -> str:
    """A scene dict as TOML text: top-level dicts as ``[table]``, lists of dicts as
    ``[[table]]``, everything below them inline."""
    if not isinstance(d, dict):
        raise TypeError(f"a scene is a dict of tables, not {type(d).__name__}")
    lines = []
    for k, v in d.items():
        if not isinstance(v, dict) and not _is_tables(v):
            lines.append(f"{_key(k)} = {_literal(v)}")
    for k, v in d.items():
        if isinstance(v, dict):
            lines.append(f"\n[{_key(k)}]")
            lines.extend(f"{_key(a)} = {_literal(b)}" for a, b in v.items())
        elif _is_tables(v):
            for t in v:
                lines.append(f"\n[[{_key(k)}]]")
                lines.extend(f"{_key(a)} = {_literal(b)}" for a, b in t.items())
    return "\n".join(lines) + "\n"


# --- Scenes --------------------------------------------------------------------------------


class Scene:
    """A scene: a TOML file, text or dict, with ``--set`` overrides on top.

    Build one with :meth:`Scene.load`, :meth:`Scene.from_toml` or :meth:`Scene.from_dict`;
    change it with :meth:`set`. Relative file paths in the scene (meshes, textures, glTF)
    lead from the scene file's folder (for text and dicts, from ``path``'s).
    """

    def __init__(self, native, path: Optional[str], text: Optional[str], sets: list):
        self._native = native
        self._path = path
        self._text = text
        self._sets = list(sets)

    @classmethod
    def load(cls, path: "os.PathLike | str") -> "Scene":
        """The scene file at ``path``."""
        path = os.fspath(path)
        return cls(_native.load(path, []), path, None, [])

    @classmethod
    def from_toml(cls, text: str, path: str = "scene.toml") -> "Scene":
        """A scene from TOML text; errors name ``path`` and the line."""
        return cls(_native.load_str(path, text, []), path, text, [])

    @classmethod
    def from_dict(cls, d: dict, path: str = "scene.toml") -> "Scene":
        """A scene from a dict of its tables, as the TOML file has them::

            Scene.from_dict({
                "camera": {"position": [0, 0, 0], "look_at": [0, 10, 0], "time": 10},
                "light": [{"position": [0, 0, 20]}],
                "group": [{"name": "cube", "velocity": [0.9, 0, 0],
                           "object": [{"type": "box", "min": [-1, 9, -1], "max": [1, 11, 1]}]}],
            })
        """
        return cls.from_toml(to_toml(d), path)

    def _reload(self, sets: list):
        if self._text is None:
            return _native.load(self._path, sets)
        return _native.load_str(self._path, self._text, sets)

    def set(self, key: str, value: Any) -> "Scene":
        """Set ``key`` (``"group.cube.velocity"``, ``"image.width"``,
        ``"group.cube.object.0.radius"``) to ``value``, as ``--set key=value`` does; returns
        the scene. A bad key or value raises ``ValueError`` and leaves the scene as it was."""
        assignment = f"{key}={_literal(value)}"
        # Shown as the command line shows an override, so that errors read as its do.
        sets = self._sets + [(f"--set {assignment}", assignment)]
        self._native = self._reload(sets)
        self._sets = sets
        return self

    def copy(self) -> "Scene":
        """An independent copy (its own overrides)."""
        return Scene(self._native, self._path, self._text, self._sets)

    @property
    def size(self) -> tuple:
        """(width, height) of the image."""
        return tuple(self._native.size)

    @property
    def time(self) -> float:
        """The camera's view time."""
        return self._native.time

    @property
    def camera(self) -> dict:
        """The camera at its imaging event: ``position`` (world frame), ``right``, ``up`` and
        ``forward`` (unit axes)."""
        return dict(zip(("position", "right", "up", "forward"), self._native.camera))

    @property
    def groups(self) -> list:
        """The velocity groups' names."""
        return list(self._native.groups)

    @property
    def velocities(self) -> dict:
        """Each group's velocity in units of c, by name."""
        return dict(zip(self._native.groups, self._native.velocities))

    @property
    def objects(self) -> list:
        """Every object as (name, kind, group name); ``object_id - 1`` indexes it."""
        groups = self._native.groups
        return [(n, k, groups[g]) for n, k, g in self._native.objects]

    @property
    def materials(self) -> list:
        """The materials' names; ``material_id - 1`` indexes them."""
        return list(self._native.materials)

    @property
    def frame_count(self) -> int:
        """Frames in the scene's film (0: a still)."""
        return self._native.frame_count

    @property
    def warnings(self) -> list:
        """What the scene's files hold that it does not take (a glTF's unmapped extensions)."""
        return list(self._native.warnings)

    def __repr__(self) -> str:
        w, h = self.size
        where = self._path if self._text is None else f"text ({self._path})"
        return f"<rest_embree.Scene {where}: {w}x{h}, groups {self.groups}, view time {self.time}>"


# --- Images --------------------------------------------------------------------------------

_VECTORS = {"normal": "N", "position": "P", "rest_position": "Pref", "camera_position": "Pcam"}
_IDS = ("object_id", "material_id", "primitive_id")


class Image:
    """A rendered frame. ``image.rgba`` is linear RGBA (H, W, 4) float32; ``image[name]`` a
    pass: ``"lookback"``, ``"doppler"``, ``"depth"`` (H, W) float32, ``"object_id"``,
    ``"material_id"``, ``"primitive_id"`` (H, W) uint32, ``"normal"``, ``"position"``,
    ``"rest_position"``, ``"camera_position"`` (H, W, 3) float32, or any EXR channel name
    (``"lookback.V"``, ``"N.X"``). ``image.facts`` says what it ran on and how long it took.
    In a notebook it shows itself."""

    def __init__(self, native, scene: "Scene | _native.Scene", passes: bool = True):
        self._native = native
        self.passes: bool = passes
        self.width: int = native.width
        self.height: int = native.height
        self.facts: dict = dict(native.facts())
        self.time: float = (scene._native if isinstance(scene, Scene) else scene).time

    def _plane(self, channel: str) -> np.ndarray:
        data = self._native.channel(channel)
        if data is None:
            raise KeyError(f"no pass {channel!r}")
        return np.frombuffer(data, dtype="<f4").reshape(self.height, self.width)

    @property
    def rgba(self) -> np.ndarray:
        """Linear (not sRGB-encoded) RGBA, float32, shape (height, width, 4)."""
        return np.frombuffer(self._native.rgba(), dtype="<f4").reshape(self.height, self.width, 4)

    def __getitem__(self, name: str) -> np.ndarray:
        if not self.passes and name != "rgba":
            raise KeyError(f"{name!r}: the image was rendered with passes=False (colour and alpha alone; see .rgba)")
        if name in _IDS:
            data = self._native.ids(name)
            return np.frombuffer(data, dtype="<u4").reshape(self.height, self.width)
        if name in _VECTORS:
            p = _VECTORS[name]
            return np.stack([self._plane(f"{p}.{a}") for a in "XYZ"], axis=-1)
        if name == "depth":
            return self._plane("Z")
        if name in ("lookback", "doppler"):
            return self._plane(f"{name}.V")
        return self._plane(name)

    def keys(self) -> list:
        """The passes ``image[...]`` takes by name."""
        return ["lookback", "doppler", "depth", *_IDS, *_VECTORS]

    def save(self, path: "os.PathLike | str") -> None:
        """Write it as ``rest-embree render`` writes its file, byte for byte for the same scene
        and overrides: ``.exr`` with every pass, ``.png`` colour (alpha only for a transparent
        scene)."""
        path = os.fspath(path)
        # Into a folder that does not exist yet, as the command line's `-o` does.
        folder = os.path.dirname(path)
        if folder:
            os.makedirs(folder, exist_ok=True)
        self._native.save(path)

    def _repr_png_(self) -> bytes:
        with tempfile.TemporaryDirectory() as d:
            p = os.path.join(d, "image.png")
            self._native.save(p)
            with open(p, "rb") as f:
                return f.read()

    def __repr__(self) -> str:
        return f"<rest_embree.Image {self.width}x{self.height} at view time {self.time}, {self.facts['backend']}>"


# --- Rendering -----------------------------------------------------------------------------


def _progress_callback(progress) -> Optional[Callable]:
    if progress is None or progress is False:
        return None
    if callable(progress):
        return progress
    if progress is not True:
        raise TypeError(f"progress must be a callable f(done, total), True or None, not {type(progress).__name__}")
    try:
        from tqdm.auto import tqdm
    except ImportError:
        tqdm = None
    if tqdm is not None:
        bar = {}

        def tick(done, total):
            if "b" not in bar:
                bar["b"] = tqdm(total=total, unit="px", unit_scale=True, desc="rendering")
            bar["b"].update(done - bar["b"].n)
            if done >= total:
                bar["b"].close()

        return tick

    def say(done, total):
        print(f"\rrendering {100 * done // max(total, 1):3d}%", end="\n" if done >= total else "", file=sys.stderr)

    return say


def _with(scene: Scene, **values) -> Scene:
    s = scene
    for key, v in values.items():
        if v is not None:
            if s is scene:
                s = scene.copy()
            s.set(key, v)
    return s


def _check_flags(passes: Any, threads: Any) -> None:
    if not isinstance(passes, bool):
        raise TypeError(
            f"passes must be True (every pass) or False (colour and alpha), not {passes!r}; "
            "a list of passes is the scene's [image] passes: scene.set(\"image.passes\", [...])")
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 0:
        raise ValueError(f"threads must be a whole number, 0 (every core) or more, not {threads!r}")


def render(
    scene: Scene,
    width: Optional[int] = None,
    height: Optional[int] = None,
    samples: Optional[int] = None,
    backend: Optional[str] = None,
    passes: bool = True,
    threads: int = 0,
    seed: Optional[int] = None,
    progress: Any = None,
    transparent: Optional[bool] = None,
) -> Image:
    """Render ``scene`` and return the :class:`Image`.

    ``width``, ``height``, ``samples`` and ``seed`` override the scene's ``[image]`` and
    ``[render]`` values (as ``--set`` would); ``backend`` is ``"embree"`` (default) or
    ``"bvh"``; ``passes=False`` fills colour and alpha only; ``threads=0`` uses every core.
    ``progress`` is a callable ``f(pixels_done, pixels)``, or ``True`` for a tqdm bar (a
    percentage without tqdm). ``transparent`` overrides ``image.transparent``: a scene that
    leaves it unset renders transparent where nothing is hit (as the command's EXR); give
    ``transparent=False`` for the command's opaque PNG (the background composited). The GIL is released while it renders; Ctrl-C stops it after the
    strip in hand and raises ``KeyboardInterrupt``.
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"render takes a Scene, not {type(scene).__name__}")
    _check_flags(passes, threads)
    s = _with(scene, **{"image.width": width, "image.height": height,
                         "image.samples": samples, "render.seed": seed,
                         "image.transparent": transparent})
    native = _native.render(s._native, backend, threads, passes, _progress_callback(progress))
    return Image(native, s, passes)


def film(scene: Scene, **kwargs) -> Iterator[tuple]:
    """The frames of the scene's ``[film]``, rendered one by one: yields (view time, Image).
    Takes :func:`render`'s keywords."""
    width, height, samples, seed, transparent = (
        kwargs.pop(k, None) for k in ("width", "height", "samples", "seed", "transparent"))
    s = _with(scene, **{"image.width": width, "image.height": height,
                         "image.samples": samples, "render.seed": seed,
                         "image.transparent": transparent})
    n = s.frame_count
    if n == 0:
        raise ValueError("the scene has no [film] (give it start, end and fps or step)")
    progress = kwargs.pop("progress", None)
    backend = kwargs.pop("backend", None)
    threads = kwargs.pop("threads", 0)
    passes = kwargs.pop("passes", True)
    if kwargs:
        raise TypeError(f"film() got unexpected keywords {sorted(kwargs)}")
    _check_flags(passes, threads)
    for k in range(n):
        frame = s._native.film_frame(k)
        native = _native.render(frame, backend, threads, passes, _progress_callback(progress))
        yield frame.time, Image(native, frame, passes)


def probe(scene: Scene, x: int, y: int, image: Optional[Image] = None, **kwargs) -> dict:
    """What pixel (x, y) of the scene's image shows, as the viewer's click tells it: the object
    and its group, the emission event (world time and place), lookback, Doppler factor, depth
    and the point on the object in its rest frame. Renders the scene (with :func:`render`'s
    keywords) unless ``image`` is given."""
    for name, v in (("x", x), ("y", y)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
            raise TypeError(f"{name} must be a whole pixel number, not {v!r}")
    if image is not None and not isinstance(image, Image):
        raise TypeError(f"image must be an Image from render(), not {type(image).__name__}")
    img = image if image is not None else render(scene, **kwargs)
    if not img.passes:
        raise ValueError("the image was rendered with passes=False: it has no ids or lookback to probe")
    if not (0 <= x < img.width and 0 <= y < img.height):
        raise ValueError(f"pixel ({x}, {y}) is outside the {img.width}x{img.height} image")
    oid = int(img["object_id"][y, x])
    if oid == 0:
        return {"hit": False, "pixel": [x, y]}
    objects = scene.objects
    name, kind, group = objects[oid - 1]
    lookback = float(img["lookback"][y, x])
    return {
        "hit": True,
        "pixel": [x, y],
        "object": name,
        "kind": kind,
        "group": group,
        "object_id": oid,
        "emission": {"t": img.time - lookback, "x": img["position"][y, x].tolist()},
        "lookback": lookback,
        "doppler": float(img["doppler"][y, x]),
        "depth": float(img["depth"][y, x]),
        "rest_position": img["rest_position"][y, x].tolist(),
    }


class Viewer:
    """The viewer (``rest-embree view``, docs/viewer.md) serving a scene from this process: its
    page is at ``url`` (token included; without it the server answers nothing). In a notebook
    it shows itself in an IFrame. ``stop()`` ends it; one runs at a time."""

    def __init__(self, url: str):
        self.url = url

    def stop(self) -> None:
        """Stop serving (renders in flight are cancelled)."""
        _native.view_stop()

    def _repr_html_(self) -> str:
        import html

        src = html.escape(self.url, quote=True)
        return f'<iframe src="{src}" width="100%" height="720" style="border: 0"></iframe>'

    def __repr__(self) -> str:
        return f"<rest_embree.Viewer at {self.url}>"


def view(scene: Scene, port: int = 0, backend: Optional[str] = None) -> Viewer:
    """Serve ``scene`` (with its ``set`` overrides) in the viewer on 127.0.0.1:``port`` (0: a
    free one) from a thread of this process, and return the :class:`Viewer`; in Jupyter the
    returned object shows the page. Its saved views and renders go to the current folder."""
    if not isinstance(scene, Scene):
        raise TypeError(f"view takes a Scene, not {type(scene).__name__}")
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise ValueError(f"port must be 0 (a free one) to 65535, not {port!r}")
    return Viewer(_native.view_start(scene._path, scene._text, scene._sets, port, backend))


def read_exr(path: "os.PathLike | str") -> dict:
    """Every channel of an EXR file's first layer, by name, as (H, W) float32 arrays."""
    w, h, channels = _native.read_exr(os.fspath(path))
    return {k: np.frombuffer(v, dtype="<f4").reshape(h, w) for k, v in channels.items()}
