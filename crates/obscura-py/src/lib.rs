//! Python bindings of Obscura: the package `obscura` (import name), built with maturin.
//!
//! - [`PyCamera`] (`obscura.Camera`): any camera of the scene format, from a TOML text or file
//!   (`Camera.from_toml`) or from OpenCV calibration (`Camera.from_opencv`,
//!   `Camera.from_opencv_fisheye`); `generate_rays`, `project` and `pixel_rays` take and give
//!   numpy arrays and run over the batch in parallel (rayon) with the GIL released.
//! - [`PyScene`] (`obscura.Scene`, made by `obscura.load_scene` from a TOML, pbrt-v4 or
//!   Mitsuba 3 file) and `obscura.render`: the renderer of `obscura render`, giving the same
//!   float32 RGBA image bit for bit; Ctrl-C interrupts it (KeyboardInterrupt). A scene is lent
//!   to one render at a time, and nothing waits for it while holding the GIL.
//!
//! Conventions are the scene format's: raster positions in pixels with pixel `(i, j)` covering
//! `[i, i+1) x [j, j+1)`, so pixel centres are at `+0.5`; camera +z is the view, world units as
//! in the scene file. Errors are Python exceptions (`ValueError` naming the file, key and line
//! for a bad scene; `TypeError`/`ValueError` for arrays of the wrong dtype or shape), never a
//! crash of the interpreter.
#![deny(missing_docs)]

use numpy::{
    IntoPyArray, PyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyReadonlyArrayDyn,
    PyUntypedArrayMethods,
};
use obscura_camera::CubeFace;
use obscura_camera::{
    AnyCamera, Camera, CameraBase, CameraError, CameraSample, FilmGeometry, OpenCvCamera,
    OpenCvFisheyeCamera, OpenCvIntrinsics, Shutter, opencv_pose,
};
use obscura_render::{
    CameraDescription, CameraKind, IntegratorKind, RenderError, RenderOptions, RenderScene,
    SceneDescription, camera_of, compose_stereo, load_camera_description, parse_camera_description,
    read_exr,
};
use obscura_sample::{Sampler, SamplerKind};
use obscura_space::{Point2, Point3, Ray, World};
use pyo3::exceptions::{PyTypeError, PyUserWarning, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Condvar, Mutex, mpsc};
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

/// Writes the ray `ray_of` gives for every sample into `origins`, `directions` (3 values per
/// ray) and `valid`, in parallel. Every element is written (NaN and `false` where no ray
/// leaves), so reused `out=` arrays hold nothing of an earlier call. `sample(i)` returns `None`
/// for a sample whose input is not finite; the smallest such index is returned and the caller
/// raises for it.
fn fill_rays(
    ray_of: impl Fn(&CameraSample) -> Option<Ray<World>> + Sync,
    sample: impl Fn(usize) -> Option<CameraSample> + Sync,
    origins: &mut [f32],
    directions: &mut [f32],
    valid: &mut [bool],
) -> Option<usize> {
    let bad = AtomicUsize::new(usize::MAX);
    origins
        .par_chunks_mut(3 * CHUNK)
        .zip(directions.par_chunks_mut(3 * CHUNK))
        .zip(valid.par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(chunk, ((o, d), v))| {
            let first = chunk * CHUNK;
            let mut first_bad = usize::MAX;
            let rows = o.chunks_exact_mut(3).zip(d.chunks_exact_mut(3)).zip(v);
            for (k, ((o, d), v)) in rows.enumerate() {
                let ray = match sample(first + k) {
                    Some(s) => ray_of(&s),
                    None => {
                        first_bad = first_bad.min(first + k);
                        None
                    }
                };
                match ray {
                    Some(r) => {
                        let (p, w) = (r.origin, r.direction);
                        o.copy_from_slice(&[p.x, p.y, p.z]);
                        d.copy_from_slice(&[w.x, w.y, w.z]);
                        *v = true;
                    }
                    None => {
                        o.fill(f32::NAN);
                        d.fill(f32::NAN);
                        *v = false;
                    }
                }
            }
            bad.fetch_min(first_bad, Ordering::Relaxed);
        });
    match bad.into_inner() {
        usize::MAX => None,
        i => Some(i),
    }
}

