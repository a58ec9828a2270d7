//! Python bindings of Obscura: the package `obscura` (import name), built with maturin.
//!
//! - [`PyCamera`] (`obscura.Camera`): any camera of the scene format, from a TOML text or file
//!   (`Camera.from_toml`) or from OpenCV calibration (`Camera.from_opencv`,
//!   `Camera.from_opencv_fisheye`); `generate_rays`, `project` and `pixel_rays` take and give
//!   numpy arrays and run over the batch in parallel (rayon) with the GIL released.
//! - [`PyScene`] (`obscura.Scene`, made by `obscura.load_scene`) and `obscura.render`: the
//!   renderer of `obscura render`, giving the same float32 RGBA image bit for bit; Ctrl-C
//!   interrupts it (KeyboardInterrupt).
//!
//! Conventions are the scene format's: raster positions in pixels with pixel `(i, j)` covering
//! `[i, i+1) x [j, j+1)`, so pixel centres are at `+0.5`; camera +z is the view, world units as
//! in the scene file. Errors are Python exceptions (`ValueError` naming the file, key and line
//! for a bad scene; `TypeError`/`ValueError` for arrays of the wrong dtype or shape), never a
//! crash of the interpreter.
#![deny(missing_docs)]

use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArrayDyn};
use obscura_camera::{
    AnyCamera, Camera, CameraBase, CameraError, CameraSample, FilmGeometry, OpenCvCamera,
    OpenCvFisheyeCamera, OpenCvIntrinsics, Shutter, opencv_pose,
};
use obscura_render::{
    IntegratorKind, RenderError, RenderOptions, RenderScene, SceneDescription, camera_of,
    load_description, parse_description, read_exr,
};
use obscura_sample::{Sampler, SamplerKind};
use obscura_space::{Point2, Point3};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, mpsc};
use std::time::Duration;

/// Rays per rayon job: large enough that scheduling costs nothing next to the rays.
const CHUNK: usize = 4096;

/// The most rays `pixel_rays` makes at once (28 bytes each: 7.5 GB of arrays).
const MAX_PIXEL_RAYS: u64 = 1 << 28;

/// How often a render's waiting thread checks for Ctrl-C and reports progress.
const POLL: Duration = Duration::from_millis(50);

fn render_err(e: RenderError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

fn camera_err(e: CameraError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// `obj` as a C-contiguous numpy array of `dtype` ("float32" or "float64"), after checking that
/// it holds numbers (TypeError otherwise, naming the argument and its dtype).
fn numeric_array<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    dtype: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let np = obj.py().import("numpy")?;
    let arr = np.call_method1("asarray", (obj,)).map_err(|e| {
        PyTypeError::new_err(format!("{name}: cannot be read as a numeric array ({e})"))
    })?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "f" | "i" | "u") {
        let dt = arr.getattr("dtype")?.str()?.to_string();
        return Err(PyTypeError::new_err(format!(
            "{name}: expected an array of floats or integers, got dtype {dt}"
        )));
    }
    // asarray copies only when the dtype or the layout differ, and keeps a 0-d array 0-d.
    let kwargs = pyo3::types::PyDict::new(obj.py());
    kwargs.set_item("dtype", dtype)?;
    kwargs.set_item("order", "C")?;
    np.call_method("asarray", (arr,), Some(&kwargs))
}

