"""rastergi: global illumination on the GPU with photon maps and a rasterized final gather.

Render a scene into a numpy array of linear radiance, compare images, and drive a
progressive renderer from Python::

    import rastergi
    image = rastergi.render("cornell", width=128, height=128, iterations=64, seed=1)
    reference = rastergi.read_image("reference.exr")
    print(rastergi.compare(image, reference).relative_rmse)

The keyword options are those of ``rastergi render`` on the command line, with ``_`` for
``-`` (``gather_directions=`` for ``--gather-directions``); vectors are sequences
(``eye=(0, 0, 3.9)``), repeatable options take a list (``point=[(0, 1, 0, 5, 5, 5)]``).
They are parsed by the command line's own parser, so their defaults, checks and messages are
the command line's, and the same options give the same image as ``rastergi render``, bit for
bit. Errors raise ``TypeError`` (an unknown option), ``ValueError`` (a value the option does
not allow), ``FileNotFoundError`` (a scene or image file that does not exist) or
``RastergiError`` (anything else rastergi refuses or fails at: a scene it cannot load, the
GPU), with the command line's message. The interpreter's lock is released while rendering,
and Ctrl-C interrupts a render between iterations.
"""

from __future__ import annotations

import difflib
import os
import tempfile
from dataclasses import dataclass
from typing import Any, Generic, NamedTuple, Optional, Sequence, Tuple, TypeVar, Union

import numpy as np

from . import _rastergi
from ._rastergi import RastergiError, __version__

__all__ = [
    "Camera",
    "Comparison",
    "RastergiError",
    "Renderer",
    "compare",
    "options",
    "read_image",
    "render",
    "write_image",
    "__version__",
]

ImageLike = Union[np.ndarray, str, "os.PathLike[str]"]
Vec3 = Tuple[float, float, float]


def _quiet_wayland_probe() -> None:
    # Mesa's Vulkan drivers probe Wayland when they start and, where XDG_RUNTIME_DIR is unset
    # (root shells, CI, containers), print "error: XDG_RUNTIME_DIR is invalid" lines that look
    # like rastergi's errors. As the command line does, point it at a private directory.
    if "XDG_RUNTIME_DIR" in os.environ:
        return
    path = os.path.join(tempfile.gettempdir(), "rastergi-runtime")
    try:
        os.makedirs(path, exist_ok=True)
        os.chmod(path, 0o700)
    except OSError:
        return
    os.environ["XDG_RUNTIME_DIR"] = path


_quiet_wayland_probe()

# name (with "_") -> (the command line's option, takes a value, repeatable)
_OPTIONS = {
    long.replace("-", "_"): (f"--{long}", takes_value, repeatable)
    for long, takes_value, repeatable in _rastergi.options()
}
# Given as arguments of their own, not as keyword options.
_ARGUMENTS = ("width", "height", "iterations")


def options() -> list:
    """The keyword options ``render`` takes (``Renderer`` takes them all but ``iterations``)."""
    return sorted(_OPTIONS)


def _is_vector(value: Any) -> bool:
    if isinstance(value, (str, bytes)) or hasattr(value, "__fspath__"):
        return False
    if isinstance(value, np.ndarray):
        return value.ndim >= 1
    return isinstance(value, Sequence)


def _text(value: Any) -> str:
    """One option value as the command line writes it."""
    if hasattr(value, "__fspath__"):
        return os.fspath(value)
    if isinstance(value, np.generic):
        value = value.item()
    if _is_vector(value):
        return ",".join(_text(v) for v in value)
    return str(value)


