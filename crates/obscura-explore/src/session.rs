//! One page's session: its view, its scene and the one worker thread that renders it.
//!
//! The scene (geometry, BVH, lights) is built once when the session starts; a change of view
//! rebuilds only the camera, the sampler and the pixel bounds (and the whole scene when the
//! shutter interval changes, since moving instances are placed over it). A change sets the
//! render's cancel flag, so the render in flight stops at its next pass boundary and the worker
//! starts the new view from pass 0; changes that arrive meanwhile are coalesced into the
//! latest. There is never more than one render per session.
//!
//! A stereo pair renders pass by pass too: each pass takes one sample per pixel of the left
//! eye, then of the right, each eye into its own film (the scene's camera swapped between
//! them), and the frame is the pair composed as `obscura render` composes it. The films' sums
//! are exact, so a pair rendered pass by pass is the command line's pair, bit for bit.

use crate::error::ExploreError;
use crate::stereo::{Pick, cameras_of, image_width, pair_layout, pick, shown};
use crate::view::{View, ViewChange};
use obscura_camera::{AnyCamera, Camera, CameraSample, StereoEye};
use obscura_render::{
    Film, Image, PixelRect, RenderOptions, RenderScene, SceneDescription, StereoLayout, camera_of,
    compose_stereo, render, srgb_8bit,
};
use obscura_sample::Sampler;
use obscura_space::{Camera as CameraSpace, Ndc, Point2, Point3, Raster, Screen};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, RwLock, RwLockReadGuard, RwLockWriteGuard};
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

/// The latest frame's images.
#[derive(Clone)]
struct Latest {
    /// The frame as the page shows it (a stereo pair composed).
    image: Image,
    /// A stereo pair's eyes (left, right) and the layout its scene file gives it.
    eyes: Option<(Arc<[Image; 2]>, StereoLayout)>,
    /// The frame's view generation.
    generation: u64,
    /// Passes in the frame.
    passes: u32,
}

/// The scene as the worker renders it, with the view's cameras for the page's questions.
struct Stage {
    /// The scene. Its camera is the view's, except while an eye of a stereo pair renders:
    /// then that eye's (only the worker changes it).
    scene: RenderScene,
    /// The view's camera: a stereo pair's rig centre.
    centre: AnyCamera,
    /// A stereo pair's eyes (left, right) and how the preview shows them.
    pair: Option<([AnyCamera; 2], StereoLayout)>,
}

impl Stage {
    /// The stage of a scene built for a view.
    fn new(scene: RenderScene) -> Result<Stage, ExploreError> {
        let (centre, eyes) = cameras_of(&scene.description)?;
        let layout = pair_layout(&scene.description).map(shown);
        Ok(Stage {
            scene,
            centre,
            pair: eyes.zip(layout),
        })
    }

    /// Points the stage at the view `d`; untouched when that fails.
    fn set_view(&mut self, d: &SceneDescription) -> Result<(), ExploreError> {
        let (centre, eyes) = cameras_of(d)?;
        set_view(&mut self.scene, d)?;
        self.centre = centre;
        self.pair = eyes.zip(pair_layout(d).map(shown));
        Ok(())
    }

    /// The camera-space depth of the first surface under preview position (`x`, `y`): a
    /// stereo pair's preview position picks the eye ([`pick`]).
    fn depth_at(&self, x: f32, y: f32) -> Result<f32, ExploreError> {
        // The page's image starts at the crop window's first pixel, the film's raster at the
        // full film's.
        let b = self.scene.pixel_bounds;
        let (x0, y0) = (b.x0 as f32, b.y0 as f32);
        let (w, h) = (b.x1 - b.x0, b.y1 - b.y0);
        let layout = self.pair.as_ref().map(|(_, layout)| *layout);
        on_image(layout, w, h, x, y)?;
        let Some((eyes, layout)) = &self.pair else {
            return depth_through(&self.scene, &self.centre, x + x0, y + y0);
        };
        let Pick { eye, x, y } = pick(Some(*layout), w, x, y);
        let camera = match eye {
            None => &self.centre,
            Some(StereoEye::Left) => &eyes[0],
            Some(StereoEye::Right) => &eyes[1],
        };
        depth_through(&self.scene, camera, x + x0, y + y0)
    }
}