/// `(3, 2)`: a shape as Python writes it.
fn shape_str(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The shape of a numpy array.
fn shape_of(arr: &Bound<'_, PyAny>) -> PyResult<Vec<usize>> {
    arr.getattr("shape")?.extract()
}

/// Values of `obj` as f32, flattened, with its shape.
fn f32_values(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<(Vec<f32>, Vec<usize>)> {
    let arr = numeric_array(obj, name, "float32")?;
    let shape = shape_of(&arr)?;
    let ro: PyReadonlyArrayDyn<'_, f32> = arr.extract()?;
    let values = match ro.as_slice() {
        Ok(slice) => slice.to_vec(),
        Err(_) => ro.as_array().iter().copied().collect(),
    };
    Ok((values, shape))
}

/// Values of `obj` as f64, flattened, with its shape.
fn f64_values(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<(Vec<f64>, Vec<usize>)> {
    let arr = numeric_array(obj, name, "float64")?;
    let shape = shape_of(&arr)?;
    let ro: PyReadonlyArrayDyn<'_, f64> = arr.extract()?;
    let values = match ro.as_slice() {
        Ok(slice) => slice.to_vec(),
        Err(_) => ro.as_array().iter().copied().collect(),
    };
    Ok((values, shape))
}

/// `(N, C)` rows of finite f32 values; ValueError naming the argument for another shape or a
/// NaN/infinity.
fn rows<const C: usize>(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<[f32; C]>> {
    let arr = numeric_array(obj, name, "float32")?;
    let shape = shape_of(&arr)?;
    if shape.len() != 2 || shape[1] != C {
        return Err(PyValueError::new_err(format!(
            "{name}: expected an array of shape (N, {C}), got shape {}",
            shape_str(&shape)
        )));
    }
    // One pass from numpy's buffer (C-contiguous after numeric_array) to rows.
    let ro: PyReadonlyArrayDyn<'_, f32> = arr.extract()?;
    let slice = ro.as_slice()?;
    check_finite(slice, name, C)?;
    Ok(slice
        .chunks_exact(C)
        .map(|c| std::array::from_fn(|k| c[k]))
        .collect())
}

/// ValueError naming the first row with a NaN or infinite value.
fn check_finite<T: Into<f64> + Copy>(values: &[T], name: &str, columns: usize) -> PyResult<()> {
    match values.iter().position(|v| !(*v).into().is_finite()) {
        Some(i) => Err(PyValueError::new_err(format!(
            "{name}[{}]: NaN or infinite values are not allowed",
            i / columns.max(1)
        ))),
        None => Ok(()),
    }
}

/// `n` values from `obj`: a scalar (used for all) or an array of shape (N,), finite.
fn per_ray(obj: &Bound<'_, PyAny>, name: &str, n: usize) -> PyResult<Vec<f32>> {
    let (values, shape) = f32_values(obj, name)?;
    check_finite(&values, name, 1)?;
    match shape.as_slice() {
        [] => Ok(vec![values[0]; n]),
        [m] if *m == n => Ok(values),
        _ => Err(PyValueError::new_err(format!(
            "{name}: expected a number or an array of shape ({n},), got shape {}",
            shape_str(&shape)
        ))),
    }
}

/// Exactly `n` finite f64 values from an array of any shape with `n` elements (OpenCV's
/// (3, 1) rvecs and (1, 5) distortion rows included).
fn vector(obj: &Bound<'_, PyAny>, name: &str, n: Option<usize>) -> PyResult<Vec<f64>> {
    let (values, shape) = f64_values(obj, name)?;
    if let Some(n) = n
        && values.len() != n
    {
        return Err(PyValueError::new_err(format!(
            "{name}: expected {n} values, got shape {}",
            shape_str(&shape)
        )));
    }
    check_finite(&values, name, 1)?;
    Ok(values)
}

/// An (N, C) float32 numpy array from `N * C` values.
fn array2<'py>(py: Python<'py>, values: Vec<f32>, columns: usize) -> PyResult<Bound<'py, PyAny>> {
    let n = values.len() / columns;
    Ok(values.into_pyarray(py).reshape([n, columns])?.into_any())
}

/// Fills `origins`, `directions` and `valid` with the rays of `samples`, in parallel; a sample
/// with no ray gets NaN origin and direction and `valid = false`.
fn trace_samples(
    camera: &AnyCamera,
    n: usize,
    sample: impl Fn(usize) -> CameraSample + Sync,
) -> (Vec<f32>, Vec<f32>, Vec<bool>) {
    let mut origins = vec![f32::NAN; 3 * n];
    let mut directions = vec![f32::NAN; 3 * n];
    let mut valid = vec![false; n];
    origins
        .par_chunks_mut(3 * CHUNK)
        .zip(directions.par_chunks_mut(3 * CHUNK))
        .zip(valid.par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(chunk, ((o, d), v))| {
            for k in 0..v.len() {
                let Some(r) = camera.generate_ray(&sample(chunk * CHUNK + k)) else {
                    continue;
                };
                let (p, dir) = (r.ray.origin, r.ray.direction);
                o[3 * k..3 * k + 3].copy_from_slice(&[p.x, p.y, p.z]);
                d[3 * k..3 * k + 3].copy_from_slice(&[dir.x, dir.y, dir.z]);
                v[k] = true;
            }
        });
    (origins, directions, valid)
}

/// A camera model of Obscura (any model of the scene format).
///
/// Raster positions are in pixels, pixel `(i, j)` covering `[i, i+1) x [j, j+1)`: pixel
/// centres are at `i + 0.5`, `j + 0.5`; x grows right and y down. Rays have unit directions.
#[pyclass(name = "Camera", module = "obscura", frozen)]
pub struct PyCamera {
    /// Boxed: Python objects are only 16-byte aligned, and the camera may want more.
    camera: Box<AnyCamera>,
    /// The sampler `pixel_rays` draws from: the scene's `[sampler] type`, else the format's
    /// default.
    sampler: SamplerKind,
}

/// The scene format's default sampler (`[sampler] type` absent).
const DEFAULT_SAMPLER: SamplerKind = SamplerKind::Sobol;

/// Reads a scene description from a path or from TOML text: an `os.PathLike`, or a one-line
/// `str` that names an existing file or has no `=` (so cannot be a scene), is read as a file;
/// any other `str` is parsed as the text of a scene file (errors then name `<string>`).
fn description_of(obj: &Bound<'_, PyAny>) -> PyResult<SceneDescription> {
    if let Ok(text) = obj.extract::<String>() {
        let as_path = Path::new(&text);
        if !text.contains('\n') && (as_path.is_file() || !text.contains('=')) {
            return load_description(as_path).map_err(render_err);
        }
        return parse_description(Path::new("<string>"), &text).map_err(render_err);
    }
    match obj.extract::<PathBuf>() {
        Ok(path) => load_description(&path).map_err(render_err),
        Err(_) => Err(PyTypeError::new_err(format!(
            "expected TOML text, a path string or an os.PathLike, got {}",
            obj.get_type().name()?
        ))),
    }
}

/// The film of an OpenCV calibration: `size` is (width, height).
fn opencv_base(
    rvec: &Bound<'_, PyAny>,
    tvec: &Bound<'_, PyAny>,
    size: (u32, u32),
) -> PyResult<CameraBase> {
    let r = vector(rvec, "rvec", Some(3))?;
    let t = vector(tvec, "tvec", Some(3))?;
    let pose = opencv_pose([r[0], r[1], r[2]], [t[0], t[1], t[2]]).map_err(camera_err)?;
    let shutter = Shutter::new(0.0, 1.0).map_err(camera_err)?;
    let film = FilmGeometry::new([size.0, size.1], None, None).map_err(camera_err)?;
    Ok(CameraBase::new(pose, shutter, film))
}

/// fx, fy, cx, cy of a 3x3 camera matrix without skew.
fn intrinsics(k: &Bound<'_, PyAny>) -> PyResult<OpenCvIntrinsics> {
    let (m, shape) = f64_values(k, "K")?;
    if shape != [3, 3] {
        return Err(PyValueError::new_err(format!(
            "K: expected a 3x3 camera matrix, got shape {}",
            shape_str(&shape)
        )));
    }
    check_finite(&m, "K", 3)?;
    if m[1] != 0.0 || m[3] != 0.0 || m[6] != 0.0 || m[7] != 0.0 || m[8] != 1.0 {
        return Err(PyValueError::new_err(format!(
            "K: expected [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (no skew), got {m:?}"
        )));
    }
    Ok(OpenCvIntrinsics {
        fx: m[0],
        fy: m[4],
        cx: m[2],
        cy: m[5],
    })
}

fn model_name(c: &AnyCamera) -> &'static str {
    match c {
        AnyCamera::Perspective(_) => "perspective",
        AnyCamera::Orthographic(_) => "orthographic",
        AnyCamera::Environment(_) => "environment",
        AnyCamera::Fisheye(_) => "fisheye",
        AnyCamera::Cylindrical(_) => "cylindrical",
        AnyCamera::Octahedral(_) => "octahedral",
        AnyCamera::CubeFace(_) => "cube_face",
        AnyCamera::Ods(_) => "ods",
        AnyCamera::OpenCv(_) => "opencv",
        AnyCamera::OpenCvFisheye(_) => "opencv_fisheye",
        AnyCamera::Realistic(_) => "realistic",
    }
}

#[pymethods]
impl PyCamera {
    /// Camera.from_toml(text_or_path)
    ///
    /// The camera of a scene file: its [camera] and [film] tables (a scene needs both; the
    /// other tables are checked as `obscura check` does, then ignored). `text_or_path` is the
    /// TOML text, a path string or an os.PathLike. Every camera model of the scene format works.
    /// Raises ValueError naming the file, key and line for a bad scene.
    #[staticmethod]
    fn from_toml(text_or_path: &Bound<'_, PyAny>) -> PyResult<PyCamera> {
        let d = description_of(text_or_path)?;
        let camera = camera_of(&d).map_err(render_err)?;
        Ok(PyCamera {
            camera: Box::new(camera),
            sampler: d.sampler.kind,
        })
    }

    /// Camera.from_opencv(K, dist, rvec, tvec, size)
    ///
    /// An OpenCV pinhole camera with distortion, as cv2.projectPoints takes it: K the 3x3
    /// camera matrix (no skew), dist 4, 5, 8, 12 or 14 coefficients (k1 k2 p1 p2 [k3 [k4 k5
    /// k6 [s1 s2 s3 s4 [tx ty]]]]), rvec and tvec the extrinsics (world to camera), size =
    /// (width, height). OpenCV's pixel centres are at integers, Obscura's at +0.5: a point
    /// OpenCV projects to (u, v) is at raster (u + 0.5, v + 0.5) here.
    #[staticmethod]
    fn from_opencv(
        #[allow(non_snake_case)] K: &Bound<'_, PyAny>,
        dist: &Bound<'_, PyAny>,
        rvec: &Bound<'_, PyAny>,
        tvec: &Bound<'_, PyAny>,
        size: (u32, u32),
    ) -> PyResult<PyCamera> {
        let k = intrinsics(K)?;
        let d = vector(dist, "dist", None)?;
        let base = opencv_base(rvec, tvec, size)?;
        let camera = OpenCvCamera::new(base, k, &d).map_err(camera_err)?;
        Ok(PyCamera {
            camera: Box::new(camera.into()),
            sampler: DEFAULT_SAMPLER,
        })
    }

    /// Camera.from_opencv_fisheye(K, D, rvec, tvec, size)
    ///
    /// An OpenCV fisheye (Kannala-Brandt) camera, as cv2.fisheye.projectPoints takes it: K the
    /// 3x3 camera matrix (no skew), D the four coefficients k1..k4, rvec and tvec the
    /// extrinsics, size = (width, height). Raster positions are OpenCV's plus 0.5.
    #[staticmethod]
    fn from_opencv_fisheye(
        #[allow(non_snake_case)] K: &Bound<'_, PyAny>,
        #[allow(non_snake_case)] D: &Bound<'_, PyAny>,
        rvec: &Bound<'_, PyAny>,
        tvec: &Bound<'_, PyAny>,
        size: (u32, u32),
    ) -> PyResult<PyCamera> {
        let k = intrinsics(K)?;
        let d = vector(D, "D", None)?;
        let base = opencv_base(rvec, tvec, size)?;
        let camera = OpenCvFisheyeCamera::new(base, k, &d).map_err(camera_err)?;
        Ok(PyCamera {
            camera: Box::new(camera.into()),
            sampler: DEFAULT_SAMPLER,
        })
    }

    /// The camera model's name in the scene format (e.g. "perspective", "opencv").
    #[getter]
    fn model(&self) -> &'static str {
        model_name(&self.camera)
    }

    /// (width, height) of the film in pixels.
    #[getter]
    fn resolution(&self) -> (u32, u32) {
        let [w, h] = self.camera.film().resolution();
        (w, h)
    }

    /// (x0, x1, y0, y1): the pixels rendered (the crop window), half-open.
    #[getter]
    fn pixel_bounds(&self) -> (u32, u32, u32, u32) {
        let [x0, x1, y0, y1] = self.camera.film().pixel_bounds();
        (x0, x1, y0, y1)
    }

    /// (open, close): the shutter interval.
    #[getter]
    fn shutter(&self) -> (f32, f32) {
        let s = self.camera.shutter();
        (s.open, s.close)
    }

    fn __repr__(&self) -> String {
        let [w, h] = self.camera.film().resolution();
        format!(
            "obscura.Camera(model={:?}, resolution=({w}, {h}))",
            self.model()
        )
    }

    /// cam.generate_rays(raster_xy, lens_uv=None, time=None) -> (origins, directions, valid)
    ///
    /// The world-space rays through raster positions `raster_xy` (N, 2) (pixel centres at
    /// +0.5). `lens_uv` (N, 2) are lens samples in [0, 1)^2, warped onto the aperture (default
    /// the lens centre, 0.5); `time` is the shutter sample u in [0, 1), a number or (N,),
    /// mapped onto the shutter interval (default 0: shutter open). Returns float32 origins
    /// (N, 3), unit directions (N, 3) and a bool mask (N,): false where no ray leaves that film
    /// point (past a fisheye's image circle, say), with NaN origin and direction there.
    /// Runs in parallel with the GIL released.
    #[pyo3(signature = (raster_xy, lens_uv=None, time=None))]
    fn generate_rays<'py>(
        &self,
        py: Python<'py>,
        raster_xy: &Bound<'py, PyAny>,
        lens_uv: Option<&Bound<'py, PyAny>>,
        time: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let film = rows::<2>(raster_xy, "raster_xy")?;
        let n = film.len();
        let lens = match lens_uv {
            Some(l) => {
                let l = rows::<2>(l, "lens_uv")?;
                if l.len() != n {
                    return Err(PyValueError::new_err(format!(
                        "lens_uv: expected shape ({n}, 2) like raster_xy, got ({}, 2)",
                        l.len()
                    )));
                }
                Some(l)
            }
            None => None,
        };
        let time = time.map(|t| per_ray(t, "time", n)).transpose()?;
        let camera = &self.camera;
        let (o, d, v) = py.allow_threads(|| {
            trace_samples(camera, n, |i| {
                let mut s = CameraSample::at(Point2::new(film[i][0], film[i][1]));
                if let Some(l) = &lens {
                    s.p_lens = glam::Vec2::from(l[i]);
                }
                if let Some(t) = &time {
                    s.time = t[i];
                }
                s
            })
        });
        let out = (array2(py, o, 3)?, array2(py, d, 3)?, v.into_pyarray(py));
        out.into_pyobject(py)
    }

    /// cam.project(points, time=None) -> (raster_xy, valid)
    ///
    /// The raster positions (N, 2) float32 (pixel centres at +0.5) of world points (N, 3), as
    /// seen through the lens centre at `time` (in the shutter's unit, default the shutter's
    /// opening). `valid` (N,) is false (and raster_xy NaN) where the camera cannot see the
    /// point (behind a projective camera, outside [near, far], ...); positions outside the
    /// image are returned as they are. Runs in parallel with the GIL released.
    #[pyo3(signature = (points, time=None))]
    fn project<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        time: Option<f32>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let points = rows::<3>(points, "points")?;
        let time = time.unwrap_or(self.camera.shutter().open);
        if !time.is_finite() {
            return Err(PyValueError::new_err("time: must be finite"));
        }
        let n = points.len();
        let camera = &self.camera;
        let (xy, valid) = py.allow_threads(|| {
            let mut xy = vec![f32::NAN; 2 * n];
            let mut valid = vec![false; n];
            xy.par_chunks_mut(2 * CHUNK)
                .zip(valid.par_chunks_mut(CHUNK))
                .enumerate()
                .for_each(|(chunk, (xy, v))| {
                    for k in 0..v.len() {
                        let [x, y, z] = points[chunk * CHUNK + k];
                        if let Some(r) = camera.project(Point3::new(x, y, z), time) {
                            xy[2 * k] = r.x;
                            xy[2 * k + 1] = r.y;
                            v[k] = true;
                        }
                    }
                });
            (xy, valid)
        });
        (array2(py, xy, 2)?, valid.into_pyarray(py)).into_pyobject(py)
    }

    /// cam.pixel_rays(spp=1, seed=0) -> (origins, directions, valid)
    ///
    /// The camera rays of the whole film (the crop window's pixels), `spp` per pixel, as the
    /// renderer draws them: sample `s` of pixel (x, y) takes its film offset inside the pixel,
    /// its lens sample and its time sample from the sampler of the scene's `[sampler] type`
    /// (Sobol for cameras not from a scene file) with this `seed`. For a scene whose geometry
    /// does not move these are exactly the renderer's camera rays. Ray `i` is sample
    /// `i % spp` of pixel (x0 + (i // spp) % W, y0 + i // (spp * W)): row by row, samples of a
    /// pixel together; reshape to (H, W, spp, 3) for a per-pixel view. Returns float32 origins
    /// (N, 3), directions (N, 3) and the bool mask (N,) as generate_rays does.
    #[pyo3(signature = (spp=1, seed=0))]
    fn pixel_rays<'py>(
        &self,
        py: Python<'py>,
        spp: u32,
        seed: u64,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let sampler = Sampler::new(self.sampler, spp, seed)
            .map_err(|e| PyValueError::new_err(format!("spp: {e}")))?;
        let [x0, x1, y0, y1] = self.camera.film().pixel_bounds();
        let (w, h) = (x1 - x0, y1 - y0);
        let n = u64::from(w) * u64::from(h) * u64::from(spp);
        if n > MAX_PIXEL_RAYS {
            return Err(PyValueError::new_err(format!(
                "pixel_rays: {w}x{h} pixels at {spp} spp are {n} rays, more than the {MAX_PIXEL_RAYS} one call makes; use a crop window or generate_rays in batches"
            )));
        }
        let camera = &self.camera;
        let uses_lens = camera.uses_lens_sample();
        let uses_time = camera.uses_time_sample() && camera.world_from_camera().is_animated();
        let spp_us = spp as usize;
        let w_us = w as usize;
        let (o, d, v) = py.allow_threads(|| {
            trace_samples(camera, n as usize, |i| {
                let s = (i % spp_us) as u32;
                let pixel = i / spp_us;
                let x = x0 + (pixel % w_us) as u32;
                let y = y0 + (pixel / w_us) as u32;
                let mut stream = sampler.stream([x, y], s);
                CameraSample::from_stream(&mut stream, [x, y], uses_lens, uses_time)
            })
        });
        (array2(py, o, 3)?, array2(py, d, 3)?, v.into_pyarray(py)).into_pyobject(py)
    }
}

