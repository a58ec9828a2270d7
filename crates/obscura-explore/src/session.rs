//! One page's session: its view, its scene and the one worker thread that renders it.
//!
//! The scene (geometry, BVH, lights) is built once when the session starts; a change of view
//! rebuilds only the camera, the sampler and the pixel bounds (and the whole scene when the
//! shutter interval changes, since moving instances are placed over it). A change sets the
//! render's cancel flag, so the render in flight stops at its next pass boundary and the worker
//! starts the new view from pass 0; changes that arrive meanwhile are coalesced into the
//! latest. There is never more than one render per session.

use crate::error::ExploreError;
use crate::view::{View, ViewChange};
use obscura_camera::{AnyCamera, Camera, CameraSample};
use obscura_render::{
    Film, Image, PixelRect, RenderOptions, RenderScene, SceneDescription, camera_of, render,
    srgb_8bit,
};
use obscura_sample::Sampler;
use obscura_space::{Camera as CameraSpace, Ndc, Point2, Point3, Raster, Screen};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, RwLock};
use tokio::sync::watch;

/// One progressive pass of a view, encoded for the page.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Which view (the session's change counter) this frame shows.
    pub generation: u64,
    /// Passes (samples per pixel) in the frame.
    pub pass: u32,
    /// Passes the view asks for.
    pub passes: u32,
    /// The frame as PNG (sRGB, 8 bits).
    pub png: Arc<Vec<u8>>,
}

/// What a session's worker reports, for the page and for tests.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct Status {
    /// The latest accepted view.
    pub generation: u64,
    /// The view of the latest frame, and its passes done.
    pub frame_generation: u64,
    /// Passes in the latest frame.
    pub passes_done: u32,
    /// Passes the latest frame's view asks for.
    pub passes: u32,
    /// Passes in the first frame sent of the latest frame's view (1 when its render started
    /// from scratch).
    pub first_pass: u32,
    /// Renders started.
    pub renders_started: u64,
    /// Renders stopped by a change before their last pass.
    pub renders_cancelled: u64,
    /// Renders running now (0 or 1).
    pub renders_running: u64,
}

/// The view waiting to be rendered, under the session's lock.
struct State {
    view: View,
    generation: u64,
    pending: Option<(View, u64)>,
    stop: bool,
}

/// What the page's handlers and the worker share.
struct Shared {
    state: Mutex<State>,
    wake: Condvar,
    cancel: AtomicBool,
    scene: RwLock<RenderScene>,
    latest: Mutex<Option<(Image, u64, u32)>>,
    frames: watch::Sender<Option<Frame>>,
    status: Mutex<Status>,
    running: AtomicU64,
    threads: Option<usize>,
}

/// A page's session. Dropping it stops its worker at the next pass boundary.
pub struct Session {
    shared: Arc<Shared>,
}

/// Locks `m`; the data behind the session's locks stays consistent even if a holder panicked.
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl Session {
    /// Builds the scene of `view` (blocking: call off the async runtime) and starts rendering
    /// it with `threads` workers (None: one per core).
    pub fn start(view: View, threads: Option<usize>) -> Result<Session, ExploreError> {
        let scene = RenderScene::build(view.description().clone())?;
        let (frames, _) = watch::channel(None);
        let shared = Arc::new(Shared {
            state: Mutex::new(State {
                view: view.clone(),
                generation: 0,
                pending: Some((view, 0)),
                stop: false,
            }),
            wake: Condvar::new(),
            cancel: AtomicBool::new(false),
            scene: RwLock::new(scene),
            latest: Mutex::new(None),
            frames,
            status: Mutex::new(Status::default()),
            running: AtomicU64::new(0),
            threads,
        });
        let worker = shared.clone();
        std::thread::Builder::new()
            .name("obscura-explore-render".into())
            .spawn(move || worker.run())
            .map_err(|e| ExploreError::Internal(format!("cannot start a render thread: {e}")))?;
        Ok(Session { shared })
    }

    /// The current view.
    pub fn view(&self) -> View {
        lock(&self.shared.state).view.clone()
    }

    /// Applies `change` (validated by the scene layer); on success the render in flight is
    /// cancelled and the new view starts from pass 0. Returns the new view's generation.
    pub fn change(&self, change: &ViewChange) -> Result<(u64, View), ExploreError> {
        let mut state = lock(&self.shared.state);
        let view = state.view.apply(change)?;
        // The camera crate's checks, which the scene layer may leave to build time.
        camera_of(view.description())?;
        state.generation += 1;
        state.view = view.clone();
        state.pending = Some((view.clone(), state.generation));
        self.shared.cancel.store(true, Ordering::SeqCst);
        self.shared.wake.notify_all();
        Ok((state.generation, view))
    }

    /// A receiver of the frames, latest first.
    pub fn frames(&self) -> watch::Receiver<Option<Frame>> {
        self.shared.frames.subscribe()
    }

    /// The worker's counters.
    pub fn status(&self) -> Status {
        let mut s = *lock(&self.shared.status);
        s.generation = lock(&self.shared.state).generation;
        s.renders_running = self.shared.running.load(Ordering::SeqCst);
        s
    }

    /// The latest image (linear RGBA), its view's generation and its passes.
    pub fn latest_image(&self) -> Option<(Image, u64, u32)> {
        lock(&self.shared.latest).clone()
    }

    /// Runs `f` on the session's scene as built for the latest rendered view (blocking while
    /// the worker swaps in a new camera).
    pub fn with_scene<T>(&self, f: impl FnOnce(&RenderScene) -> T) -> T {
        let scene = self.shared.scene.read().unwrap_or_else(|e| e.into_inner());
        f(&scene)
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        lock(&self.shared.state).stop = true;
        self.shared.cancel.store(true, Ordering::SeqCst);
        self.shared.wake.notify_all();
    }
}