/// Refuses a position off the page's image: the crop window's `w` x `h` pixels, twice as wide
/// for a pair shown side by side (`shown`).
pub(crate) fn on_image(
    shown: Option<StereoLayout>,
    w: u32,
    h: u32,
    x: f32,
    y: f32,
) -> Result<(), ExploreError> {
    let width = image_width(shown, w);
    if x.is_finite() && y.is_finite() && x >= 0.0 && y >= 0.0 && x < width as f32 && y < h as f32 {
        Ok(())
    } else {
        Err(ExploreError::NothingThere(format!(
            "({x}, {y}) is off the image [0, {width}) x [0, {h})"
        )))
    }
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
    stage: RwLock<Stage>,
    latest: Mutex<Option<Latest>>,
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

/// Reads the stage (consistent even if a holder panicked, as for [`lock`]).
fn read(stage: &RwLock<Stage>) -> RwLockReadGuard<'_, Stage> {
    stage.read().unwrap_or_else(|e| e.into_inner())
}

/// Writes the stage (consistent even if a holder panicked, as for [`lock`]).
fn write(stage: &RwLock<Stage>) -> RwLockWriteGuard<'_, Stage> {
    stage.write().unwrap_or_else(|e| e.into_inner())
}

impl Session {
    /// Builds the scene of `view` (blocking: call off the async runtime) and starts rendering
    /// it with `threads` workers (None: one per core).
    pub fn start(view: View, threads: Option<usize>) -> Result<Session, ExploreError> {
        let stage = Stage::new(RenderScene::build(view.description().clone())?)?;
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
            stage: RwLock::new(stage),
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
        // The camera crate's checks, which the scene layer may leave to build time (both
        // eyes' for a stereo pair).
        cameras_of(view.description())?;
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

    /// The latest image (linear RGBA) as the page shows it (a stereo pair composed), its
    /// view's generation and its passes.
    pub fn latest_image(&self) -> Option<(Image, u64, u32)> {
        lock(&self.shared.latest)
            .as_ref()
            .map(|l| (l.image.clone(), l.generation, l.passes))
    }

    /// The latest frame's stereo pair: the left and right eyes' images (linear RGBA), the
    /// layout its scene file gives it, its view's generation and its passes; None when the
    /// latest frame is of a single view (or there is none yet).
    pub fn latest_eyes(&self) -> Option<([Image; 2], StereoLayout, u64, u32)> {
        let latest = lock(&self.shared.latest);
        let l = latest.as_ref()?;
        let (eyes, layout) = l.eyes.as_ref()?;
        Some(((**eyes).clone(), *layout, l.generation, l.passes))
    }

    /// The camera-space depth (z at shutter open) of the first surface under position
    /// (`x`, `y`) of the page's image, from the lens centre, in the scene as built for the
    /// latest rendered view: the `focal_distance` that brings it into focus. In a stereo
    /// pair's side-by-side image each half is its eye's film; in an anaglyph the rig's centre
    /// answers (its view is midway between the eyes' images of a point). Blocks while the
    /// worker swaps in a new camera.
    pub fn depth_at(&self, x: f32, y: f32) -> Result<f32, ExploreError> {
        read(&self.shared.stage).depth_at(x, y)
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
            let pair = {
                let mut stage = write(&self.stage);
                if let Err(e) = stage.set_view(view.description()) {
                    // Validated already in `change`; a failure here (a map unreadable since)
                    // leaves the old scene and no frame.
                    eprintln!("obscura serve: {e}");
                    continue;
                }
                stage.pair.clone()
            };
            self.running.fetch_add(1, Ordering::SeqCst);
            lock(&self.status).renders_started += 1;
            let done = match pair {
                None => self.render_view(generation),
                Some((eyes, shown)) => {
                    let layout = view.description().camera.stereo.map_or(shown, |s| s.layout);
                    self.render_pair(generation, eyes, shown, layout)
                }
            };
            match done {
                Ok(true) => {}
                Ok(false) => lock(&self.status).renders_cancelled += 1,
                Err(e) => eprintln!("obscura serve: {e}"),
            }
            self.running.fetch_sub(1, Ordering::SeqCst);
        }
    }

    /// Renders a single view, sending each pass; Ok(false) when a change cancelled it.
    fn render_view(&self, generation: u64) -> Result<bool, ExploreError> {
        let stage = read(&self.stage);
        let scene = &stage.scene;
        let passes = scene.sampler.samples_per_pixel();
        let on_pass = |done: u32, all: u32, film: &Film| {
            self.publish(generation, done, all, film.resolve(), None);
        };
        let outcome = render(
            scene,
            RenderOptions {
                threads: self.threads,
                cancel: Some(&self.cancel),
                on_pass: Some(&on_pass),
                ..Default::default()
            },
        )
        .map_err(threads_error)?;
        Ok(outcome.passes_done >= passes)
    }