/// The `out=` tuple of a call: exactly `names.len()` items, or a TypeError/ValueError.
fn out_tuple<'py>(out: &Bound<'py, PyAny>, names: &[&str]) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let list = names.join(", ");
    let tuple = out.downcast::<PyTuple>().map_err(|_| {
        PyTypeError::new_err(format!("out: expected a tuple ({list}) of numpy arrays"))
    })?;
    if tuple.len() != names.len() {
        return Err(PyValueError::new_err(format!(
            "out: expected {} arrays ({list}), got {}",
            names.len(),
            tuple.len()
        )));
    }
    Ok(tuple.iter().collect())
}

/// One `out=` array after checking its dtype, shape, layout and writability.
fn out_array<'py, T: numpy::Element, D: numpy::ndarray::Dimension>(
    item: Bound<'py, PyAny>,
    name: &str,
    shape: &[usize],
    dtype: &str,
) -> PyResult<Bound<'py, PyArray<T, D>>> {
    let want = shape_str(shape);
    let arr = item.downcast_into::<PyArray<T, D>>().map_err(|e| {
        PyTypeError::new_err(format!(
            "out: {name} must be a C-contiguous {dtype} numpy array of shape {want}, got {}",
            e.into_inner().get_type()
        ))
    })?;
    if arr.shape() != shape {
        return Err(PyValueError::new_err(format!(
            "out: {name} must have shape {want}, got {}",
            shape_str(arr.shape())
        )));
    }
    if !arr.is_c_contiguous() {
        return Err(PyValueError::new_err(format!(
            "out: {name} must be C-contiguous"
        )));
    }
    Ok(arr)
}

/// Write access to an output array; ValueError when it is read-only or already borrowed (the
/// same array given twice in `out=`).
fn writable<'py, T: numpy::Element, D: numpy::ndarray::Dimension>(
    arr: &Bound<'py, PyArray<T, D>>,
    name: &str,
) -> PyResult<numpy::PyReadwriteArray<'py, T, D>> {
    arr.try_readwrite().map_err(|e| {
        PyValueError::new_err(format!(
            "out: {name} cannot be written ({e}: read-only, or the same array given twice)"
        ))
    })
}

/// The (origins, directions, valid) arrays of a batch of `n` rays: the caller's `out=` arrays,
/// checked, or fresh zeroed ones (numpy's calloc, so pages are first touched by the parallel
/// fill).
type RayArrays<'py> = (
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray1<bool>>,
);

fn ray_arrays<'py>(
    py: Python<'py>,
    out: Option<&Bound<'py, PyAny>>,
    n: usize,
) -> PyResult<RayArrays<'py>> {
    let Some(out) = out else {
        return Ok((
            PyArray2::zeros(py, [n, 3], false),
            PyArray2::zeros(py, [n, 3], false),
            PyArray1::zeros(py, n, false),
        ));
    };
    let [o, d, v]: [Bound<'py, PyAny>; 3] = out_tuple(out, &["origins", "directions", "valid"])?
        .try_into()
        .map_err(|_| PyValueError::new_err("out: expected 3 arrays"))?;
    Ok((
        out_array(o, "origins", &[n, 3], "float32")?,
        out_array(d, "directions", &[n, 3], "float32")?,
        out_array(v, "valid", &[n], "bool")?,
    ))
}

