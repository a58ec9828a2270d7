"""Tests of the obscura Python package (pytest).

Round trips through the bindings for the camera models, values checked against formulas
written out here (never against the bindings themselves), renders compared bit for bit across
thread counts and, when OBSCURA_BIN names the `obscura` binary, with the EXR it writes; and bad
input of every kind raising a Python exception.
"""

import json
import math
import os
import pathlib
import signal
import subprocess
import sys
import threading
import _thread

import numpy as np
import pytest

import obscura

ROOT = pathlib.Path(__file__).resolve().parents[3]
SCENES = ROOT / "scenes"


def scene_text(camera, resolution=(64, 48), extra=""):
    """A minimal scene file: a film, a camera and one quad (the parser needs no more)."""
    return f"""
[film]
resolution = [{resolution[0]}, {resolution[1]}]
[camera]
{camera}
{extra}
[[shapes]]
type = "quad"
origin = [-10.0, -10.0, -5.0]
edge_u = [20.0, 0.0, 0.0]
edge_v = [0.0, 20.0, 0.0]
"""


LOOK = "eye = [0.5, 1.0, 3.0]\ntarget = [0.0, 0.2, -1.0]"

# Every model with a one-to-one film <-> direction map (ODS pairs two eyes per panorama).
MODELS = {
    "perspective": f'type = "perspective"\nfov = 50.0\n{LOOK}',
    "orthographic": f'type = "orthographic"\nscreen_window = [-2.0, 2.0, -1.5, 1.5]\n{LOOK}',
    "fisheye": f'type = "fisheye"\nprojection = "equisolid"\nfov = 185.0\n{LOOK}',
    "environment": f'type = "environment"\n{LOOK}',
    "cylindrical": f'type = "cylindrical"\nfov = 100.0\n{LOOK}',
    "octahedral": f'type = "octahedral"\n{LOOK}',
    "opencv": (
        'type = "opencv"\nfx = 60.0\nfy = 62.0\ncx = 31.5\ncy = 23.5\n'
        f"distortion = [-0.2, 0.05, 0.001, -0.002, 0.01]\n{LOOK}"
    ),
    "opencv_fisheye": (
        'type = "opencv_fisheye"\nfx = 20.0\nfy = 20.0\ncx = 31.5\ncy = 23.5\n'
        f"distortion = [0.04, -0.012, 0.003, -0.0005]\n{LOOK}"
    ),
}


def film_points(cam, n, seed, margin=1.0):
    """Raster positions spread over the film, `margin` pixels inside its edges."""
    w, h = cam.resolution
    rng = np.random.default_rng(seed)
    return np.column_stack(
        [rng.uniform(margin, w - margin, n), rng.uniform(margin, h - margin, n)]
    ).astype(np.float32)


DOUBLE_GAUSS = (SCENES / "lenses" / "double-gauss-50mm.dat").as_posix()

# Models with a lens, by case name: (model, [camera] table). Without lens samples,
# generate_rays gives the ray project inverts: the lens centre's, or a lens system's chief ray.
LENS_MODELS = {
    "thin_lens": ("perspective", f"type = \"perspective\"\nfov = 50.0\nlens_radius = 0.2\nfocal_distance = 3.0\n{LOOK}"),
    "orthographic_thin_lens": (
        "orthographic",
        f"type = \"orthographic\"\nscreen_window = [-2.0, 2.0, -1.5, 1.5]\nlens_radius = 0.2\nfocal_distance = 3.0\n{LOOK}",
    ),
    "realistic": (
        "realistic",
        f"type = \"realistic\"\nlens_file = \"{DOUBLE_GAUSS}\"\nfocus_distance = 2.0\n{LOOK}",
    ),
}

ROUND_TRIPS = {**{m: (m, text) for m, text in MODELS.items()}, **LENS_MODELS}


def round_trip_error(cam, xy, t):
    """The largest distance (px) between raster positions and the projections of the points at
    distances `t` along their default rays, and the fraction of positions with a ray."""
    o, d, valid = cam.generate_rays(xy)
    back, seen = cam.project((o + t * d)[valid])
    assert seen.all()
    return np.abs(back - xy[valid]).max(), valid.mean()


@pytest.mark.parametrize("case", sorted(ROUND_TRIPS))
def test_project_inverts_generate_rays(case):
    model, table = ROUND_TRIPS[case]
    square = model == "octahedral"  # an octahedral map needs a square film
    cam = obscura.Camera.from_toml(scene_text(table, resolution=(48, 48) if square else (64, 48)))
    assert cam.model == model
    xy = film_points(cam, 2000, seed=len(case))
    o, d, valid = cam.generate_rays(xy)
    assert o.shape == (2000, 3) and d.shape == (2000, 3) and valid.shape == (2000,)
    assert o.dtype == np.float32 and d.dtype == np.float32 and valid.dtype == np.bool_
    # The fisheyes have no rays outside their image circle; everything else covers the film.
    assert valid.mean() > (0.5 if "fisheye" in model else 0.999)
    np.testing.assert_allclose(np.linalg.norm(d[valid], axis=1), 1.0, atol=1e-5)
    assert np.isnan(o[~valid]).all() and np.isnan(d[~valid]).all()
    t = np.random.default_rng(7).uniform(0.5, 8.0, (2000, 1)).astype(np.float32)
    back, seen = cam.project((o + t * d)[valid])
    assert seen.all()
    err = np.abs(back - xy[valid]).max()
    assert err < 2e-2, f"{case}: round trip off by {err} px"