def _argv(where: str, scene: Any, options: dict, allowed) -> list:
    """The command line of ``rastergi render`` for these options."""
    argv = []
    for name, value in options.items():
        if name not in allowed:
            close = difflib.get_close_matches(name, allowed, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else f"; the options are: {', '.join(sorted(allowed))}"
            raise TypeError(f"{where}() got an unexpected keyword argument '{name}'{hint}")
        if value is None:
            continue
        flag, takes_value, repeatable = _OPTIONS[name]
        if not takes_value:
            if value is True:
                argv.append(flag)
            elif value is not False:
                raise TypeError(f"{where}(): '{name}' is a flag: give True or False")
            continue
        # --name=value: a value may start with "-" (a negative number).
        if repeatable and _is_vector(value) and len(value) > 0 and all(_is_vector(v) for v in value):
            argv += [f"{flag}={_text(v)}" for v in value]
        else:
            argv.append(f"{flag}={_text(value)}")
    # After "--" the scene is the scene even where it starts with "-".
    return argv + ["--", os.fspath(scene) if hasattr(scene, "__fspath__") else str(scene)]


def render(scene: Union[str, "os.PathLike[str]"], width: int = 256, height: int = 256, iterations: int = 256,
           **options: Any) -> np.ndarray:
    """Renders ``scene`` as ``rastergi render`` does and returns the image.

    ``scene`` is a built-in scene (``"cornell"``, ``"atrium"``, ``"spheres:N"``, ...) or the path
    of a .obj, .gltf or .glb file. The options are those of ``rastergi render`` (see the module's
    documentation and :func:`options`): ``seed``, ``photons``, ``grid``, ``gather``
    (``"auto"``, ``"raster"``, ``"lists"``, ``"trace"``; ``auto`` chooses by timing, so give
    another for images that repeat bit for bit), ``gather_directions``, ``directions``,
    ``hit_light``, ``show`` (``"full"``, ``"direct"``, ``"indirect"``, ``"photon-map"``),
    ``eye``, ``target``, ``up``, ``fov``, ``camera``, ``sun``, ``sun_size``, ``sky``, ``point``, ``spot``,
    ``env``, ``env_scale``, ``light_samples`` (a count, or ``"balanced"``, the default, which
    follows timings), ``emitter_edges`` (sub-pixel rays per axis for the emission at emitters'
    edges, 0 to 16; 0: off), ``photon_passes``, ``pass_iterations``,
    ``photon_budget`` (``"balanced"``, which follows timings, or ``"fitted"``, which repeats bit
    for bit), ``photon_guiding``, ``gather_guiding`` and ``sky_guiding`` (``"on"`` or ``"off"``),
    ``bundle``, ``backend``, ``rays`` (``"auto"``, ``"hardware"``, ``"compute"``: hardware ray
    queries or the compute-shader BVH), ``method`` (``"gather"`` or ``"path"``, the reference path
    tracer) and ``denoise`` (``True``: the image denoised as ``rastergi render --denoise``
    writes it; gather method, full image).

    Returns a float32 array of shape (height, width, 3): linear RGB radiance, row 0 at the top.
    """
    argv = _argv("render", scene, options, _OPTIONS.keys() - set(_ARGUMENTS))
    argv = [f"--width={_text(width)}", f"--height={_text(height)}", f"--iterations={_text(iterations)}"] + argv
    return _rastergi.render(argv)


class Camera(NamedTuple):
    """A pinhole camera: position, the point it looks at, its up vector, vertical fov (degrees)."""

    eye: Vec3
    target: Vec3
    up: Vec3
    fov: float


def _vec3(name: str, value: Any) -> Vec3:
    try:
        v = tuple(float(x) for x in value)
    except TypeError:
        raise TypeError(f"{name} must be a sequence of three numbers, got {value!r}") from None
    if len(v) != 3:
        raise ValueError(f"{name} must be three numbers (x, y, z), got {len(v)}")
    return v  # type: ignore[return-value]


T = TypeVar("T")


class _Native(Generic[T]):
    """A read-only attribute of :class:`Renderer`, typed ``T``, that is its native renderer's
    attribute of the same name (as a ``property`` returning ``self._native.<name>``)."""

    def __init__(self, doc: Optional[str] = None) -> None:
        self.__doc__ = doc

    def __set_name__(self, owner: type, name: str) -> None:
        self._name = name

    def __get__(self, obj: Any, owner: Optional[type] = None) -> T:
        if obj is None:  # looked up on the class, as a property returns itself
            return self  # type: ignore[return-value]
        return getattr(obj._native, self._name)

    def __set__(self, obj: Any, value: Any) -> None:
        raise AttributeError(f"property '{self._name}' of '{type(obj).__name__}' object has no setter")

    def __delete__(self, obj: Any) -> None:
        raise AttributeError(f"property '{self._name}' of '{type(obj).__name__}' object has no deleter")


class Renderer:
    """A progressive renderer: its scene, photon map and image stay between calls.

    ``Renderer(scene, width=256, height=256, **options)`` takes the options of :func:`render`
    (all but ``iterations``), loads the scene and traces the photon map. Each
    :meth:`iterate` adds one sample per pixel; :meth:`image` is their mean so far. The
    same options and iterations give the image :func:`render` and ``rastergi render`` give.
    """

    def __init__(self, scene: Union[str, "os.PathLike[str]"], width: int = 256, height: int = 256,
                 **options: Any) -> None:
        argv = _argv("Renderer", scene, options, _OPTIONS.keys() - set(_ARGUMENTS))
        argv = [f"--width={_text(width)}", f"--height={_text(height)}"] + argv
        self._native = _rastergi.Renderer(argv)

    def iterate(self, n: int = 1) -> "Renderer":
        """Runs ``n`` more iterations (one sample per pixel each); returns the renderer."""
        if n < 0:
            raise ValueError(f"iterate needs a number of iterations >= 0, got {n}")
        self._native.iterate(int(n))
        return self

    def image(self, show: Optional[str] = None) -> np.ndarray:
        """The mean radiance so far, float32 (height, width, 3), linear RGB.

        ``show``: ``"full"``, ``"direct"``, ``"indirect"`` or ``"photon-map"`` (the last only
        for a renderer made with ``show="photon-map"``); default: the renderer's ``show``.
        """
        return self._native.image(show)

    def set_camera(self, eye: Sequence[float], target: Sequence[float], up: Optional[Sequence[float]] = None,
                   fov: Optional[float] = None) -> None:
        """Moves the camera (``up`` and ``fov``, in degrees, default to the current ones).

        The image restarts (``samples`` is 0 again); the scene and photon map are kept.
        """
        self._native.set_camera(_vec3("eye", eye), _vec3("target", target),
                                None if up is None else _vec3("up", up), None if fov is None else float(fov))

    def reset(self) -> None:
        """Discards the iterations so far."""
        self._native.reset()

    samples = _Native[int]("""Iterations in the image: since the renderer was made or its camera last changed.""")

    @property
    def camera(self) -> Camera:
        """The camera."""
        eye, target, up, fov = self._native.camera
        return Camera(eye, target, up, fov)

    error_estimate = _Native[Optional[float]](
        """The image's relative RMSE estimated without a reference, from two independent
        halves of the iterations (as ``rastergi render --target-error``); None before there
        are enough.""")
    width = _Native[int]()
    height = _Native[int]()
    method = _Native[str]("""``"gather"`` or ``"path"``.""")
    show = _Native[str]("""What :meth:`image` shows by default.""")

    def __repr__(self) -> str:
        return f"<rastergi.Renderer {self.width}x{self.height} method={self.method} samples={self.samples}>"


@dataclass(frozen=True)
class Comparison:
    """How an image differs from a reference: the numbers ``rastergi compare`` prints."""

    relative_rmse: float
    """sqrt(mean((image - reference)^2)) / mean(reference), over the compared pixels and channels."""
    block_mean_error: float
    """Mean |difference of 16x16-block means| / mean(reference): noise averages out, bias remains."""
    psnr: float
    """10 log10(peak^2 / mean squared error) in dB, the peak the reference's maximum; inf if equal."""
    mean_ratio: Tuple[float, float, float]
    """mean(image) / mean(reference) per channel."""
    rmse: float
    """The absolute RMSE, linear units."""
    reference_mean: float
    """The reference's mean over the compared pixels."""
    peak: float
    """The reference's maximum over the compared pixels (the PSNR's peak)."""
    compared_pixels: int
    total_pixels: int


def _image_for_compare(value: ImageLike, name: str) -> Tuple[np.ndarray, str]:
    if isinstance(value, (str, bytes)) or hasattr(value, "__fspath__"):
        path = os.fsdecode(os.fspath(value))
        return read_image(path), path
    return _array(value, name), name


def _array(value: Any, name: str) -> np.ndarray:
    array = np.ascontiguousarray(value, dtype=np.float32)
    if array.ndim != 3 or array.shape[2] != 3:
        raise ValueError(f"{name} must be an array of shape (height, width, 3), got shape {array.shape}")
    return array


def compare(image: ImageLike, reference: ImageLike, mask_emitters: Union[None, bool, float] = None) -> Comparison:
    """Compares ``image`` with ``reference`` as ``rastergi compare`` does.

    Each is an array (height, width, 3) of linear radiance or the path of a .exr (linear) or
    .png (display-encoded, decoded to linear: approximate) file. ``mask_emitters`` leaves out
    reference pixels above the threshold in any channel and their neighbours (``True``: the
    command line's default threshold, 3). Raises ValueError for images of different sizes,
    non-finite pixels, a mask that leaves nothing or a black reference.
    """
    a, a_name = _image_for_compare(image, "image")
    b, b_name = _image_for_compare(reference, "reference")
    if mask_emitters is True:
        threshold: Optional[float] = 3.0
    elif mask_emitters is None or mask_emitters is False:
        threshold = None
    else:
        threshold = float(mask_emitters)
    return Comparison(**_rastergi.compare(a, a_name, b, b_name, threshold))


def read_image(path: Union[str, "os.PathLike[str]"]) -> np.ndarray:
    """Reads a .exr (linear) or .png (sRGB decoded to linear) image: float32 (height, width, 3)."""
    return _rastergi.read_image(os.fspath(path))


def write_image(path: Union[str, "os.PathLike[str]"], image: Any, exposure: Optional[float] = None) -> None:
    """Writes an image (height, width, 3) of linear radiance: .exr as float32, .png as
    2^exposure times the image in sRGB (``exposure`` in stops; default fitted as
    ``rastergi render`` fits it: 0 unless the median is far from middle grey)."""
    _rastergi.write_image(os.fspath(path), _array(image, "image"), None if exposure is None else float(exposure))