/// Fills `arrays` with the rays `ray_of` gives for the samples of `sample` ([`fill_rays`])
/// with the GIL released, and returns them as the `(origins, directions, valid)` tuple, with
/// the first sample index whose input was not finite.
fn trace_into<'py>(
    py: Python<'py>,
    arrays: RayArrays<'py>,
    sample: impl Fn(usize) -> Option<CameraSample> + Sync + Send,
    ray_of: impl Fn(&CameraSample) -> Option<Ray<World>> + Sync + Send,
) -> PyResult<(Bound<'py, PyTuple>, Option<usize>)> {
    let (o_arr, d_arr, v_arr) = arrays;
    let bad = {
        let (mut o_rw, mut d_rw, mut v_rw) = (
            writable(&o_arr, "origins")?,
            writable(&d_arr, "directions")?,
            writable(&v_arr, "valid")?,
        );
        let (o, d, v) = (
            o_rw.as_slice_mut()?,
            d_rw.as_slice_mut()?,
            v_rw.as_slice_mut()?,
        );
        py.allow_threads(|| fill_rays(ray_of, sample, o, d, v))
    };
    Ok(((o_arr, d_arr, v_arr).into_pyobject(py)?, bad))
}

/// The (raster_xy, valid) arrays of `project`.
type ProjectArrays<'py> = (Bound<'py, PyArray2<f32>>, Bound<'py, PyArray1<bool>>);

/// The (raster_xy, valid) arrays of `project` for `n` points, as [`ray_arrays`] makes them.
fn project_arrays<'py>(
    py: Python<'py>,
    out: Option<&Bound<'py, PyAny>>,
    n: usize,
) -> PyResult<ProjectArrays<'py>> {
    let Some(out) = out else {
        return Ok((
            PyArray2::zeros(py, [n, 2], false),
            PyArray1::zeros(py, n, false),
        ));
    };
    let [xy, v]: [Bound<'py, PyAny>; 2] = out_tuple(out, &["raster_xy", "valid"])?
        .try_into()
        .map_err(|_| PyValueError::new_err("out: expected 2 arrays"))?;
    Ok((
        out_array(xy, "raster_xy", &[n, 2], "float32")?,
        out_array(v, "valid", &[n], "bool")?,
    ))
}

/// A read-only view of `obj` as `(N, C)` float32 values (converted only when its dtype or
/// layout differ); the caller checks finiteness as it reads.
fn rows_view<'py, const C: usize>(
    obj: &Bound<'py, PyAny>,
    name: &str,
) -> PyResult<PyReadonlyArray2<'py, f32>> {
    let arr = numeric_array(obj, name, "float32")?;
    let shape = shape_of(&arr)?;
    if shape.len() != 2 || shape[1] != C {
        return Err(PyValueError::new_err(format!(
            "{name}: expected an array of shape (N, {C}), got shape {}",
            shape_str(&shape)
        )));
    }
    arr.extract()
}