impl Shared {
    /// The worker: waits for a view, renders it pass by pass until done or cancelled.
    fn run(&self) {
        loop {
            let (view, generation) = {
                let mut state = lock(&self.state);
                loop {
                    if state.stop {
                        return;
                    }
                    if let Some(p) = state.pending.take() {
                        // Cleared under the lock that `change` sets it under, so a change
                        // made after this point always cancels the render below.
                        self.cancel.store(false, Ordering::SeqCst);
                        break p;
                    }
                    state = self.wake.wait(state).unwrap_or_else(|e| e.into_inner());
                }
            };
            {
                let mut scene = self.scene.write().unwrap_or_else(|e| e.into_inner());
                if let Err(e) = set_view(&mut scene, view.description()) {
                    // Validated already in `change`; a failure here (a map unreadable since)
                    // leaves the old scene and no frame.
                    eprintln!("obscura serve: {e}");
                    continue;
                }
            }
            self.render_view(generation);
        }
    }

    fn render_view(&self, generation: u64) {
        let scene = self.scene.read().unwrap_or_else(|e| e.into_inner());
        self.running.fetch_add(1, Ordering::SeqCst);
        lock(&self.status).renders_started += 1;
        let passes = scene.sampler.samples_per_pixel();
        let on_pass = |done: u32, all: u32, film: &Film| {
            if self.cancel.load(Ordering::SeqCst) {
                return;
            }
            let image = film.resolve();
            let png = match png_bytes(&image) {
                Ok(p) => p,
                Err(e) => {
                    eprintln!("obscura serve: {e}");
                    return;
                }
            };
            *lock(&self.latest) = Some((image, generation, done));
            {
                let mut s = lock(&self.status);
                if s.frame_generation != generation || s.passes_done == 0 {
                    s.first_pass = done;
                }
                s.frame_generation = generation;
                s.passes_done = done;
                s.passes = all;
            }
            self.frames.send_replace(Some(Frame {
                generation,
                pass: done,
                passes: all,
                png: Arc::new(png),
            }));
        };
        let outcome = render(
            &scene,
            RenderOptions {
                threads: self.threads,
                cancel: Some(&self.cancel),
                on_pass: Some(&on_pass),
                ..Default::default()
            },
        );
        match outcome {
            Ok(o) if o.passes_done < passes => lock(&self.status).renders_cancelled += 1,
            Ok(_) => {}
            Err(e) => eprintln!("obscura serve: cannot start the render threads: {e}"),
        }
        self.running.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Points `scene` at the view `d`: a new camera, sampler and pixel bounds; the whole scene
/// again when the shutter interval moved (moving instances are placed over it).
fn set_view(scene: &mut RenderScene, d: &SceneDescription) -> Result<(), ExploreError> {
    if d.camera.shutter != scene.description.camera.shutter {
        *scene = RenderScene::build(d.clone())?;
        return Ok(());
    }
    let camera = camera_of(d)?;
    let [x0, x1, y0, y1] = Camera::film(&camera).pixel_bounds();
    let sampler = Sampler::new(d.sampler.kind, d.sampler.spp, d.sampler.seed).map_err(|e| {
        obscura_render::RenderError::Scene {
            file: d.file.clone(),
            line: None,
            key: Some("sampler".into()),
            message: e.to_string(),
        }
    })?;
    scene.camera = camera;
    scene.sampler = sampler;
    scene.pixel_bounds = PixelRect { x0, y0, x1, y1 };
    scene.description = d.clone();
    Ok(())
}

/// An image as an 8-bit sRGB PNG, opaque.
pub fn png_bytes(image: &Image) -> Result<Vec<u8>, ExploreError> {
    use image::ImageEncoder;
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let mut rgba = Vec::with_capacity(image.pixels.len() * 4);
    for p in &image.pixels {
        rgba.extend_from_slice(&[srgb_8bit(p[0]), srgb_8bit(p[1]), srgb_8bit(p[2]), 255]);
    }
    let mut out = Vec::new();
    PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Sub)
        .write_image(
            &rgba,
            image.width,
            image.height,
            image::ExtendedColorType::Rgba8,
        )
        .map_err(|e| ExploreError::Internal(format!("PNG encoding: {e}")))?;
    Ok(out)
}

/// The camera-space depth (z at shutter open) of the first surface seen through raster
/// position (`x`, `y`) from the lens centre: the `focal_distance` that brings it into focus.
pub fn depth_at(scene: &RenderScene, x: f32, y: f32) -> Result<f32, ExploreError> {
    let b = scene.pixel_bounds;
    if !(x.is_finite() && y.is_finite())
        || x < b.x0 as f32
        || y < b.y0 as f32
        || x >= b.x1 as f32
        || y >= b.y1 as f32
    {
        return Err(ExploreError::NothingThere(format!(
            "raster ({x}, {y}) is off the film [{}, {}) x [{}, {})",
            b.x0, b.x1, b.y0, b.y1
        )));
    }
    let camera = &scene.camera;
    let hit = camera
        .generate_ray(&CameraSample::at(Point2::<Raster>::new(x, y)))
        .and_then(|r| scene.geometry.intersect(&r.ray))
        .ok_or_else(|| ExploreError::NothingThere(format!("no surface under raster ({x}, {y})")))?;
    let camera_from_world = camera
        .world_from_camera()
        .at(camera.shutter().open)
        .inverse();
    Ok(camera_from_world.point(hit.p).z)
}

/// The coordinates of raster position (`x`, `y`) in each space the camera crate defines
/// (docs/cameras.md): raster, NDC, screen and camera space (on the near plane, z = 0 in
/// screen space) for the projective models, and the world-space ray through the lens centre
/// at shutter open for every model.
pub fn coordinates(camera: &AnyCamera, x: f32, y: f32) -> serde_json::Value {
    let projective = match camera {
        AnyCamera::Perspective(c) => Some(c.projective()),
        AnyCamera::Orthographic(c) => Some(c.projective()),
        _ => None,
    };
    let raster = Point3::<Raster>::new(x, y, 0.0);
    let triple = |x: f32, y: f32, z: f32| serde_json::json!([x, y, z]);
    let spaces = projective.map(|p| {
        let ndc: Point3<Ndc> = p.ndc_from_raster().point(raster);
        let screen: Point3<Screen> = p.screen_from_raster().point(raster);
        let cam: Point3<CameraSpace> = p.camera_from_raster().point(raster);
        serde_json::json!({
            "ndc": triple(ndc.x, ndc.y, ndc.z),
            "screen": triple(screen.x, screen.y, screen.z),
            "camera": triple(cam.x, cam.y, cam.z),
        })
    });
    let ray = camera
        .generate_ray(&CameraSample::at(Point2::<Raster>::new(x, y)))
        .map(|r| {
            serde_json::json!({
                "origin": triple(r.ray.origin.x, r.ray.origin.y, r.ray.origin.z),
                "direction": triple(r.ray.direction.x, r.ray.direction.y, r.ray.direction.z),
            })
        });
    let [w, h] = Camera::film(camera).resolution();
    serde_json::json!({
        "raster": [x, y],
        "resolution": [w, h],
        "projective": spaces,
        "ray": ray,
    })
}
