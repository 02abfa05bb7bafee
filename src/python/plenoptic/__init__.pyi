# Type stubs of the package plenoptic (what plenoptic/__init__.py re-exports from the compiled
# extension plenoptic._plenoptic). Checked against the module by the test suite
# (src/python/tests/test_plenoptic.py: test_the_stubs_name_every_function_class_and_parameter):
# every public name, and every parameter name in order, must be the module's.
from typing import Any, Dict, Iterable, List, Optional, Sequence, Tuple, Union

import numpy as np
from numpy.typing import NDArray

__version__: str
build: str

# A (height, width, 3) image of radiance: any floating dtype and memory layout is accepted
# (converted to float32); functions return float32.
_ImageIn = NDArray[np.floating[Any]]
_Image = NDArray[np.float32]
_Rgb = Sequence[float]
_Vec3 = Sequence[float]
_CameraChoice = Union[None, str, "Camera"]

class Error(RuntimeError): ...
class UsageError(Error, ValueError): ...

class FileError(Error, OSError):
    filename: str

class Camera:
    def __init__(
        self,
        eye: _Vec3,
        target: _Vec3,
        up: _Vec3 = ...,
        fov: float = ...,
        fstop: float = ...,
        focus_distance: float = ...,
        name: str = ...,
    ) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def eye(self) -> List[float]: ...
    @property
    def target(self) -> List[float]: ...
    @property
    def up(self) -> List[float]: ...
    @property
    def fov(self) -> float: ...
    @property
    def fstop(self) -> float: ...
    @property
    def focus_distance(self) -> float: ...
    def __repr__(self) -> str: ...

class Scene:
    @property
    def source(self) -> str: ...
    @property
    def triangle_count(self) -> int: ...
    @property
    def material_names(self) -> List[str]: ...
    @property
    def camera_names(self) -> List[str]: ...
    @property
    def light_count(self) -> int: ...
    def camera(self, name: str) -> Camera: ...
    def emission(self, material: str) -> List[float]: ...
    def set_emission(self, material: str, rgb: _Rgb) -> None: ...
    def set_light_color(self, index: int, rgb: _Rgb) -> None: ...
    def set_light_direction(self, index: int, direction: _Rgb) -> None: ...
    def set_albedo(self, material: str, rgb: _Rgb) -> None: ...
    def __repr__(self) -> str: ...

class LightField:
    @property
    def stats(self) -> Dict[str, Any]: ...
    def save(self, path: str, compress: str = ...) -> None: ...
    def render(
        self,
        width: int = ...,
        height: int = ...,
        spp: Optional[int] = ...,
        camera: _CameraChoice = ...,
        seed: int = ...,
        reference: bool = ...,
        threads: int = ...,
        texture_lod: bool = ...,
        *,
        samples: Optional[int] = ...,
    ) -> _Image: ...
    def render_path(
        self,
        path: Union[str, Iterable[Camera]],
        width: int = ...,
        height: int = ...,
        spp: Optional[int] = ...,
        camera: _CameraChoice = ...,
        seed: int = ...,
        reference: bool = ...,
        threads: int = ...,
        texture_lod: bool = ...,
        *,
        samples: Optional[int] = ...,
    ) -> List[_Image]: ...
    def relight(self, scene: Scene) -> LightField: ...
    def __repr__(self) -> str: ...

def load_scene(path: str) -> Scene: ...
def trace(
    scene: Scene,
    width: int = ...,
    height: int = ...,
    spp: int = ...,
    seed: int = ...,
    threads: int = ...,
    camera: _CameraChoice = ...,
    max_depth: int = ...,
    variance: bool = ...,
) -> Union[Tuple[_Image, Dict[str, Any]], Tuple[_Image, Dict[str, Any], _Image]]: ...
def bake(
    scene: Scene,
    preset: str = ...,
    seed: int = ...,
    threads: int = ...,
    visibility: Optional[str] = ...,
    reuse_visibility: bool = ...,
    sun_masks: bool = ...,
    punctual_highlights: bool = ...,
    caustic_photons: Optional[int] = ...,
    max_memory: Optional[str] = ...,
    keep_visibility: bool = ...,
    fresh: bool = ...,
    subsurface_walks: Optional[int] = ...,
    visibility_precision: str = ...,
    visibility_memory: str = ...,
) -> LightField: ...
def load_light_field(path: str, visibility: Optional[str] = ...) -> LightField: ...
def read_image(path: str) -> _Image: ...
def exposure_scale(
    ev: Optional[float] = ...,
    fstop: Optional[float] = ...,
    shutter: Optional[float] = ...,
    iso: Optional[float] = ...,
    tonemap: str = ...,
    key: Optional[float] = ...,
    auto_key: bool = ...,
    white: Optional[float] = ...,
) -> float: ...
def tone_map(
    image: _ImageIn,
    ev: Optional[float] = ...,
    fstop: Optional[float] = ...,
    shutter: Optional[float] = ...,
    iso: Optional[float] = ...,
    tonemap: str = ...,
    key: Optional[float] = ...,
    auto_key: bool = ...,
    white: Optional[float] = ...,
) -> NDArray[np.uint8]: ...
def write_image(
    path: str,
    image: _ImageIn,
    ev: Optional[float] = ...,
    fstop: Optional[float] = ...,
    shutter: Optional[float] = ...,
    iso: Optional[float] = ...,
    tonemap: str = ...,
    key: Optional[float] = ...,
    auto_key: bool = ...,
    white: Optional[float] = ...,
) -> None: ...
def write_video(
    path: str,
    frames: Iterable[_ImageIn],
    fps: float = ...,
    ev: Optional[float] = ...,
    fstop: Optional[float] = ...,
    shutter: Optional[float] = ...,
    iso: Optional[float] = ...,
    tonemap: str = ...,
    key: Optional[float] = ...,
    auto_key: bool = ...,
    white: Optional[float] = ...,
) -> None: ...
def compare(a: _ImageIn, reference: _ImageIn) -> Dict[str, Any]: ...
def sh9(env: _ImageIn) -> NDArray[np.float64]: ...
def irradiance(env: _ImageIn, size: int = ..., method: str = ...) -> _Image: ...
def prefilter(
    env: _ImageIn, levels: int = ..., height: int = ..., samples: int = ..., model: str = ...
) -> List[Tuple[float, _Image]]: ...
def set_progress(enabled: Optional[bool]) -> None: ...
def get_progress() -> Optional[bool]: ...