@pytest.mark.parametrize("t", [0.5, 1.0, 100.0])
def test_a_realistic_camera_round_trips_through_its_chief_rays(t):
    # The shipped scene: points near the lens (0.5 m) and far away, where a ray through an
    # off-centre part of the pupil would miss its film point by tenths of a pixel.
    cam = obscura.Camera.from_toml(SCENES / "spheres-realistic.toml")
    assert cam.model == "realistic"
    w, h = cam.resolution
    g = np.stack(np.meshgrid(np.arange(0, w, 7) + 0.5, np.arange(0, h, 7) + 0.5), -1)
    err, covered = round_trip_error(cam, g.reshape(-1, 2).astype(np.float32), t)
    assert covered == 1.0
    assert err < 2e-2, f"round trip off by {err} px at t = {t}"


def test_perspective_matches_the_pinhole_formula():
    # fov 90 on a 2x2 film from the origin looking down -z: pixel (0, 0)'s centre (0.5, 0.5) is
    # at screen (-0.5, 0.5), so its direction is normalize(-0.5, 0.5, -1).
    cam = obscura.Camera.from_toml(
        scene_text(
            'type = "perspective"\nfov = 90.0\neye = [0.0, 0.0, 0.0]\ntarget = [0.0, 0.0, -1.0]',
            resolution=(2, 2),
        )
    )
    o, d, valid = cam.generate_rays([[0.5, 0.5], [1.0, 1.0], [2.0, 0.0]])
    assert valid.all()
    np.testing.assert_allclose(o, 0.0, atol=1e-7)
    expect = np.array([[-0.5, 0.5, -1.0], [0.0, 0.0, -1.0], [1.0, 1.0, -1.0]])
    expect /= np.linalg.norm(expect, axis=1, keepdims=True)
    np.testing.assert_allclose(d, expect, atol=1e-6)


def rodrigues(rvec):
    theta = np.linalg.norm(rvec)
    k = rvec / theta
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(theta) * kx + (1 - math.cos(theta)) * kx @ kx


def opencv_project(points, K, dist, rvec, tvec):
    """cv2.projectPoints written out (k1 k2 p1 p2 k3), pixel centres at integers."""
    k1, k2, p1, p2, k3 = dist
    pc = points @ rodrigues(rvec).T + tvec
    x, y = pc[:, 0] / pc[:, 2], pc[:, 1] / pc[:, 2]
    r2 = x * x + y * y
    radial = 1 + k1 * r2 + k2 * r2**2 + k3 * r2**3
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
    yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    return np.column_stack([K[0, 0] * xd + K[0, 2], K[1, 1] * yd + K[1, 2]])


def test_from_opencv_matches_the_opencv_formula():
    K = np.array([[500.0, 0.0, 319.5], [0.0, 480.0, 239.5], [0.0, 0.0, 1.0]])
    dist = np.array([-0.25, 0.08, 0.001, -0.0015, 0.01])
    rvec = np.array([0.1, -0.2, 0.05])
    tvec = np.array([0.3, -0.1, 2.0])
    cam = obscura.Camera.from_opencv(K, dist, rvec.reshape(3, 1), tvec, (640, 480))
    assert cam.model == "opencv" and cam.resolution == (640, 480)
    rng = np.random.default_rng(3)
    # Points in front of the camera, inside the view.
    pc = np.column_stack(
        [rng.uniform(-0.5, 0.5, 500), rng.uniform(-0.4, 0.4, 500), rng.uniform(1, 5, 500)]
    )
    R = rodrigues(rvec)
    world = (pc - tvec) @ R  # R^T (pc - t)
    xy, valid = cam.project(world.astype(np.float32))
    assert valid.all()
    expect = opencv_project(world, K, dist, rvec, tvec) + 0.5
    np.testing.assert_allclose(xy, expect, atol=2e-3)
    # And back: rays through those raster positions pass through the points.
    o, d, ok = cam.generate_rays(xy)
    assert ok.all()
    t = np.einsum("ij,ij->i", world - o, d)[:, None]
    np.testing.assert_allclose(o + t * d, world, atol=2e-3)


def test_from_opencv_fisheye_round_trip():
    K = np.array([[95.0, 0.0, 159.5], [0.0, 95.0, 159.5], [0.0, 0.0, 1.0]])
    D = [0.04, -0.012, 0.003, -0.0005]
    cam = obscura.Camera.from_opencv_fisheye(K, D, np.zeros(3), np.zeros(3), (320, 320))
    assert cam.model == "opencv_fisheye"
    # The optical axis: OpenCV's principal point is raster (cx + 0.5, cy + 0.5), along +z of
    # the OpenCV camera, which with zero extrinsics is world +z.
    o, d, ok = cam.generate_rays([[160.0, 160.0]])
    assert ok.all()
    np.testing.assert_allclose(d, [[0.0, 0.0, 1.0]], atol=1e-6)
    xy = film_points(cam, 1000, seed=1, margin=40)
    o, d, ok = cam.generate_rays(xy)
    assert ok.mean() > 0.9
    back, seen = cam.project((o + 3.0 * d)[ok])
    assert seen.all()
    assert np.abs(back - xy[ok]).max() < 1e-2