/// A scene loaded from a file and built (geometry, BVHs, materials, lights), ready to render.
#[pyclass(name = "Scene", module = "obscura", frozen)]
pub struct PyScene {
    /// The built scene, boxed (its BVH wants more alignment than a Python object has);
    /// `render` sets its sampler and integrator for each call.
    scene: Mutex<Box<RenderScene>>,
    /// The file's own sampler settings and integrator, restored when a call overrides none.
    file_sampler: (SamplerKind, u32, u64),
    file_integrator: IntegratorKind,
    path: PathBuf,
}

fn lock(m: &Mutex<Box<RenderScene>>) -> std::sync::MutexGuard<'_, Box<RenderScene>> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

#[pymethods]
impl PyScene {
    /// (width, height) of the film in pixels.
    #[getter]
    fn resolution(&self) -> (u32, u32) {
        let [w, h] = lock(&self.scene).description.film.resolution;
        (w, h)
    }

    /// Samples per pixel the file asks for.
    #[getter]
    fn spp(&self) -> u32 {
        self.file_sampler.1
    }

    /// The file's sampler seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.file_sampler.2
    }

    /// The file's integrator: path, depth, distance, position, normal or albedo.
    #[getter]
    fn integrator(&self) -> &'static str {
        self.file_integrator.name()
    }

    /// The scene file's path.
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// The scene's camera, as Camera.from_toml of the file gives it.
    #[getter]
    fn camera(&self) -> PyCamera {
        PyCamera {
            camera: Box::new(lock(&self.scene).camera.clone()),
            sampler: self.file_sampler.0,
        }
    }

    fn __repr__(&self) -> String {
        let (w, h) = self.resolution();
        format!(
            "obscura.Scene({:?}, resolution=({w}, {h}), spp={}, integrator={:?})",
            self.path.display().to_string(),
            self.spp(),
            self.integrator()
        )
    }
}

