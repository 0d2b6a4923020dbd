# Type stubs of the rvr module (python/*.cpp); docs/python.md describes it.
from typing import Any, Optional, Sequence, TypedDict

import numpy as np
import numpy.typing as npt

__version__: str

class BadInput(ValueError): ...

class RendererInfo(TypedDict):
    name: str
    loop_order: str
    description: str

class SceneInfo(TypedDict):
    name: str
    description: str

def renderers() -> list[RendererInfo]: ...
def scenes() -> list[SceneInfo]: ...

class Scene:
    def __init__(
        self,
        source: str = "builtin:cornell",
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
    ) -> None: ...
    @property
    def source(self) -> str: ...
    width: int
    height: int
    spp: int
    camera: dict[str, Any]
    @property
    def warnings(self) -> list[str]: ...
    def to_json(self) -> str: ...
    def save(self, path: str) -> None: ...

class Render:
    @property
    def color(self) -> npt.NDArray[np.float32]: ...
    @property
    def depth(self) -> npt.NDArray[np.float32]: ...
    @property
    def object_id(self) -> npt.NDArray[np.int32]: ...
    @property
    def primitive_id(self) -> npt.NDArray[np.int32]: ...
    @property
    def normal(self) -> npt.NDArray[np.float32]: ...
    @property
    def cost(self) -> npt.NDArray[np.float32]: ...
    @property
    def stats(self) -> dict[str, Any]: ...
    @property
    def warnings(self) -> list[str]: ...
    @property
    def renderer(self) -> str: ...
    @property
    def seconds(self) -> float: ...
    def _repr_png_(self) -> bytes: ...

def render(
    scene: Scene, renderer: str, mode: str = "local", threads: int = 0, **options: Any
) -> Render: ...
def _running_renders() -> int: ...
def compare(a: Render, b: Render) -> dict[str, Any]: ...
def diff(
    path_a: str,
    path_b: str,
    *,
    fail: float = ...,
    fail_percent: float = ...,
    hard_fail: Optional[float] = None,
    warn: float = ...,
    warn_percent: float = ...,
    hard_warn: Optional[float] = None,
    fail_above: Optional[float] = None,
    out: str = "",
) -> dict[str, Any]: ...
def study(
    scenes: Sequence[str] = ("builtin:tessphere", "builtin:soup"),
    *,
    renderers: Sequence[str] = (),
    width: int = 1024,
    mode: str = "local",
    budget: float = 300.0,
    repetitions: int = 5,
    sessions: int = 3,
    noise_threshold: float = 0.03,
    seed: int = 1,
    check_predictions: bool = True,
) -> dict[str, Any]: ...