fn not_finite(name: &str, row: usize) -> PyErr {
    PyValueError::new_err(format!(
        "{name}[{row}]: NaN or infinite values are not allowed"
    ))
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

/// The camera's part ([`parse_camera_description`]) of a scene file given by path or as TOML
/// text: an `os.PathLike`, or a one-line `str` that names an existing file or has no `=` (so
/// cannot be a scene), is read as a file; any other `str` is parsed as the text of a scene file
/// (errors then name `<string>`).
fn camera_description(obj: &Bound<'_, PyAny>) -> PyResult<CameraDescription> {
    let description = if let Ok(text) = obj.extract::<String>() {
        let as_path = Path::new(&text);
        if !text.contains('\n') && (as_path.is_file() || !text.contains('=')) {
            load_camera_description(as_path)
        } else {
            parse_camera_description(Path::new("<string>"), &text)
        }
    } else {
        match obj.extract::<PathBuf>() {
            Ok(path) => load_camera_description(&path),
            Err(_) => {
                return Err(PyTypeError::new_err(format!(
                    "expected TOML text, a path string or an os.PathLike, got {}",
                    obj.get_type().name()?
                )));
            }
        }
    };
    description.map_err(render_err)
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
    /// The camera of a scene file: its [camera] and [film] tables, checked as the renderer
    /// checks them, and [sampler] type, the sampler pixel_rays draws from. Every other table
    /// and key is ignored, even one the renderer would refuse. `text_or_path` is the TOML
    /// text, a path string or an os.PathLike: a str on one line that names a file, or has no
    /// `=` (so cannot be a scene), is read as a path; any other str is the text (errors then
    /// name `<string>`). Every camera model of the scene format works.
    /// Raises ValueError naming the file, key and line for a bad camera or film.
    #[staticmethod]
    fn from_toml(text_or_path: &Bound<'_, PyAny>) -> PyResult<PyCamera> {
        let d = camera_description(text_or_path)?;
        let camera = d.camera().map_err(render_err)?;
        Ok(PyCamera {
            camera: Box::new(camera),
            sampler: d.sampler,
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
    /// +0.5). `lens_uv` (N, 2) are lens samples in [0, 1)^2, warped onto the aperture; without
    /// them each film point gets the ray that `project` inverts: through the lens centre (0.5,
    /// 0.5) for a thin lens, and for a realistic camera (a lens system) the chief ray, from the
    /// film point through the centre of the aperture stop and out of the front element. `time`
    /// is the shutter sample u in [0, 1), a number or (N,), mapped onto the shutter interval
    /// (default 0: shutter open). Returns float32 origins
    /// (N, 3), unit directions (N, 3) and a bool mask (N,): false where no ray leaves that film
    /// point (past a fisheye's image circle, say), with NaN origin and direction there.
    /// Runs in parallel with the GIL released.
    #[pyo3(signature = (raster_xy, lens_uv=None, time=None, out=None))]
    fn generate_rays<'py>(
        &self,
        py: Python<'py>,
        raster_xy: &Bound<'py, PyAny>,
        lens_uv: Option<&Bound<'py, PyAny>>,
        time: Option<&Bound<'py, PyAny>>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let film_view = rows_view::<2>(raster_xy, "raster_xy")?;
        let film = film_view.as_slice()?;
        let n = film.len() / 2;
        let lens_view = match lens_uv {
            Some(l) => {
                let l = rows_view::<2>(l, "lens_uv")?;
                if l.shape()[0] != n {
                    return Err(PyValueError::new_err(format!(
                        "lens_uv: expected shape ({n}, 2) like raster_xy, got ({}, 2)",
                        l.shape()[0]
                    )));
                }
                Some(l)
            }
            None => None,
        };
        let lens = lens_view.as_ref().map(|l| l.as_slice()).transpose()?;
        let time = time.map(|t| per_ray(t, "time", n)).transpose()?;
        let arrays = ray_arrays(py, out, n)?;
        let sample = |i: usize| {
            let (x, y) = (film[2 * i], film[2 * i + 1]);
            if !(x.is_finite() && y.is_finite()) {
                return None;
            }
            let mut s = CameraSample::at(Point2::new(x, y));
            if let Some(l) = lens {
                let (u, w) = (l[2 * i], l[2 * i + 1]);
                if !(u.is_finite() && w.is_finite()) {
                    return None;
                }
                s.p_lens = glam::Vec2::new(u, w);
            }
            if let Some(t) = &time {
                s.time = t[i];
            }
            Some(s)
        };
        let (rays, bad) = match (&*self.camera, lens) {
            // No lens samples: the one ray of each film point that `project` inverts. For a
            // thin lens that is the lens centre's; a lens system's is the chief ray, through
            // the stop's centre (which no lens sample picks out).
            (AnyCamera::Realistic(c), None) => {
                trace_into(py, arrays, sample, |s| c.generate_chief_ray(s))?
            }
            (camera, _) => trace_into(py, arrays, sample, |s| {
                camera.generate_ray(s).map(|r| r.ray)
            })?,
        };
        if let Some(i) = bad {
            let film_ok = film[2 * i].is_finite() && film[2 * i + 1].is_finite();
            return Err(not_finite(if film_ok { "lens_uv" } else { "raster_xy" }, i));
        }
        Ok(rays)
    }

    /// cam.project(points, time=None, out=None) -> (raster_xy, valid)
    ///
    /// The raster positions (N, 2) float32 (pixel centres at +0.5) of world points (N, 3), as
    /// seen through the lens centre at `time` (in the shutter's unit, default the shutter's
    /// opening). `valid` (N,) is false (and raster_xy NaN) where the camera cannot see the
    /// point (behind a projective camera, outside [near, far], ...); positions outside the
    /// image are returned as they are. `out=(raster_xy, valid)` writes into (and returns) those
    /// arrays (float32 (N, 2) and bool (N,), C-contiguous) instead of allocating new ones. Runs
    /// in parallel with the GIL released.
    #[pyo3(signature = (points, time=None, out=None))]
    fn project<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        time: Option<f32>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let points_view = rows_view::<3>(points, "points")?;
        let points = points_view.as_slice()?;
        let time = time.unwrap_or(self.camera.shutter().open);
        if !time.is_finite() {
            return Err(PyValueError::new_err("time: must be finite"));
        }
        let n = points.len() / 3;
        let (xy_arr, v_arr) = project_arrays(py, out, n)?;
        let (mut xy_rw, mut v_rw) = (writable(&xy_arr, "raster_xy")?, writable(&v_arr, "valid")?);
        let (xy, valid) = (xy_rw.as_slice_mut()?, v_rw.as_slice_mut()?);
        let camera = &self.camera;
        let bad = py.allow_threads(|| {
            let bad = AtomicUsize::new(usize::MAX);
            xy.par_chunks_mut(2 * CHUNK)
                .zip(valid.par_chunks_mut(CHUNK))
                .enumerate()
                .for_each(|(chunk, (xy, v))| {
                    for k in 0..v.len() {
                        let i = chunk * CHUNK + k;
                        let p = &points[3 * i..3 * i + 3];
                        let r = if p.iter().all(|c| c.is_finite()) {
                            camera.project(Point3::new(p[0], p[1], p[2]), time)
                        } else {
                            bad.fetch_min(i, Ordering::Relaxed);
                            None
                        };
                        let r = r.map_or([f32::NAN; 2], |r| [r.x, r.y]);
                        xy[2 * k..2 * k + 2].copy_from_slice(&r);
                        v[k] = !r[0].is_nan();
                    }
                });
            bad.into_inner()
        });
        if bad != usize::MAX {
            return Err(not_finite("points", bad));
        }
        drop((xy_rw, v_rw));
        (xy_arr, v_arr).into_pyobject(py)
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
    #[pyo3(signature = (spp=1, seed=0, out=None))]
    fn pixel_rays<'py>(
        &self,
        py: Python<'py>,
        spp: u32,
        seed: u64,
        out: Option<&Bound<'py, PyAny>>,
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
        let arrays = ray_arrays(py, out, n as usize)?;
        let sample = |i| {
            let s = (i % spp_us) as u32;
            let pixel = i / spp_us;
            let x = x0 + (pixel % w_us) as u32;
            let y = y0 + (pixel / w_us) as u32;
            let mut stream = sampler.stream([x, y], s);
            Some(CameraSample::from_stream(
                &mut stream,
                [x, y],
                uses_lens,
                uses_time,
            ))
        };
        let (rays, _) = trace_into(py, arrays, sample, |s| {
            camera.generate_ray(s).map(|r| r.ray)
        })?;
        Ok(rays)
    }
}

/// A scene loaded from a file and built (geometry, BVHs, materials, lights), ready to render.
#[pyclass(name = "Scene", module = "obscura", frozen)]
pub struct PyScene {
    /// The built scene, lent to one render at a time.
    slot: SceneSlot,
    /// What the file says (before any call's overrides), and the camera it makes: read by the
    /// getters and by `render` without waiting for a render that has the scene. Boxed, as the
    /// camera in [`PyCamera`].
    description: Box<SceneDescription>,
    camera: Box<AnyCamera>,
    path: PathBuf,
}

/// A built scene that one render at a time takes out and puts back ([`SceneSlot::take`]).
///
/// The mutex is held only while the scene is taken or put back, never while its holder waits
/// for anything. Holding a lock on the scene for a whole render deadlocked: the render's
/// waiting thread needs the GIL to report progress and check Ctrl-C, while another Python
/// thread held the GIL and waited for the lock (to read `scene.camera`, or to render).
struct SceneSlot {
    /// The scene, boxed (its BVH wants more alignment than a Python object has); None while
    /// a render has it.
    scene: Mutex<Option<Box<RenderScene>>>,
    /// Signalled when a render puts the scene back.
    returned: Condvar,
}

/// A scene taken from its [`SceneSlot`]; dropping it puts the scene back, even when the render
/// panicked.
struct Lease<'a> {
    slot: &'a SceneSlot,
    scene: Option<Box<RenderScene>>,
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl SceneSlot {
    fn new(scene: RenderScene) -> Self {
        SceneSlot {
            scene: Mutex::new(Some(Box::new(scene))),
            returned: Condvar::new(),
        }
    }

    /// Takes the scene, waiting while another render has it. Call it with the GIL released:
    /// every [`POLL`] of waiting it calls `poll` (which may take the GIL to check Ctrl-C),
    /// whose error ends the wait.
    fn take(&self, poll: impl Fn() -> PyResult<()>) -> PyResult<Lease<'_>> {
        let mut guard = lock(&self.scene);
        loop {
            if let Some(scene) = guard.take() {
                return Ok(Lease {
                    slot: self,
                    scene: Some(scene),
                });
            }
            guard = match self.returned.wait_timeout(guard, POLL) {
                Ok((g, _)) => g,
                Err(e) => e.into_inner().0,
            };
            if guard.is_none() {
                drop(guard);
                poll()?;
                guard = lock(&self.scene);
            }
        }
    }
}

impl std::ops::Deref for Lease<'_> {
    type Target = RenderScene;
    fn deref(&self) -> &RenderScene {
        self.scene
            .as_ref()
            .expect("a lease holds its scene until dropped")
    }
}