def test_generate_rays_lens_and_time():
    text = scene_text(
        'type = "perspective"\nfov = 40.0\nlens_radius = 0.2\nfocal_distance = 4.0\n'
        "eye = [0.0, 0.0, 0.0]\ntarget = [0.0, 0.0, -1.0]\nshutter = [0.0, 2.0]\n"
        "eye_end = [1.0, 0.0, 0.0]\ntarget_end = [1.0, 0.0, -1.0]"
    )
    cam = obscura.Camera.from_toml(text)
    assert cam.shutter == (0.0, 2.0)
    xy = np.array([[32.0, 24.0]] * 3, dtype=np.float32)
    lens = np.array([[0.5, 0.5], [0.9, 0.5], [0.5, 0.5]], dtype=np.float32)
    o, d, ok = cam.generate_rays(xy, lens_uv=lens, time=np.array([0.0, 0.0, 0.5]))
    assert ok.all()
    # Lens centre at shutter open: the eye. Off-centre lens: another origin, the same point in
    # focus 4 units ahead. Half-way through the shutter: the eye has moved half-way.
    np.testing.assert_allclose(o[0], [0.0, 0.0, 0.0], atol=1e-6)
    assert np.linalg.norm(o[1] - o[0]) > 0.05
    focus0 = o[0] + d[0] * (4.0 / -d[0][2])
    focus1 = o[1] + d[1] * (4.0 / -d[1][2])
    np.testing.assert_allclose(focus0, focus1, atol=1e-4)
    np.testing.assert_allclose(o[2], [0.5, 0.0, 0.0], atol=1e-5)
    # A scalar time applies to every ray.
    o2, _, _ = cam.generate_rays(xy, time=0.5)
    np.testing.assert_allclose(o2[:, 0], 0.5, atol=1e-5)


def test_pixel_rays_cover_the_film_in_order():
    cam = obscura.Camera.from_toml(scene_text(MODELS["perspective"], resolution=(8, 6)))
    o, d, ok = cam.pixel_rays(spp=4, seed=5)
    assert o.shape == (8 * 6 * 4, 3) and ok.all()
    # Ray i is sample i % 4 of pixel ((i // 4) % 8, i // 32): each projects inside its pixel.
    xy, seen = cam.project(o + 2.0 * d)
    assert seen.all()
    i = np.arange(len(xy))
    px, py = (i // 4) % 8, i // 32
    assert ((xy[:, 0] >= px - 1e-3) & (xy[:, 0] <= px + 1 + 1e-3)).all()
    assert ((xy[:, 1] >= py - 1e-3) & (xy[:, 1] <= py + 1 + 1e-3)).all()
    # The samples of a pixel differ; the same seed repeats them, another seed does not.
    assert len(np.unique(xy[:4], axis=0)) == 4
    o2, d2, _ = cam.pixel_rays(spp=4, seed=5)
    assert (d2.view(np.uint32) == d.view(np.uint32)).all()
    _, d3, _ = cam.pixel_rays(spp=4, seed=6)
    assert not np.array_equal(d3, d)


def bits(a):
    return np.ascontiguousarray(a).view(np.uint32)


@pytest.fixture(scope="module")
def perspective_scene():
    return obscura.load_scene(SCENES / "spheres-perspective.toml")


def test_render_is_the_same_for_any_thread_count(perspective_scene):
    s = perspective_scene
    assert s.resolution == (320, 240) and s.integrator == "path"
    one = obscura.render(s, spp=2, threads=1)
    two = obscura.render(s, spp=2, threads=2)
    assert one.shape == (240, 320, 4) and one.dtype == np.float32
    assert (bits(one) == bits(two)).all()
    # A different seed gives a different image, so the comparison above can fail.
    other = obscura.render(s, spp=2, seed=12345, threads=2)
    assert not (bits(other) == bits(one)).all()
    # Alpha: 1 where the floor or a sphere fills the pixel, 0 for the sky above the horizon.
    assert one[-1, :, 3].min() == 1.0 and one[0, :, 3].max() == 0.0


def test_render_accepts_a_path_and_an_aov():
    depth = obscura.render(str(SCENES / "spheres-perspective.toml"), spp=1, integrator="depth")
    assert depth.shape == (240, 320, 4)
    # Camera-space depth where the pixel is covered (bottom row: the floor), 0 for the sky.
    assert np.isfinite(depth).all()
    assert (depth[-1, :, 0] > 0).all() and (depth[0, :, 0] == 0).all()


OBSCURA_BIN = os.environ.get("OBSCURA_BIN")


@pytest.mark.skipif(not OBSCURA_BIN, reason="OBSCURA_BIN names no obscura binary")
@pytest.mark.parametrize(
    "scene,flags",
    [
        ("spheres-perspective.toml", dict(spp=2, seed=3)),
        ("spheres-thin-lens.toml", dict(spp=2, integrator="albedo")),
        ("cornell-box.toml", dict(spp=1)),
        # Imported through obscura-import, as the command line imports them.
        ("spheres-perspective.pbrt", dict(spp=2, seed=5)),
        ("spheres-perspective.xml", dict(spp=1)),
    ],
)
def test_render_equals_the_command_line(tmp_path, scene, flags):
    out = tmp_path / "cli.exr"
    cmd = [OBSCURA_BIN, "render", str(SCENES / scene), "-o", str(out), "--threads", "2"]
    for k, v in flags.items():
        cmd += [f"--{k}", str(v)]
    subprocess.run(cmd, check=True, capture_output=True)
    cli = obscura.read_exr(out)
    py = obscura.render(obscura.load_scene(SCENES / scene), threads=2, **flags)
    assert cli.shape == py.shape
    assert (bits(cli) == bits(py)).all()


def test_progress_callback_and_its_exception(perspective_scene):
    calls = []

    def progress(done, total):
        calls.append((done, total))

    obscura.render(perspective_scene, spp=64, progress=progress)
    # Called from the waiting thread every 50 ms; a debug build takes long enough for several.
    for done, total in calls:
        assert 0 <= done <= total

    class Stop(Exception):
        pass

    def stop(done, total):
        raise Stop()

    with pytest.raises(Stop):
        obscura.render(perspective_scene, spp=100000, progress=stop)


@pytest.mark.parametrize("spp", [1, 2, 16])
def test_progress_reports_the_finish_once(perspective_scene, spp):
    # However soon the render ends after the last 50 ms poll (a 1-spp render may end before
    # the first), the last call is the finish, and it comes once.
    calls = []
    obscura.render(perspective_scene, spp=spp, progress=lambda done, total: calls.append((done, total)))
    assert calls, "the callback was never called"
    total = calls[-1][1]
    assert total > 0 and calls[-1] == (total, total)
    assert calls.count((total, total)) == 1


def test_progress_line_ends_at_100_percent(perspective_scene, capsys):
    obscura.render(perspective_scene, spp=1, progress=True)
    err = capsys.readouterr().err
    assert err.endswith("(100%)\n"), repr(err[-80:])
    done, total = err.rsplit("rendering: ", 1)[1].split(" tiles")[0].split("/")
    assert done == total


def test_ctrl_c_raises_keyboard_interrupt(perspective_scene):
    # interrupt_main is what the SIGINT handler does: the render's next check of the signals
    # raises KeyboardInterrupt and stops the workers. A process started in the background by a
    # shell without job control inherits SIGINT ignored, and Python then installs no handler and
    # interrupt_main does nothing; so the test installs Python's own handler for its duration.
    polls = 0

    def guard(done, total):
        # The render polls every 50 ms; far more polls than the timer's 0.2 s means the interrupt
        # was lost. Failing here ends the 100000-spp render instead of hanging the suite.
        nonlocal polls
        polls += 1
        assert polls < 600, "Ctrl-C did not stop the render"

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.2, _thread.interrupt_main)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            obscura.render(perspective_scene, spp=100000, threads=1, progress=guard)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)


