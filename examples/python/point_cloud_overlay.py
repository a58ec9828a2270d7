"""Project a point cloud into a calibrated, distorted camera and overlay it on that camera's render.

    pip install ./crates/obscura-py
    python examples/python/point_cloud_overlay.py [OUT.ppm]

The scene is docs/gallery/opencv-distortion.toml: an OpenCV camera with strong barrel distortion
looking at a ring of pillars and spheres. The point cloud is sampled on the white sphere's surface
(centre (2.5, 0.6, -2.5), radius 0.6) in world space; `Camera.project` puts each point where
the distorted camera sees it, so the red dots land on the rendered sphere, bent by the lens as
the render is. Points on the sphere's far side project too (projection knows no occlusion); the
script keeps those whose normal faces the camera.
"""

import sys
from pathlib import Path

import numpy as np
import obscura

root = Path(__file__).resolve().parents[2]
scene_path = root / "docs" / "gallery" / "opencv-distortion.toml"
out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("point_cloud_overlay.ppm")

camera = obscura.Camera.from_toml(scene_path)
image = obscura.render(scene_path, spp=16)

# Points on the white sphere, uniformly on its surface.
rng = np.random.default_rng(0)
normals = rng.normal(size=(4000, 3))
normals /= np.linalg.norm(normals, axis=1, keepdims=True)
centre = np.array([2.5, 0.6, -2.5])
points = centre + 0.6 * normals

# Keep the points facing the camera: the ray from the eye through the pixel meets them first.
origins, directions, valid = camera.generate_rays(np.array([[160.0, 120.0]]))
eye = origins[0]
facing = np.einsum("ij,ij->i", normals, eye - points) > 0
raster, seen = camera.project(points[facing])
raster = raster[seen]

# sRGB of the render (sky composited: alpha is coverage), then the dots.
rgb = np.clip(image[..., :3], 0.0, 1.0)
rgb = np.where(rgb <= 0.0031308, 12.92 * rgb, 1.055 * rgb ** (1 / 2.4) - 0.055)
pixels = (rgb * 255 + 0.5).astype(np.uint8)
h, w = pixels.shape[:2]
cols = np.floor(raster[:, 0]).astype(int)
rows = np.floor(raster[:, 1]).astype(int)
inside = (cols >= 0) & (cols < w) & (rows >= 0) & (rows < h)
pixels[rows[inside], cols[inside]] = [230, 20, 20]

with open(out, "wb") as f:
    f.write(b"P6\n%d %d\n255\n" % (w, h))
    f.write(pixels.tobytes())
print(f"{int(inside.sum())} of {len(points)} points drawn on the render -> {out}")