impl std::ops::DerefMut for Lease<'_> {
    fn deref_mut(&mut self) -> &mut RenderScene {
        self.scene
            .as_mut()
            .expect("a lease holds its scene until dropped")
    }
}

impl Drop for Lease<'_> {
    fn drop(&mut self) {
        *lock(&self.slot.scene) = self.scene.take();
        self.slot.returned.notify_one();
    }
}

#[pymethods]
impl PyScene {
    /// (width, height) of the film in pixels.
    #[getter]
    fn resolution(&self) -> (u32, u32) {
        let [w, h] = self.description.film.resolution;
        (w, h)
    }

    /// Samples per pixel the file asks for.
    #[getter]
    fn spp(&self) -> u32 {
        self.description.sampler.spp
    }

    /// The file's sampler seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.description.sampler.seed
    }

    /// The file's integrator: path, depth, distance, position, normal or albedo.
    #[getter]
    fn integrator(&self) -> &'static str {
        self.description.integrator.kind.name()
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
            camera: self.camera.clone(),
            sampler: self.description.sampler.kind,
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
/// Reads, validates and builds a scene file (meshes and maps load now, relative to the file):
/// the scene format's TOML, or a pbrt-v4 (.pbrt) or Mitsuba 3 (.xml) scene, imported as
/// `obscura render` imports it (what the import approximates or leaves out is a UserWarning).
/// Raises ValueError naming the file, key and line for a bad scene.
#[pyfunction]
fn load_scene(py: Python<'_>, path: PathBuf) -> PyResult<PyScene> {
    let (scene, warnings) = py.allow_threads(|| build_scene(&path))?;
    for w in warnings {
        PyErr::warn(
            py,
            &py.get_type::<PyUserWarning>(),
            &std::ffi::CString::new(w.replace('\0', " "))?,
            1,
        )?;
    }
    Ok(PyScene {
        description: Box::new(scene.description.clone()),
        camera: Box::new(scene.camera.clone()),
        slot: SceneSlot::new(scene),
        path,
    })
}