# Run in a process of its own (argv[1]: a scene file), so that a deadlock fails the test by
# its timeout instead of hanging the suite. Each render that the others race with runs until
# its progress callable says stop, so nothing here waits on a clock.
RENDERS_IN_THREADS = r"""
import _thread, signal, sys, threading
import obscura

scene = obscura.load_scene(sys.argv[1])
errors = []


class Stop(Exception):
    pass


def render_until(stop):
    # A long render in another thread, stopped by its progress callable once stop(polls) is
    # true; returns the thread once the render runs (it has polled).
    started = threading.Event()
    polls = [0]

    def progress(done, total):
        polls[0] += 1
        started.set()
        if stop(polls[0]):
            raise Stop()

    def run():
        try:
            obscura.render(scene, spp=10**6, threads=1, progress=progress)
        except Stop:
            pass
        except BaseException as e:
            errors.append(e)

    thread = threading.Thread(target=run)
    thread.start()
    assert started.wait(60), "the render never polled"
    return thread


# Reading the scene while another thread renders it.
read = threading.Event()
t = render_until(lambda polls: read.is_set())
assert scene.camera.model == "perspective" and scene.resolution == (320, 240)
read.set()
t.join()

# Rendering the scene while another thread renders it: this one waits its turn.
t = render_until(lambda polls: polls >= 5)
assert obscura.render(scene, spp=1).shape == (240, 320, 4)
t.join()

# Ctrl-C while waiting for the other render ends the wait (interrupt_main is what the SIGINT
# handler does; the handler is installed in case SIGINT came ignored).
signal.signal(signal.SIGINT, signal.default_int_handler)
interrupted = threading.Event()


def stop_once_interrupted(polls):
    if polls == 3:
        _thread.interrupt_main()
    assert polls < 200, "Ctrl-C did not end the wait for the other render"
    return interrupted.is_set()


t = render_until(stop_once_interrupted)
try:
    obscura.render(scene, spp=1)
    errors.append("no KeyboardInterrupt")
except KeyboardInterrupt:
    interrupted.set()
t.join()


# Four threads rendering the scene at once, three times over.
def one():
    try:
        obscura.render(scene, spp=1)
    except BaseException as e:
        errors.append(e)


for _ in range(3):
    threads = [threading.Thread(target=one) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
assert not errors, errors
print("ok")
"""


def test_renders_in_threads_neither_deadlock_nor_ignore_ctrl_c():
    cmd = [sys.executable, "-c", RENDERS_IN_THREADS, str(SCENES / "spheres-perspective.toml")]
    try:
        run = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        pytest.fail("renders in threads deadlocked (no end in 120 s)")
    assert run.returncode == 0 and run.stdout == "ok\n", run.stderr


# Bad input: each a Python exception with a message that says what is wrong.