/// load_scene(path) -> Scene
///
/// Reads, validates and builds a scene file (meshes and maps load now, relative to the file).
/// Raises ValueError naming the file, key and line for a bad scene.
#[pyfunction]
fn load_scene(py: Python<'_>, path: PathBuf) -> PyResult<PyScene> {
    let d = load_description(&path).map_err(render_err)?;
    let file_sampler = (d.sampler.kind, d.sampler.spp, d.sampler.seed);
    let file_integrator = d.integrator.kind;
    let scene = py
        .allow_threads(|| RenderScene::build(d))
        .map_err(render_err)?;
    Ok(PyScene {
        scene: Mutex::new(Box::new(scene)),
        file_sampler,
        file_integrator,
        path,
    })
}

/// What a render's waiting thread does between polls: report progress, check Ctrl-C.
enum Progress {
    Off,
    Stderr,
    Callback(Py<PyAny>),
}

impl Progress {
    /// Reports (tiles done, tiles in all); an error (KeyboardInterrupt from Ctrl-C, or the
    /// callback's own) stops the render.
    fn poll(&self, py: Python<'_>, done: u64, total: u64) -> PyResult<()> {
        py.check_signals()?;
        match self {
            Progress::Off => Ok(()),
            Progress::Stderr => {
                let percent = (done * 100).checked_div(total).unwrap_or(0);
                let line = format!("\rrendering: {done}/{total} tiles ({percent}%)");
                py.import("sys")?
                    .getattr("stderr")?
                    .call_method1("write", (line,))?;
                Ok(())
            }
            Progress::Callback(f) => f.call1(py, (done, total)).map(drop),
        }
    }
}