/// Builds the scene of a file as `obscura render` reads it: TOML as it is, a .pbrt or .xml
/// through obscura-import (errors moved to the imported file's lines), with the import's
/// warnings.
fn build_scene(path: &Path) -> PyResult<(RenderScene, Vec<String>)> {
    let (d, imported) = obscura_import::load(path).map_err(render_err)?;
    match imported {
        None => Ok((RenderScene::build(d).map_err(render_err)?, Vec::new())),
        Some(i) => {
            let scene = RenderScene::build(d).map_err(|e| render_err(i.locate(e)))?;
            Ok((scene, i.warnings))
        }
    }
}

/// What a render's waiting thread does between polls: report progress, check Ctrl-C.
enum Progress {
    Off,
    Stderr,
    Callback(Py<PyAny>),
}

impl Progress {
    /// Checks for Ctrl-C, then reports (tiles done, tiles in all); an error (KeyboardInterrupt
    /// from Ctrl-C, or the callback's own) stops the render.
    fn poll(&self, py: Python<'_>, done: u64, total: u64) -> PyResult<()> {
        py.check_signals()?;
        self.report(py, done, total)
    }

    /// Reports (tiles done, tiles in all).
    fn report(&self, py: Python<'_>, done: u64, total: u64) -> PyResult<()> {
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

/// render(scene, spp=None, integrator=None, seed=None, threads=None, progress=False,
///        cube_map=False)
///
/// Renders `scene` (a Scene, or a path that load_scene reads: TOML, .pbrt or .xml) and
/// returns its image as a float32 numpy array
/// (H, W, 4): linear RGB and alpha (the fraction of the pixel whose camera rays hit geometry),
/// row 0 at the top, the crop window's pixels. Equal bit for bit to the EXR of
/// `obscura render SCENE --spp .. --integrator .. --seed ..` with the same overrides, for any
/// `threads`. `integrator` is path, depth, distance, position, normal or albedo (the AOVs);
/// `threads` defaults to one per core. `progress` is False, True (a line on sys.stderr) or a
/// callable taking (tiles_done, tiles_total), called from the calling thread every 50 ms and
/// once at the finish (tiles_done == tiles_total). Ctrl-C stops the render and raises
/// KeyboardInterrupt; so does an exception from the progress callable. The GIL is released
/// while rendering. Threads may render the same Scene at once: each render waits (answering
/// Ctrl-C) for the one before it.
///
/// Several views, as `obscura render` makes them: a scene with `[camera.stereo]` renders both
/// eyes and returns them composed (layout "side_by_side": (H, 2W, 4); "anaglyph": (H, W, 4)) or,
/// for layout "separate", a tuple (left, right). `cube_map=True` renders the six 90-degree
/// faces from the camera's position (as `--cube-map`) and returns a dict from face name
/// ("px", "nx", "py", "ny", "pz", "nz") to its array.
#[pyfunction]
#[pyo3(signature = (scene, spp=None, integrator=None, seed=None, threads=None, progress=None, cube_map=false))]
#[allow(clippy::too_many_arguments)]
fn render<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    spp: Option<u32>,
    integrator: Option<&str>,
    seed: Option<u64>,
    threads: Option<usize>,
    progress: Option<&Bound<'py, PyAny>>,
    cube_map: bool,
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
        None => scene.description.integrator.kind,
    };
    let file_sampler = &scene.description.sampler;
    let spp = spp.unwrap_or(file_sampler.spp);
    let seed = seed.unwrap_or(file_sampler.seed);
    let sampler = Sampler::new(file_sampler.kind, spp, seed)
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
    let run = RenderRun {
        scene,
        sampler,
        spp,
        seed,
        kind,
        threads,
        progress: &progress,
    };