@pytest.fixture(scope="module")
def cam():
    return obscura.Camera.from_toml(scene_text(MODELS["perspective"]))


def test_wrong_shapes_raise_value_error(cam):
    with pytest.raises(ValueError, match=r"raster_xy: expected an array of shape \(N, 2\), got shape \(5, 3\)"):
        cam.generate_rays(np.zeros((5, 3)))
    with pytest.raises(ValueError, match=r"points: expected an array of shape \(N, 3\), got shape \(3,\)"):
        cam.project(np.zeros(3))
    with pytest.raises(ValueError, match="lens_uv"):
        cam.generate_rays(np.zeros((5, 2)), lens_uv=np.zeros((4, 2)))
    with pytest.raises(ValueError, match="time"):
        cam.generate_rays(np.zeros((5, 2)), time=np.zeros(4))


def test_wrong_dtypes_raise_type_error(cam):
    with pytest.raises(TypeError, match="raster_xy: expected an array of floats or integers"):
        cam.generate_rays(np.array([["a", "b"]]))
    with pytest.raises(TypeError, match="points"):
        cam.project(np.array([[object(), 1, 2]], dtype=object))
    with pytest.raises(TypeError):
        obscura.Camera.from_toml(42)


def test_integers_and_float64_are_accepted(cam):
    a, _, _ = cam.generate_rays(np.array([[10, 20]], dtype=np.int64))
    b, _, _ = cam.generate_rays(np.array([[10.0, 20.0]], dtype=np.float64))
    assert (bits(a) == bits(b)).all()


def test_nans_raise_value_error(cam):
    with pytest.raises(ValueError, match=r"raster_xy\[1\]: NaN or infinite"):
        cam.generate_rays(np.array([[1.0, 2.0], [np.nan, 1.0]]))
    with pytest.raises(ValueError, match=r"points\[0\]"):
        cam.project(np.array([[np.inf, 0.0, 0.0]]))
    with pytest.raises(ValueError, match="K"):
        obscura.Camera.from_opencv(np.full((3, 3), np.nan), [0, 0, 0, 0], np.zeros(3), np.zeros(3), (4, 4))


