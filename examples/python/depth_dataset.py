"""Make a small depth dataset: renders of one scene from random camera poses, with their depth.

    pip install ./crates/obscura-py
    python examples/python/depth_dataset.py [N] [OUT.npz]

Each sample is a camera pose drawn around the ring of pillars (eye on a circle at a random
height, looking at a random point near the centre), its path-traced RGB image and its depth
image (camera-space z of the first hit, 0 where nothing is hit), written with the camera's
look-at to one .npz file.
"""

import sys
from pathlib import Path

import numpy as np
import obscura

root = Path(__file__).resolve().parents[2]
base = (root / "docs" / "gallery" / "panorama.toml").read_text()
n = int(sys.argv[1]) if len(sys.argv) > 1 else 8
out = Path(sys.argv[2]) if len(sys.argv) > 2 else Path("depth_dataset.npz")

# The scene without its [camera] and [film]: the script writes its own.
body = base[base.index("[materials.floor]"):]
rng = np.random.default_rng(1)
rgbs, depths, poses = [], [], []
for i in range(n):
    angle = rng.uniform(0, 2 * np.pi)
    eye = [float(3.2 * np.cos(angle)), float(rng.uniform(0.4, 2.0)), float(3.2 * np.sin(angle))]
    target = [float(rng.uniform(-1, 1)), float(rng.uniform(0.3, 1.2)), float(rng.uniform(-1, 1))]
    text = f"""[film]
resolution = [128, 96]
[sampler]
spp = 8
seed = {i}
[integrator]
type = "path"
max_depth = 3
[camera]
fov = 70.0
eye = {eye}
target = {target}
{body}"""
    scene_file = out.with_suffix(f".{i}.toml")
    scene_file.write_text(text)
    rgbs.append(obscura.render(scene_file)[..., :3])
    depths.append(obscura.render(scene_file, integrator="depth", spp=1)[..., 0])
    poses.append(eye + target)
    scene_file.unlink()
np.savez_compressed(out, rgb=np.stack(rgbs), depth=np.stack(depths), look_at=np.array(poses))
print(f"{n} views -> {out}: rgb {np.stack(rgbs).shape}, depth {np.stack(depths).shape}")