    // The views the command line would make: cube faces, a stereo pair, or the one image.
    let description = &scene.description;
    if cube_map {
        let faces = pyo3::types::PyDict::new(py);
        for (face, name) in CubeFace::ALL.into_iter().zip(CUBE_FACE_NAMES) {
            let mut view = SceneDescription::clone(description);
            view.camera.kind = CameraKind::CubeFace;
            view.camera.face = face;
            view.camera.stereo = None;
            let camera = camera_of(&view).map_err(render_err)?;
            faces.set_item(name, image_array(py, run.view(py, Some(camera))?)?)?;
        }
        return Ok(faces.into_any());
    }
    if let (Some(eyes), Some(stereo)) = (description.stereo_eyes(), description.camera.stereo) {
        let [left, right] = eyes.map(|d| camera_of(&d));
        let left = run.view(py, Some(left.map_err(render_err)?))?;
        let right = run.view(py, Some(right.map_err(render_err)?))?;
        return match compose_stereo(&left, &right, stereo.layout) {
            Some(image) => image_array(py, image),
            None => (image_array(py, left)?, image_array(py, right)?)
                .into_pyobject(py)
                .map(|t| t.into_any()),
        };
    }
    image_array(py, run.view(py, None)?)
}

/// The face names of `render(..., cube_map=True)`, in [`CubeFace::ALL`]'s order: the suffixes
/// `obscura render --cube-map` gives its files.
const CUBE_FACE_NAMES: [&str; 6] = ["px", "nx", "py", "ny", "pz", "nz"];