def test_bad_scene_names_file_key_and_line(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(scene_text('type = "perspective"\nfov = 180.0\n' + LOOK))
    with pytest.raises(ValueError) as e:
        obscura.Camera.from_toml(bad)
    msg = str(e.value)
    assert str(bad) in msg and "camera.fov" in msg and ":6:" in msg
    with pytest.raises(ValueError, match="camera.fov"):
        obscura.load_scene(bad)
    with pytest.raises(ValueError, match="camera.type"):
        obscura.Camera.from_toml(scene_text('type = "pinhole"'))
    with pytest.raises(ValueError, match="cannot read the scene file"):
        obscura.load_scene(tmp_path / "missing.toml")
    with pytest.raises(ValueError, match="cannot read the scene file"):
        obscura.Camera.from_toml(str(tmp_path / "missing.toml"))


# What Camera.from_toml ignores, each of which the renderer refuses: (text before the scene,
# text after it).
REFUSED_TABLES = {
    "unknown table": ("", "[foo]\nbar = 1\n"),
    "unknown integrator": ("", '[integrator]\ntype = "nope"\n'),
    "zero spp": ("", "[sampler]\nspp = 0\n"),
    "undefined material": (
        "",
        '[[shapes]]\ntype = "sphere"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = "undefined"\n',
    ),
    "unknown material type": ("", '[materials.x]\ntype = "nonsense"\n'),
    "unknown light": ("", '[[lights]]\ntype = "laser"\n'),
    "root and dotted keys": ('version = 3\nsampler.spp = 0\nmaterials.y.type = "nonsense"\n', ""),
}


@pytest.mark.parametrize("case", sorted(REFUSED_TABLES))
def test_from_toml_ignores_tables_other_than_camera_and_film(tmp_path, case):
    head, tail = REFUSED_TABLES[case]
    text = head + scene_text(MODELS["perspective"], extra=tail)
    # The renderer refuses the scene ...
    path = tmp_path / "scene.toml"
    path.write_text(text)
    with pytest.raises(ValueError):
        obscura.load_scene(path)
    # ... but its camera is all there is to read, from text and from the file alike.
    for source in (text, path):
        cam = obscura.Camera.from_toml(source)
        assert cam.model == "perspective" and cam.resolution == (64, 48)


def test_from_toml_errors_keep_their_lines_after_ignored_tables(tmp_path):
    # Ignored tables before the camera, one with a matrix whose rows start lines with "[": the
    # error in the camera still names the camera's key and its line in the file.
    ignored = (
        '[integrator]\ntype = "nope"\n'
        '[[shapes]]\ntype = "mesh"\nfile = "x.obj"\ntransform = [\n'
        "  [1.0, 0.0, 0.0, 0.0],\n  [0.0, 1.0, 0.0, 0.0],\n  [0.0, 0.0, 1.0, 0.0],\n"
        "  [0.0, 0.0, 0.0, 1.0],\n]\n"
    )
    text = ignored + '[film]\nresolution = [64, 48]\n[camera]\ntype = "perspective"\nfov = 180.0\n'
    line = text.splitlines().index("fov = 180.0") + 1
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    with pytest.raises(ValueError) as e:
        obscura.Camera.from_toml(bad)
    assert f"{bad}:{line}:" in str(e.value) and "camera.fov" in str(e.value)
    # A syntax error anywhere is still an error, with its line.
    with pytest.raises(ValueError, match=r"<string>:2:"):
        obscura.Camera.from_toml(scene_text(MODELS["perspective"]).replace("[film]", "[film"))


def test_from_toml_keeps_the_sampler_type_for_pixel_rays():
    # [sampler] type is the one key outside [camera] and [film] that counts: pixel_rays draws
    # from that sampler (the rest of the table, spp 0 here, is ignored).
    base = scene_text(MODELS["perspective"], resolution=(8, 6))
    sobol = obscura.Camera.from_toml(base).pixel_rays(spp=4, seed=1)[1]
    halton = obscura.Camera.from_toml(base + '[sampler]\ntype = "halton"\nspp = 0\n').pixel_rays(spp=4, seed=1)[1]
    explicit = obscura.Camera.from_toml(base + '[sampler]\ntype = "sobol"\n').pixel_rays(spp=4, seed=1)[1]
    assert (bits(explicit) == bits(sobol)).all()
    assert not (bits(halton) == bits(sobol)).all()
    with pytest.raises(ValueError, match="sampler.type"):
        obscura.Camera.from_toml(base + '[sampler]\ntype = "nope"\n')


def test_bad_opencv_arguments():
    K = np.array([[100.0, 0.0, 50.0], [0.0, 100.0, 50.0], [0.0, 0.0, 1.0]])
    with pytest.raises(ValueError, match="distortion"):
        obscura.Camera.from_opencv(K, [0.1], np.zeros(3), np.zeros(3), (100, 100))
    with pytest.raises(ValueError, match="skew"):
        obscura.Camera.from_opencv(K + [[0, 1, 0], [0, 0, 0], [0, 0, 0]], [0] * 5, np.zeros(3), np.zeros(3), (100, 100))
    with pytest.raises(ValueError, match="rvec: expected 3 values"):
        obscura.Camera.from_opencv(K, [0] * 5, np.zeros(2), np.zeros(3), (100, 100))
    with pytest.raises(ValueError, match="fx"):
        obscura.Camera.from_opencv(K * [[-1], [1], [1]], [0] * 5, np.zeros(3), np.zeros(3), (100, 100))


def test_bad_render_arguments(perspective_scene):
    with pytest.raises(ValueError, match="unknown integrator `mist`"):
        obscura.render(perspective_scene, integrator="mist")
    with pytest.raises(ValueError, match="spp: must be >= 1"):
        obscura.render(perspective_scene, spp=0)
    with pytest.raises(ValueError, match="threads: must be >= 1"):
        obscura.render(perspective_scene, threads=0)
    with pytest.raises(TypeError, match="scene"):
        obscura.render(3.5)
    with pytest.raises(ValueError, match="spp"):
        obscura.Camera.from_toml(scene_text(MODELS["perspective"])).pixel_rays(spp=0)


@pytest.mark.parametrize("fisheye", [False, True])
def test_project_equals_opencv_project_points(fisheye):
    """OpenCV's own projectPoints (when cv2 is installed, as .ci/run does) against project."""
    cv2 = pytest.importorskip("cv2")
    K = np.array([[420.0, 0.0, 321.0], [0.0, 410.0, 238.0], [0.0, 0.0, 1.0]])
    rvec = np.array([[0.2], [-0.1], [0.05]])
    tvec = np.array([[0.1], [0.2], [1.5]])
    rng = np.random.default_rng(11)
    pc = np.column_stack(
        [rng.uniform(-0.6, 0.6, 400), rng.uniform(-0.5, 0.5, 400), rng.uniform(1, 6, 400)]
    )
    world = (pc - tvec.ravel()) @ rodrigues(rvec.ravel())
    if fisheye:
        D = np.array([0.05, -0.01, 0.002, -0.0003])
        cam = obscura.Camera.from_opencv_fisheye(K, D, rvec, tvec, (640, 480))
        expect, _ = cv2.fisheye.projectPoints(world.reshape(-1, 1, 3), rvec, tvec, K, D)
    else:
        D = np.array([-0.28, 0.09, 0.0012, -0.0007, -0.01])
        cam = obscura.Camera.from_opencv(K, D, rvec, tvec, (640, 480))
        expect, _ = cv2.projectPoints(world, rvec, tvec, K, D)
    xy, ok = cam.project(world.astype(np.float32))
    assert ok.all()
    np.testing.assert_allclose(xy, expect.reshape(-1, 2) + 0.5, atol=2e-3)


def test_out_arrays_are_filled_and_returned():
    cam = obscura.Camera.from_toml(scene_text(MODELS["fisheye"]))
    xy = film_points(cam, 500, seed=5, margin=0.0)
    fresh = cam.generate_rays(xy)
    # Outputs full of stale values: every element must be overwritten, NaN where no ray leaves.
    out = (np.full((500, 3), 7.0, np.float32), np.full((500, 3), 7.0, np.float32), np.ones(500, bool))
    got = cam.generate_rays(xy, out=out)
    assert all(g is o for g, o in zip(got, out))
    for g, f in zip(got[:2], fresh[:2]):
        assert (bits(g) == bits(f)).all()
    assert (got[2] == fresh[2]).all() and not fresh[2].all()  # some points lie past the circle
    p = fresh[0][fresh[2]] + 2.0 * fresh[1][fresh[2]]
    pout = (np.full((len(p), 2), 7.0, np.float32), np.zeros(len(p), bool))
    got = cam.project(p, out=pout)
    assert got[0] is pout[0] and (bits(got[0]) == bits(cam.project(p)[0])).all()
    r = cam.pixel_rays(spp=1, seed=2)
    n = len(r[2])
    rout = (np.empty((n, 3), np.float32), np.empty((n, 3), np.float32), np.empty(n, bool))
    got = cam.pixel_rays(spp=1, seed=2, out=rout)
    assert (bits(got[1]) == bits(r[1])).all()


def test_bad_out_arrays_raise(cam):
    xy = np.zeros((4, 2), np.float32) + 10.0
    good = lambda: (np.empty((4, 3), np.float32), np.empty((4, 3), np.float32), np.empty(4, bool))
    with pytest.raises(TypeError, match="out: expected a tuple"):
        cam.generate_rays(xy, out=[np.empty((4, 3), np.float32)] * 3)
    with pytest.raises(ValueError, match="out: expected 3 arrays"):
        cam.generate_rays(xy, out=good()[:2])
    o, d, v = good()
    with pytest.raises(ValueError, match=r"out: origins must have shape \(4, 3\)"):
        cam.generate_rays(xy, out=(np.empty((5, 3), np.float32), d, v))
    with pytest.raises(TypeError, match="out: directions must be a C-contiguous float32"):
        cam.generate_rays(xy, out=(o, np.empty((4, 3), np.float64), v))
    with pytest.raises(ValueError, match="C-contiguous"):
        cam.generate_rays(xy, out=(o, np.empty((3, 4), np.float32).T, v))
    ro = np.empty((4, 3), np.float32)
    ro.flags.writeable = False
    with pytest.raises(ValueError, match="out: origins cannot be written"):
        cam.generate_rays(xy, out=(ro, d, v))
    with pytest.raises(ValueError, match="out: directions cannot be written"):
        cam.generate_rays(xy, out=(o, o, v))
    with pytest.raises(TypeError, match="out: valid must be a C-contiguous bool"):
        cam.project(np.zeros((4, 3)), out=(np.empty((4, 2), np.float32), np.empty(4, np.uint8)))


@pytest.mark.parametrize("name", ["spheres-perspective.pbrt", "spheres-perspective.xml"])
def test_load_scene_imports_pbrt_and_mitsuba_scenes(name):
    # The shipped pbrt-v4 and Mitsuba 3 versions of spheres-perspective.toml: the same film,
    # samples and camera (its pose imported as a matrix, so equal to rounding), and a picture.
    scene = obscura.load_scene(SCENES / name)
    assert scene.resolution == (320, 240) and scene.spp == 16
    toml = obscura.Camera.from_toml(SCENES / "spheres-perspective.toml")
    xy = film_points(toml, 500, seed=2, margin=0.0)
    for got, expect in zip(scene.camera.generate_rays(xy), toml.generate_rays(xy)):
        np.testing.assert_allclose(got, expect, atol=1e-5)
    image = obscura.render(SCENES / name, spp=1)
    assert image.shape == (240, 320, 4) and np.isfinite(image).all()
    # The floor fills the bottom row, the sky the top one.
    assert image[-1, :, 3].min() == 1.0 and image[0, :, 3].max() == 0.0


def test_a_bad_pbrt_scene_names_its_file_and_line(tmp_path):
    bad = tmp_path / "bad.pbrt"
    bad.write_text(
        'LookAt 0 0 5  0 0 0  0 1 0\nCamera "perspective" "float fov" [ 40 ]\n'
        'Film "rgb" "integer xresolution" [ 0 ] "integer yresolution" [ 24 ]\nWorldBegin\n'
    )
    with pytest.raises(ValueError, match=f"{bad}:3"):
        obscura.load_scene(bad)
    with pytest.raises(ValueError, match=f"{bad}:3"):
        obscura.render(bad)


STEREO = """
[camera.stereo]
interaxial = 0.3
convergence = 4.0
layout = "{layout}"
"""


def stereo_scene(tmp_path, layout):
    text = (SCENES / "spheres-perspective.toml").read_text()
    assert "[camera.stereo]" not in text
    # The [camera] table is followed by others: put the stereo sub-table at the end.
    path = tmp_path / f"stereo-{layout}.toml"
    path.write_text(text + STEREO.format(layout=layout))
    return path


@pytest.mark.parametrize("layout", ["side_by_side", "anaglyph", "separate"])
def test_stereo_pairs_are_composed_as_their_layout_says(tmp_path, layout):
    path = stereo_scene(tmp_path, layout)
    mono = obscura.render(SCENES / "spheres-perspective.toml", spp=1, threads=2)
    got = obscura.render(path, spp=1, threads=2)
    if layout == "separate":
        left, right = got
        assert left.shape == right.shape == mono.shape
        assert not (bits(left) == bits(right)).all()
    elif layout == "side_by_side":
        assert got.shape == (240, 640, 4)
        assert not (bits(got[:, :320]) == bits(got[:, 320:])).all()
    else:
        assert got.shape == mono.shape
    if OBSCURA_BIN:
        out = tmp_path / "cli.exr"
        cmd = [OBSCURA_BIN, "render", str(path), "-o", str(out), "--spp", "1"]
        subprocess.run(cmd, check=True, capture_output=True)
        if layout == "separate":
            for eye, img in zip(["left", "right"], got):
                cli = obscura.read_exr(tmp_path / f"cli-{eye}.exr")
                assert (bits(cli) == bits(img)).all()
        else:
            assert (bits(obscura.read_exr(out)) == bits(got)).all()


def test_cube_map_faces_equal_the_command_line(tmp_path):
    path = tmp_path / "cube.toml"
    text = (SCENES / "spheres-perspective.toml").read_text()
    path.write_text(text.replace("resolution = [320, 240]", "resolution = [32, 32]"))
    faces = obscura.render(path, spp=1, cube_map=True)
    assert sorted(faces) == sorted(["px", "nx", "py", "ny", "pz", "nz"])
    assert all(f.shape == (32, 32, 4) for f in faces.values())
    # Up (+y) sees the sky only, down (-y) the floor only: alpha 0 and 1.
    assert faces["py"][..., 3].max() == 0.0 and faces["ny"][..., 3].min() == 1.0
    if OBSCURA_BIN:
        out = tmp_path / "cli.exr"
        cmd = [OBSCURA_BIN, "render", str(path), "-o", str(out), "--spp", "1", "--cube-map"]
        subprocess.run(cmd, check=True, capture_output=True)
        for name, img in faces.items():
            assert (bits(obscura.read_exr(tmp_path / f"cli-{name}.exr")) == bits(img)).all()


FIXTURE = pathlib.Path(__file__).parent / "data" / "rays.json"


def from_bits(values, columns):
    a = np.array(values, dtype=np.uint32).view(np.float32)
    return a.reshape(-1, columns) if columns > 1 else a


@pytest.mark.parametrize("case", json.loads(FIXTURE.read_text())["cameras"], ids=lambda c: c["name"])
def test_bindings_equal_the_rust_crates_bit_for_bit(case):
    # Expected values written by the Rust crates themselves (tests/it/py_fixture.rs).
    cam = obscura.Camera.from_toml(case["toml"])
    o, d, valid = cam.generate_rays(
        from_bits(case["raster_xy"], 2),
        lens_uv=from_bits(case["lens_uv"], 2),
        time=from_bits(case["time"], 1),
    )
    assert (valid == np.array(case["valid"])).all()
    assert (bits(o) == np.array(case["origins"], np.uint32).reshape(-1, 3)).all()
    assert (bits(d) == np.array(case["directions"], np.uint32).reshape(-1, 3)).all()
    points = from_bits(case["points"], 3)
    xy, seen = cam.project(points)
    assert (seen == np.array(case["points_valid"])).all()
    assert (bits(xy) == np.array(case["raster_of_points"], np.uint32).reshape(-1, 2)).all()


def realistic_macro(tmp_path, tilt):
    """The double Gauss 50 mm at the origin looking down -z, focused 0.5 m away, its plane of
    focus tilted by `tilt` degrees (about camera x, then y)."""
    lens = (SCENES / "lenses" / "double-gauss-50mm.dat").as_posix()
    path = tmp_path / f"realistic-{tilt[0]}-{tilt[1]}.toml"
    path.write_text(
        scene_text(
            'type = "realistic"\neye = [0.0, 0.0, 0.0]\ntarget = [0.0, 0.0, -1.0]\n'
            f'lens_file = "{lens}"\nfocus_distance = 0.5\n'
            f"focal_plane_tilt = [{tilt[0]}, {tilt[1]}]",
            resolution=(96, 64),
        )
    )
    return obscura.Camera.from_toml(path)


def miss_rms(cam, point):
    """RMS distance by which the camera's rays from `point`'s image, over a grid of lens
    samples, pass the world point."""
    xy, seen = cam.project(np.array([point], dtype=np.float32))
    assert seen.all()
    g = (np.arange(16) + 0.5) / 16
    lens = np.array([[u, v] for u in g for v in g], dtype=np.float32)
    o, d, ok = cam.generate_rays(np.repeat(xy, len(lens), axis=0), lens_uv=lens)
    assert ok.sum() > 100
    o, d = o[ok].astype(np.float64), d[ok].astype(np.float64)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    r = np.asarray(point, dtype=np.float64) - o
    off = r - (r * d).sum(axis=1, keepdims=True) * d
    return math.sqrt((off**2).sum(axis=1).mean())


def test_a_realistic_camera_tilts_its_plane_of_focus(tmp_path):
    # Camera-space points (x, 0, 0.5 + x tan(40 deg)) lie on the tilted plane; the world is
    # camera space with z negated. Untilted, the near and far points are out of focus by the
    # lens's cone (about 1.5 mm RMS at f/2); tilted, the rays from each point's image meet
    # there up to the lens's own spot (a few tenths of a millimetre).
    tilted = realistic_macro(tmp_path, (0.0, 40.0))
    flat = realistic_macro(tmp_path, (0.0, 0.0))
    assert tilted.model == "realistic"
    slope = math.tan(math.radians(40.0))
    for x in (-0.1, 0.1):
        point = (x, 0.0, -(0.5 + x * slope))
        sharp, blurred = miss_rms(tilted, point), miss_rms(flat, point)
        assert blurred > 1e-3, blurred
        assert sharp < 0.3 * blurred, (x, sharp, blurred)
