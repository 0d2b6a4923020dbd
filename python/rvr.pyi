"""rvr: one scene rendered with both loop orders (rasterization and ray tracing) and compared
pixel by pixel, through the libraries of the command line. Frame buffers come back as numpy
arrays. docs/python.md describes the module."""

# Type stubs of the module rvr, and the one source of its docstrings: the build turns the
# docstrings below into python/stub_docs.py's header, which the bindings (python/*.cpp) hand to
# pybind11, and tests/python/test_stub.py holds these signatures to the module's.
import os
from typing import Any, Optional, Sequence, TypedDict, Union

import numpy as np
import numpy.typing as npt

__version__: str

class BadInput(ValueError):
    """Bad input: a scene, an option or a file rvr refuses. The message is the one the command
    line prints after 'error: ', e.g. 'scene.json: objects[3].radius: must be > 0, got -1';
    a bad keyword value names the keyword, e.g. "accel: 'kd' is not one of bvh, bvh2,
    none"."""

class RendererInfo(TypedDict):
    name: str
    loop_order: str
    description: str

class SceneInfo(TypedDict):
    name: str
    description: str

def renderers() -> list[RendererInfo]:
    """The renderer table: a list of dicts {name, loop_order (triangle-major, pixel-major,
    hybrid), description}."""

def scenes() -> list[SceneInfo]:
    """The built-in scenes: a list of dicts {name ('builtin:cornell'), description}, as
    `rvr scenes` lists them."""

class Scene:
    """A scene: a scene file (rvr-scene/1), a model file Assimp reads, 'builtin:NAME', a dict
    holding an rvr-scene/1 document, or a mesh from numpy arrays (Scene.from_mesh), loaded by
    the command line's loader."""

    def __init__(
        self,
        source: Union[str, os.PathLike[str], dict[str, Any]] = "builtin:cornell",
        *,
        width: Optional[int] = None,
        height: Optional[int] = None,
        spp: Optional[int] = None,
        exposure: Optional[float] = None,
        camera_from: Optional[Sequence[float]] = None,
        up_axis: str = "auto",
        model_camera: str = "file",
        model_lights: str = "file",
        camera: Optional[dict[str, Any]] = None,
    ) -> None:
        """Loads SOURCE with the command line's overrides (--width, --height, --spp,
        --exposure, --camera-from, --up, --camera, --lights); camera={'eye', 'target', 'up',
        'fov'} then replaces those camera settings. SOURCE as a dict is an rvr-scene/1
        document, read as a scene file holding its JSON would be (mesh files relative to the
        current folder; messages name it 'dict'). Raises rvr.BadInput with the command line's
        message."""

    @staticmethod
    def from_mesh(
        vertices: npt.ArrayLike,
        indices: npt.ArrayLike,
        *,
        normals: Optional[npt.ArrayLike] = None,
        colors: Optional[npt.ArrayLike] = None,
        width: Optional[int] = None,
        height: Optional[int] = None,
        spp: Optional[int] = None,
        exposure: Optional[float] = None,
        camera_from: Optional[Sequence[float]] = None,
        up_axis: str = "y",
        camera: Optional[dict[str, Any]] = None,
    ) -> Scene:
        """A scene of one triangle mesh given as arrays, as a model file holding only that mesh
        is one: the framing camera, the default lights, the automatic exposure, degenerate
        triangles dropped with a warning. VERTICES: N x 3 positions; INDICES: M x 3 vertex
        indices of the triangles (or M*3 in a row); NORMALS: N x 3 vertex normals (smooth
        shading; flat without); COLORS: N x 3 linear RGB vertex colours. UP_AXIS: y or z, the
        arrays' up. The other keywords are rvr.Scene's. Messages name it 'mesh'."""

    @property
    def source(self) -> str:
        """What was loaded: 'builtin:cornell', the file's path, 'dict' or 'mesh'."""

    @property
    def width(self) -> int:
        """Image width in pixels."""

    @width.setter
    def width(self, value: int) -> None: ...
    @property
    def height(self) -> int:
        """Image height in pixels."""

    @height.setter
    def height(self, value: int) -> None: ...
    @property
    def spp(self) -> int:
        """Samples per pixel."""

    @spp.setter
    def spp(self, value: int) -> None: ...
    @property
    def camera(self) -> dict[str, Any]:
        """The camera as a dict {eye, target, up, fov (vertical, degrees)}; assigning a dict sets
        the keys it has."""

    @camera.setter
    def camera(self, value: dict[str, Any]) -> None: ...
    @property
    def warnings(self) -> list[str]:
        """What the loader had to change or drop, each naming the file."""

    def to_json(self) -> str:
        """The scene as rvr-scene/1 JSON text (as `rvr scenes --export`)."""

    def save(self, path: Union[str, os.PathLike[str]]) -> None:
        """Writes the scene as rvr-scene/1 to PATH, its meshes as PLY beside it."""

