"""Type stubs of the obscura package (the compiled module obscura._obscura)."""

import os
from typing import Callable, Dict, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

_F32 = npt.NDArray[np.float32]
_Bool = npt.NDArray[np.bool_]
_ArrayLike = npt.ArrayLike
_PathLike = Union[str, "os.PathLike[str]"]

class Camera:
    """A camera model of Obscura (any model of the scene format).

    Raster positions are in pixels, pixel (i, j) covering [i, i+1) x [j, j+1): pixel centres
    are at +0.5; x grows right, y down. Rays have unit directions.
    """

    @staticmethod
    def from_toml(text_or_path: Union[str, "os.PathLike[str]"]) -> "Camera":
        """The camera of a scene file's [camera] and [film] tables, from its TOML text or path.

        [sampler] type is read too (pixel_rays draws from that sampler); every other table is
        ignored, even one the renderer would refuse. A str on one line that names a file, or has
        no "=" (so cannot be a scene), is read as a path; any other str is the text (errors then
        name <string>). Raises ValueError naming the file, key and line for a bad camera or
        film."""
    @staticmethod
    def from_opencv(
        K: _ArrayLike, dist: _ArrayLike, rvec: _ArrayLike, tvec: _ArrayLike, size: Tuple[int, int]
    ) -> "Camera":
        """An OpenCV pinhole camera with distortion (as cv2.projectPoints takes it).

        size is (width, height). Raster positions are OpenCV's pixel coordinates plus 0.5."""
    @staticmethod
    def from_opencv_fisheye(
        K: _ArrayLike, D: _ArrayLike, rvec: _ArrayLike, tvec: _ArrayLike, size: Tuple[int, int]
    ) -> "Camera":
        """An OpenCV fisheye (Kannala-Brandt, D = k1..k4) camera (as cv2.fisheye takes it)."""
    @property
    def model(self) -> str:
        """The model's name in the scene format, e.g. "perspective" or "opencv"."""
    @property
    def resolution(self) -> Tuple[int, int]:
        """(width, height) in pixels."""
    @property
    def pixel_bounds(self) -> Tuple[int, int, int, int]:
        """(x0, x1, y0, y1): the crop window's pixels, half-open."""
    @property
    def shutter(self) -> Tuple[float, float]:
        """(open, close): the shutter interval."""
    def generate_rays(
        self,
        raster_xy: _ArrayLike,
        lens_uv: Optional[_ArrayLike] = None,
        time: Optional[Union[float, _ArrayLike]] = None,
        out: Optional[Tuple[_F32, _F32, _Bool]] = None,
    ) -> Tuple[_F32, _F32, _Bool]:
        """Rays through raster positions (N, 2) -> (origins (N, 3), directions (N, 3), valid (N,)).

        lens_uv (N, 2) in [0, 1)^2. Without it each film point gets the ray project inverts: the
        lens centre's (0.5, 0.5) for a thin lens; for a realistic camera the chief ray, through
        the centre of the aperture stop. time is the shutter sample u in [0, 1) (a number or
        (N,); default 0). Where no ray leaves, valid is False and the ray NaN.
        out=(origins, directions, valid): C-contiguous float32 (N, 3), float32 (N, 3) and bool
        (N,) arrays to write into (and return) instead of new ones; every element is written."""
    def project(
        self,
        points: _ArrayLike,
        time: Optional[float] = None,
        out: Optional[Tuple[_F32, _Bool]] = None,
    ) -> Tuple[_F32, _Bool]:
        """World points (N, 3) -> (raster_xy (N, 2), valid (N,)); time in shutter units
        (default the shutter's opening). Invisible points: valid False, raster NaN.
        out=(raster_xy, valid): float32 (N, 2) and bool (N,) arrays to write into."""
    def pixel_rays(
        self, spp: int = 1, seed: int = 0, out: Optional[Tuple[_F32, _F32, _Bool]] = None
    ) -> Tuple[_F32, _F32, _Bool]:
        """The renderer's camera rays for the whole film: H*W*spp rays, row by row, the samples of
        a pixel together (reshape to (H, W, spp, 3)); drawn from the scene's sampler (Sobol for
        OpenCV cameras) with this seed. out= as for generate_rays."""

class Scene:
    """A scene file loaded and built, ready to render."""

    @property
    def resolution(self) -> Tuple[int, int]:
        """(width, height) in pixels."""
    @property
    def spp(self) -> int:
        """Samples per pixel the file asks for."""
    @property
    def seed(self) -> int:
        """The file's sampler seed."""
    @property
    def integrator(self) -> str:
        """The file's integrator."""
    @property
    def path(self) -> "os.PathLike[str]":
        """The scene file's path."""
    @property
    def camera(self) -> Camera:
        """The scene's camera."""

def load_scene(path: _PathLike) -> Scene:
    """Read, validate and build a scene file; ValueError names the file, key and line.

    TOML, or a pbrt-v4 (.pbrt) or Mitsuba 3 (.xml) scene imported as `obscura render` imports
    it (what the import approximates or leaves out comes as a UserWarning)."""

def render(
    scene: Union[Scene, _PathLike],
    spp: Optional[int] = None,
    integrator: Optional[str] = None,
    seed: Optional[int] = None,
    threads: Optional[int] = None,
    progress: Union[bool, Callable[[int, int], object], None] = False,
    cube_map: bool = False,
) -> Union[_F32, Tuple[_F32, _F32], Dict[str, _F32]]:
    """Render to a float32 (H, W, 4) linear RGBA array, equal bit for bit to `obscura render`.

    scene: a Scene or a path (TOML, .pbrt or .xml, as load_scene reads it). integrator: path,
    depth, distance, position, normal or albedo. progress: False, True (a line on stderr) or a
    callable (tiles_done, tiles_total), called every 50 ms and once at the finish
    (tiles_done == tiles_total). Ctrl-C raises KeyboardInterrupt. Threads may render the same
    Scene at once: each render waits for the one before it.
    A `[camera.stereo]` scene gives both eyes composed as its layout says ("side_by_side":
    (H, 2W, 4), "anaglyph": (H, W, 4)) or, for "separate", a tuple (left, right).
    cube_map=True gives a dict {"px", "nx", "py", "ny", "pz", "nz"} of the six faces, as
    `obscura render --cube-map` writes them."""

def read_exr(path: _PathLike) -> _F32:
    """An RGBA EXR (as `obscura render` writes it) as float32 (H, W, 4), values exactly as stored."""