/// render(scene, spp=None, integrator=None, seed=None, threads=None, progress=False)
///
/// Renders `scene` (a Scene, or a path to load) and returns its image as a float32 numpy array
/// (H, W, 4): linear RGB and alpha (the fraction of the pixel whose camera rays hit geometry),
/// row 0 at the top, the crop window's pixels. Equal bit for bit to the EXR of
/// `obscura render SCENE --spp .. --integrator .. --seed ..` with the same overrides, for any
/// `threads`. `integrator` is path, depth, distance, position, normal or albedo (the AOVs);
/// `threads` defaults to one per core. `progress` is False, True (a line on sys.stderr) or a
/// callable taking (tiles_done, tiles_total), called from the calling thread. Ctrl-C stops the
/// render and raises KeyboardInterrupt; so does an exception from the progress callable. The
/// GIL is released while rendering. Stereo pairs and cube maps (`obscura render --cube-map`)
/// are not composed here: a stereo scene renders its centre view.
#[pyfunction]
#[pyo3(signature = (scene, spp=None, integrator=None, seed=None, threads=None, progress=None))]
fn render<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    spp: Option<u32>,
    integrator: Option<&str>,
    seed: Option<u64>,
    threads: Option<usize>,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let loaded;
    let scene: &PyScene = match scene.downcast::<PyScene>() {
        Ok(s) => s.get(),
        Err(_) => {
            let path: PathBuf = scene.extract().map_err(|_| {
                PyTypeError::new_err("scene: expected an obscura.Scene or a path to a scene file")
            })?;
            loaded = Bound::new(py, load_scene(py, path)?)?;
            loaded.get()
        }
    };
    if spp == Some(0) {
        return Err(PyValueError::new_err("spp: must be >= 1, got 0"));
    }
    if threads == Some(0) {
        return Err(PyValueError::new_err("threads: must be >= 1, got 0"));
    }
    let kind = match integrator {
        Some(name) => IntegratorKind::parse(name).ok_or_else(|| {
            PyValueError::new_err(format!(
                "integrator: unknown integrator `{name}`, expected path, depth, distance, position, normal or albedo"
            ))
        })?,
        None => scene.file_integrator,
    };
    let (sampler_kind, file_spp, file_seed) = scene.file_sampler;
    let spp = spp.unwrap_or(file_spp);
    let seed = seed.unwrap_or(file_seed);
    let sampler = Sampler::new(sampler_kind, spp, seed)
        .map_err(|e| PyValueError::new_err(format!("spp: {e}")))?;
    let progress = match progress {
        None => Progress::Off,
        Some(p) if p.is_callable() => Progress::Callback(p.clone().unbind()),
        Some(p) => {
            if p.is_truthy()? {
                Progress::Stderr
            } else {
                Progress::Off
            }
        }
    };

    let cancel = AtomicBool::new(false);
    let tiles_done = AtomicU64::new(0);
    let tiles_total = AtomicU64::new(0);
    let on_tile = |done: u64, total: u64| {
        tiles_done.fetch_max(done, Ordering::Relaxed);
        tiles_total.store(total, Ordering::Relaxed);
    };
    let (outcome, interrupted) = py.allow_threads(|| {
        let mut guard = lock(&scene.scene);
        guard.sampler = sampler;
        guard.description.sampler.spp = spp;
        guard.description.sampler.seed = seed;
        guard.description.integrator.kind = kind;
        let rs: &RenderScene = &guard;
        std::thread::scope(|s| {
            let (tx, rx) = mpsc::channel();
            let (cancel, on_tile) = (&cancel, &on_tile);
            s.spawn(move || {
                let options = RenderOptions {
                    threads,
                    cancel: Some(cancel),
                    on_tile: Some(on_tile),
                    ..Default::default()
                };
                // The receiver waits for this; if it has gone, nobody needs the image.
                let _ = tx.send(obscura_render::render(rs, options));
            });
            let mut interrupted: Option<PyErr> = None;
            loop {
                match rx.recv_timeout(POLL) {
                    Ok(outcome) => return (Some(outcome), interrupted),
                    Err(mpsc::RecvTimeoutError::Timeout) => {
                        if interrupted.is_none() {
                            let (done, total) = (
                                tiles_done.load(Ordering::Relaxed),
                                tiles_total.load(Ordering::Relaxed),
                            );
                            if let Err(e) = Python::with_gil(|py| progress.poll(py, done, total)) {
                                cancel.store(true, Ordering::Relaxed);
                                interrupted = Some(e);
                            }
                        }
                    }
                    // The render thread ended without an answer (it panicked); the scope
                    // re-raises its panic, which PyO3 turns into a Python exception.
                    Err(mpsc::RecvTimeoutError::Disconnected) => return (None, interrupted),
                }
            }
        })
    });
    if let Progress::Stderr = progress {
        py.import("sys")?
            .getattr("stderr")?
            .call_method1("write", ("\n",))?;
    }
    if let Some(e) = interrupted {
        return Err(e);
    }
    let outcome = outcome
        .ok_or_else(|| PyValueError::new_err("the render stopped without an image"))?
        .map_err(|e| {
            PyValueError::new_err(format!("threads: cannot start the worker threads: {e}"))
        })?;
    image_array(py, outcome.film.resolve())
}

/// read_exr(path) -> numpy.ndarray
///
/// An RGBA EXR (such as `obscura render` writes) as a float32 array (H, W, 4), row 0 at the
/// top, values exactly as stored: for comparing renders bit for bit with the command line.
#[pyfunction]
#[pyo3(name = "read_exr")]
fn read_exr_file<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyAny>> {
    let (image, _) = py.allow_threads(|| read_exr(&path)).map_err(render_err)?;
    image_array(py, image)
}

/// An (H, W, 4) float32 array of an image.
fn image_array(py: Python<'_>, image: obscura_render::Image) -> PyResult<Bound<'_, PyAny>> {
    let (w, h) = (image.width as usize, image.height as usize);
    let values: Vec<f32> = image.pixels.into_iter().flatten().collect();
    Ok(values.into_pyarray(py).reshape([h, w, 4])?.into_any())
}

/// Obscura's camera models and renderer: numpy arrays in and out.
#[pymodule]
#[pyo3(name = "_obscura")]
fn obscura_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyCamera>()?;
    m.add_class::<PyScene>()?;
    m.add_function(wrap_pyfunction!(load_scene, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(read_exr_file, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