class Render:
    """A finished render. Its arrays are read-only views of the render's own buffers (no
    copy), rows top to bottom; they stay valid after the Render is gone."""

    @property
    def color(self) -> npt.NDArray[np.float32]:
        """H x W x 3 float32, linear RGB."""

    @property
    def depth(self) -> npt.NDArray[np.float32]:
        """H x W float32 view-axis depth, +inf on background."""

    @property
    def object_id(self) -> npt.NDArray[np.int32]:
        """H x W int32 index into the scene's objects, -1 on background."""

    @property
    def primitive_id(self) -> npt.NDArray[np.int32]:
        """H x W int32 triangle index in the object (0 for analytic shapes), -1 on
        background."""

    @property
    def normal(self) -> npt.NDArray[np.float32]:
        """H x W x 3 float32 world-space shading normal facing the viewer, 0 on background."""

    @property
    def cost(self) -> npt.NDArray[np.float32]:
        """H x W float32 work per pixel (nodes visited and tests, or fragments)."""

    @property
    def lod(self) -> npt.NDArray[np.float32]:
        """H x W float32 texture level of detail sampled at the visible surface (the AOV
        `--aov lod` writes), NaN where the surface is not textured."""

    @property
    def answer(self) -> npt.NDArray[np.uint8]:
        """H x W uint8: how a z-buffer answered the effect at each pixel in full mode, the
        answers compare splits each effect's error by, in this order from 0: none,
        reflected_view, layer_view, cube_map_reflection, cube_map_refraction,
        first_interface_only, ssr_hit, ssr_off_screen, ssr_hidden, ssr_background, left_out,
        at_limit. 0 everywhere for a tracer's render, or outside full mode."""

    @property
    def stats(self) -> dict[str, Any]:
        """The document `rvr render --stats` writes, as a dict."""

    @property
    def warnings(self) -> list[str]:
        """The scene loader's warnings, then the renderer's."""

    @property
    def renderer(self) -> str:
        """The renderer's name."""

    @property
    def seconds(self) -> float:
        """The render's wall time."""

    def save(self, path: Union[str, os.PathLike[str]], aovs: Sequence[str] = ()) -> None:
        """Writes the colour to PATH (.png: 8-bit sRGB; .exr: linear float) and the AOVs named
        in AOVS (depth, id, normal, cost, lod) beside it (PATH without its extension, then
        .depth.exr, .id.exr, .normal.exr, .cost.exr and .cost.png, .lod.exr), as
        `rvr render -o PATH --aov AOVS` does: the same files, through the same writer."""

    def _repr_png_(self) -> bytes:
        """The colour as PNG bytes (sRGB), for Jupyter."""

def render(
    scene: Scene, renderer: str, mode: str = "local", threads: int = 0, **options: Any
) -> Render:
    """Renders SCENE (an rvr.Scene) with RENDERER (a name from rvr.renderers()) in MODE
    (visibility, local, full) on THREADS worker threads (0: every core). Other keyword options
    are the command line's of the same names: accel, spheres, sphere_segments, triangle_test,
    texture_lod, max_depth, seed, shadow_map_size, cube_map_size, shadow_bias, shadow_pcf,
    hiz, depth_format, supersampling, zbuffer_dof, zbuffer_reflection, gl. One the renderer
    does not read is named in Render.warnings. The GIL is released while rendering; Ctrl-C cancels the render (it stops
    at its next tile or chunk) and raises KeyboardInterrupt."""

def _running_renders() -> int:
    """Render threads still running: 0 outside rvr.render, also after a KeyboardInterrupt."""

def compare(a: Render, b: Render, *, allow_different: bool = False) -> dict[str, Any]:
    """Compares two renders of one scene (A the reference) as `rvr compare` does: a dict with
    the keys and values of metrics.json (docs/cli.md), through the same writer. Renders of
    different scenes, cameras, image settings, modes or sphere settings (spheres,
    sphere_segments) are refused with rvr.BadInput, as the command line compares only renders
    of one scene, unless ALLOW_DIFFERENT is true. Depth outliers on analytic spheres are
    classed with the renders' sphere settings, as rvr compare classes them."""

def diff(
    a: Union[str, os.PathLike[str], npt.ArrayLike, Render],
    b: Union[str, os.PathLike[str], npt.ArrayLike, Render],
    *,
    fail: float = 1e-06,
    fail_percent: float = 0.0,
    hard_fail: Optional[float] = None,
    warn: float = 1e-06,
    warn_percent: float = 0.0,
    hard_warn: Optional[float] = None,
    fail_above: Optional[float] = None,
    out: Union[str, os.PathLike[str]] = "",
) -> dict[str, Any]:
    """Compares two images as `rvr diff` does (idiff's thresholds; fail_above: FAILURE when the
    RMS error is above it; out: a heat map file to write). A and B are image files, arrays
    (H x W or H x W x C, as floats) or renders (their colour). A dict: mean_error, rms_error,
    peak_snr, max_error, max_at (x, y, channel), pixels, warn_pixels, fail_pixels, verdict
    (PASS, WARNING, FAILURE)."""

def study(
    scenes: Union[str, Sequence[str]] = ("builtin:tessphere", "builtin:soup"),
    *,
    renderers: Union[str, Sequence[str]] = (),
    width: int = 1024,
    mode: str = "local",
    budget: float = 300.0,
    repetitions: int = 5,
    sessions: int = 3,
    noise_threshold: float = 0.03,
    seed: int = 1,
    check_predictions: bool = True,
) -> dict[str, Any]:
    """Runs `rvr study` (docs/cli.md): the scene families SCENES (one name or several) swept
    within BUDGET seconds, one renderer per loop order plus RENDERERS, cost models fitted,
    crossovers found. Returns the study.json document as a dict; its 'points' is a list of
    records for pandas.DataFrame. Each point is measured in SESSIONS fresh preparations of its
    scene in this process (the command line starts a process for each). Bad values raise
    rvr.BadInput naming the keyword. Ctrl-C stops the sweep and raises KeyboardInterrupt."""