    /// Renders a stereo pair pass by pass, the left eye's pass then the right's, each into
    /// its own film, sending each pass composed as `shown`; Ok(false) when a change cancelled
    /// it. `layout` is the scene file's (kept with the eyes for saving them).
    fn render_pair(
        &self,
        generation: u64,
        eyes: [AnyCamera; 2],
        shown: StereoLayout,
        layout: StereoLayout,
    ) -> Result<bool, ExploreError> {
        let (bounds, passes) = {
            let stage = read(&self.stage);
            (
                stage.scene.pixel_bounds,
                stage.scene.sampler.samples_per_pixel(),
            )
        };
        // The eyes' films have the view's pixel bounds: an eye differs from the rig's centre
        // only in its pose and its screen window, not in its resolution or crop.
        let mut films = [Film::new(bounds), Film::new(bounds)];
        let outcome = self.pair_passes(&mut films, &eyes, passes, |pass, films| {
            let images = [films[0].resolve(), films[1].resolve()];
            // `shown` is never `separate`, the one layout without a single image.
            if let Some(image) = compose_stereo(&images[0], &images[1], shown) {
                self.publish(generation, pass, passes, image, Some((images, layout)));
            }
        });
        // The view's own camera back in the scene, however the passes ended.
        let mut stage = write(&self.stage);
        stage.scene.camera = stage.centre.clone();
        outcome
    }

    /// Adds passes to both eyes' `films` until `passes` are done or a change cancels them
    /// (Ok(false)), calling `on_pass` with the passes done after each pair of passes. Each
    /// eye's pass is a render of that one pass resumed from the eye's film, with the eye's
    /// camera swapped into the scene.
    fn pair_passes(
        &self,
        films: &mut [Film; 2],
        eyes: &[AnyCamera; 2],
        passes: u32,
        on_pass: impl Fn(u32, &[Film; 2]),
    ) -> Result<bool, ExploreError> {
        for pass in 0..passes {
            for (film, camera) in films.iter_mut().zip(eyes) {
                if self.cancel.load(Ordering::SeqCst) {
                    return Ok(false);
                }
                write(&self.stage).scene.camera = camera.clone();
                let stage = read(&self.stage);
                // `render` takes the film and gives it back with the pass added (or as it
                // was, when cancelled); an empty film stands in meanwhile.
                let resumed = std::mem::replace(
                    film,
                    Film::new(PixelRect {
                        x0: 0,
                        y0: 0,
                        x1: 0,
                        y1: 0,
                    }),
                );
                let outcome = render(
                    &stage.scene,
                    RenderOptions {
                        threads: self.threads,
                        cancel: Some(&self.cancel),
                        resume: Some((resumed, pass)),
                        passes: Some(pass..pass + 1),
                        ..Default::default()
                    },
                )
                .map_err(threads_error)?;
                *film = outcome.film;
                if outcome.passes_done <= pass {
                    return Ok(false);
                }
            }
            on_pass(pass + 1, films);
        }
        Ok(true)
    }

    /// Makes a pass the latest frame and sends it to the pages (nothing once cancelled).
    fn publish(
        &self,
        generation: u64,
        done: u32,
        all: u32,
        image: Image,
        eyes: Option<([Image; 2], StereoLayout)>,
    ) {
        if self.cancel.load(Ordering::SeqCst) {
            return;
        }
        let png = match png_bytes(&image) {
            Ok(p) => p,
            Err(e) => {
                eprintln!("obscura serve: {e}");
                return;
            }
        };
        *lock(&self.latest) = Some(Latest {
            image,
            eyes: eyes.map(|(images, layout)| (Arc::new(images), layout)),
            generation,
            passes: done,
        });
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
    }
}

/// The error of a render whose thread pool could not start.
fn threads_error(e: impl std::fmt::Display) -> ExploreError {
    ExploreError::Internal(format!("cannot start the render threads: {e}"))
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
    depth_through(scene, &scene.camera, x, y)
}

/// The depth under a preview position of the view `scene` was built for: [`depth_at`],
/// or for a stereo pair, through the eye (or the rig's centre) the position picks.
pub(crate) fn preview_depth(scene: RenderScene, x: f32, y: f32) -> Result<f32, ExploreError> {
    Stage::new(scene)?.depth_at(x, y)
}

/// [`depth_at`] through `camera` (one of the scene's view's cameras, of its film bounds).
fn depth_through(
    scene: &RenderScene,
    camera: &AnyCamera,
    x: f32,
    y: f32,
) -> Result<f32, ExploreError> {
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