/// One call of `render`: the settings every view of it shares.
struct RenderRun<'a> {
    scene: &'a PyScene,
    sampler: Sampler,
    spp: u32,
    seed: u64,
    kind: IntegratorKind,
    threads: Option<usize>,
    progress: &'a Progress,
}

impl RenderRun<'_> {
    /// Renders one view: the scene's own camera, or `camera` in its place for this view only.
    fn view(&self, py: Python<'_>, camera: Option<AnyCamera>) -> PyResult<obscura_render::Image> {
        let (threads, progress) = (self.threads, self.progress);
        let cancel = AtomicBool::new(false);
        let tiles_done = AtomicU64::new(0);
        let tiles_total = AtomicU64::new(0);
        let on_tile = |done: u64, total: u64| {
            tiles_done.fetch_max(done, Ordering::Relaxed);
            tiles_total.store(total, Ordering::Relaxed);
        };
        // The last (tiles done, tiles in all) the progress was told.
        let mut reported = None;
        let (outcome, interrupted) = py.allow_threads(|| {
            // Another render of this scene may have it: wait, answering Ctrl-C.
            let check = || Python::with_gil(|py| py.check_signals());
            let mut scene = match self.scene.slot.take(check) {
                Ok(scene) => scene,
                Err(e) => return (None, Some(e)),
            };
            scene.sampler = self.sampler.clone();
            scene.description.sampler.spp = self.spp;
            scene.description.sampler.seed = self.seed;
            scene.description.integrator.kind = self.kind;
            scene.camera = camera.unwrap_or_else(|| AnyCamera::clone(&self.scene.camera));
            let rs: &RenderScene = &scene;
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
                                match Python::with_gil(|py| progress.poll(py, done, total)) {
                                    Ok(()) => reported = Some((done, total)),
                                    Err(e) => {
                                        cancel.store(true, Ordering::Relaxed);
                                        interrupted = Some(e);
                                    }
                                }
                            }
                        }
                        // The render thread ended without an answer (it panicked); the scope
                        // re-raises its panic, which PyO3 turns into a Python exception.
                        Err(mpsc::RecvTimeoutError::Disconnected) => {
                            return (None, interrupted);
                        }
                    }
                }
            })
            // Dropping the lease puts the scene back for the next render.
        });
        // The finish is reported once: here, unless the last poll came after it.
        let finished = interrupted.is_none() && matches!(outcome, Some(Ok(_)));
        let end = (
            tiles_done.load(Ordering::Relaxed),
            tiles_total.load(Ordering::Relaxed),
        );
        if finished && reported != Some(end) {
            progress.report(py, end.0, end.1)?;
        }
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
        Ok(outcome.film.resolve())
    }
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
