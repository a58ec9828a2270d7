"""Obscura's camera models and renderer from Python: numpy arrays in and out.

- ``Camera.from_toml``, ``Camera.from_opencv``, ``Camera.from_opencv_fisheye`` make a camera;
  ``generate_rays``, ``project`` and ``pixel_rays`` work on whole numpy batches in parallel,
  with the GIL released.
- ``load_scene`` and ``render`` render a scene file to a float32 (H, W, 4) array, equal bit for
  bit to ``obscura render`` of the same scene and settings.

Raster positions are in pixels with pixel centres at +0.5 (pixel (i, j) covers
[i, i+1) x [j, j+1)). Bad input raises ValueError or TypeError, never crashes.
"""

from ._obscura import Camera, Scene, __version__, load_scene, read_exr, render

__all__ = ["Camera", "Scene", "load_scene", "read_exr", "render", "__version__"]
