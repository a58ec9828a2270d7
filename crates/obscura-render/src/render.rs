//! The parallel tile renderer: passes of one sample per pixel over tiles, merged in order.
//!
//! A render is a sequence of passes; pass `k` takes sample index `k` of every pixel. The
//! (pass, tile) jobs are numbered pass by pass, and every worker takes the next job number from
//! one counter, renders the tile into its own buffer and leaves it in a slot; whichever worker
//! is free merges the buffers in job order into a pass accumulator, which is added to the film
//! pixel by pixel when its pass's last tile is merged. No worker waits at a pass or batch
//! boundary: only a window of buffers (the slowest tile in flight holds up the merge of the
//! ones after it) bounds how far rendering runs ahead of merging. The film's sums are exact
//! fixed-point integers, so a render is bit-identical for any thread count, a render stopped
//! after pass `k` and resumed from there equals one that ran straight through, and a render
//! of some passes or some tiles only (a slice, [`RenderOptions::passes`] and
//! [`RenderOptions::tiles`]) adds to the other slices' films to exactly the whole render's.

use crate::build::RenderScene;
use crate::film::{Film, PixelRect, TileBuffer};
use crate::scene::IntegratorKind;
use glam::Vec3;
use obscura_camera::{Camera, CameraSample};
use obscura_sample::SampleStream;
use obscura_shade::PathIntegrator;
use obscura_space::{Ray, World};
use std::ops::Range;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Tile edge in pixels.
pub const TILE_SIZE: u32 = 16;

/// How many rendered tiles may wait to be merged (bounds the memory of tile buffers): the
/// slowest tile in flight holds up the merge of the ones after it, and a worker does not start
/// a tile this many jobs past the merge.
pub const TILE_WINDOW: usize = 256;

/// The in-order merge of rendered tiles: the pass accumulator and the film it completes into.
struct Merger {
    /// The next job to merge.
    cursor: u64,
    /// The sums of the pass under way; added to the film when its last tile is merged, so a
    /// pass cut short leaves the film untouched and no per-pass copy of it is needed.
    pass_film: Film,
    /// The film: complete passes only.
    film: Film,
    /// Passes in the film.
    passes_done: u32,
    /// Set once a cancelled render has stopped adding passes.
    stopped: bool,
}

/// Locks `m`; a worker that panicked cannot leave a tile buffer or a slot half-written, so a
/// poisoned lock's contents are still sound.
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Counters of a render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Camera samples taken (one camera ray each).
    pub samples: u64,
    /// Samples whose radiance was NaN or infinite, dropped rather than splatted.
    pub dropped_nonfinite: u64,
    /// Samples for which the camera produced no ray (e.g. a zero-weight lens point).
    pub no_ray: u64,
}

/// How far a render got.
#[derive(Debug)]
pub struct RenderOutcome {
    /// The accumulated film: complete passes only.
    pub film: Film,
    /// Passes (samples per pixel) in the film.
    pub passes_done: u32,
    /// Counters.
    pub stats: RenderStats,
    /// Wall-clock time of this call.
    pub elapsed: Duration,
}

impl RenderOutcome {
    /// True when the film holds every sample the scene asks for.
    pub fn is_complete(&self, scene: &RenderScene) -> bool {
        self.passes_done >= scene.sampler.samples_per_pixel()
    }
}

/// Called after each pass with (passes done, the pass to stop at, the film so far). It may borrow
/// locals of the caller (a checkpoint path, a timer): the lifetime is the options'.
pub type PassCallback<'a> = dyn Fn(u32, u32, &Film) + Sync + 'a;

/// Options of [`render`].
#[derive(Default)]
pub struct RenderOptions<'a> {
    /// Worker threads; `None` for rayon's default (one per core).
    pub threads: Option<usize>,
    /// Set to stop at the next pass boundary (the pass under way is discarded).
    pub cancel: Option<&'a AtomicBool>,
    /// Called after each pass with (passes done, passes in all).
    pub on_pass: Option<&'a PassCallback<'a>>,
    /// Called as tiles finish with (tiles done in this render, tiles in all).
    pub on_tile: Option<&'a (dyn Fn(u64, u64) + Sync)>,
    /// Continue from this film, which holds this many passes.
    pub resume: Option<(Film, u32)>,
    /// Take only these passes (sample indices) [default: all]; with `resume`, start at the
    /// resumed pass count instead of the range's start. An end past the scene's samples per
    /// pixel stops there.
    pub passes: Option<Range<u32>>,
    /// Render only these tiles, as indices into [`tiles`] of the scene's pixel bounds
    /// [default: all]. Their samples still reach the pixels around them that the filter
    /// covers, so films of disjoint tile ranges add up to the whole film.
    pub tiles: Option<Range<usize>>,
}

/// The tiles covering `bounds`, row by row.
pub fn tiles(bounds: PixelRect) -> Vec<PixelRect> {
    let mut out = Vec::new();
    let mut y = bounds.y0;
    while y < bounds.y1 {
        let mut x = bounds.x0;
        while x < bounds.x1 {
            out.push(PixelRect {
                x0: x,
                y0: y,
                x1: (x + TILE_SIZE).min(bounds.x1),
                y1: (y + TILE_SIZE).min(bounds.y1),
            });
            x += TILE_SIZE;
        }
        y += TILE_SIZE;
    }
    out
}

/// Renders `scene`, or continues a resumed film, until every pass is done or `cancel` is set.
pub fn render(
    scene: &RenderScene,
    options: RenderOptions<'_>,
) -> Result<RenderOutcome, rayon::ThreadPoolBuildError> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = options.threads {
        builder = builder.num_threads(n.max(1));
    }
    let pool = builder.build()?;
    let start = Instant::now();
    let spp = scene.sampler.samples_per_pixel();
    let passes = options.passes.unwrap_or(0..spp);
    let end_pass = passes.end.min(spp);
    let (film, first_pass) = options
        .resume
        .unwrap_or_else(|| (Film::new(scene.pixel_bounds), passes.start));
    let first_pass = first_pass.min(end_pass);
    let mut tiles = tiles(scene.pixel_bounds);
    if let Some(r) = options.tiles {
        let end = r.end.min(tiles.len());
        tiles.truncate(end);
        tiles.drain(..r.start.min(end));
    }
    // Job j is tile j % tile_count of pass first_pass + j / tile_count: workers take jobs in
    // this order from one counter, and the rendered buffers are merged in the same order
    // through a window of slots, so the film never depends on which worker rendered what.
    let tile_count = tiles.len() as u64;
    let jobs = tile_count * u64::from(end_pass - first_pass);
    let tiles_done = AtomicU64::new(0);
    let samples = AtomicU64::new(0);
    let dropped = AtomicU64::new(0);
    let no_ray = AtomicU64::new(0);
    let cancelled = || options.cancel.is_some_and(|c| c.load(Ordering::Relaxed));
    let path = PathIntegrator::new(scene.description.integrator.max_depth);

    let on_pass = options.on_pass;
    let window = TILE_WINDOW as u64;
    let next_job = AtomicU64::new(0);
    // The merger's cursor, readable without its lock.
    let merged = AtomicU64::new(0);
    let slots: Vec<Mutex<Option<TileBuffer>>> =
        (0..TILE_WINDOW).map(|_| Mutex::new(None)).collect();
    let spare: Mutex<Vec<TileBuffer>> = Mutex::new(Vec::new());
    let merger = Mutex::new(Merger {
        cursor: 0,
        pass_film: Film::new(scene.pixel_bounds),
        film,
        passes_done: first_pass,
        stopped: false,
    });
    // Merges every rendered job from the cursor on, in order; a finished pass goes to the film
    // (unless the render was cancelled: then nothing more is added).
    let merge_ready = |m: &mut Merger| {
        while m.cursor < jobs && !m.stopped {
            let Some(buffer) = lock(&slots[(m.cursor % window) as usize]).take() else {
                return;
            };
            m.pass_film.merge(&buffer);
            lock(&spare).push(buffer);
            m.cursor += 1;
            merged.store(m.cursor, Ordering::Release);
            if m.cursor.is_multiple_of(tile_count) {
                if cancelled() {
                    m.stopped = true;
                    return;
                }
                let pass = first_pass + (m.cursor / tile_count) as u32;
                m.film.absorb(&mut m.pass_film);
                m.passes_done = pass;
                if let Some(f) = on_pass {
                    f(pass, end_pass, &m.film);
                }
            }
        }
    };
    let worker = || {
        loop {
            if cancelled() {
                return;
            }
            let job = next_job.fetch_add(1, Ordering::Relaxed);
            if job >= jobs {
                return;
            }
            // The job's slot is free once the merge is within a window of it. The job at the
            // merge cursor is being rendered by another worker, so this wait is short (and
            // rare); meanwhile merge whatever is ready.
            while job >= merged.load(Ordering::Acquire) + window {
                if let Ok(mut m) = merger.try_lock() {
                    merge_ready(&mut m);
                    if m.stopped {
                        return;
                    }
                }
                if cancelled() {
                    return;
                }
                std::thread::yield_now();
            }
            let tile = tiles[(job % tile_count) as usize];
            let pass = first_pass + (job / tile_count) as u32;
            let mut buffer = match lock(&spare).pop() {
                Some(mut b) => {
                    b.reset(tile, scene.pixel_bounds);
                    b
                }
                None => TileBuffer::new(tile, scene.pixel_bounds, scene.filter),
            };
            let counts = render_tile(scene, &path, tile, pass, &mut buffer);
            samples.fetch_add(counts.samples, Ordering::Relaxed);
            dropped.fetch_add(counts.dropped_nonfinite, Ordering::Relaxed);
            no_ray.fetch_add(counts.no_ray, Ordering::Relaxed);
            let done = tiles_done.fetch_add(1, Ordering::Relaxed) + 1;
            if let Some(f) = options.on_tile {
                f(done, jobs);
            }
            *lock(&slots[(job % window) as usize]) = Some(buffer);
            // Merge if no one else is (a worker that holds the merger merges what is ready
            // when it looks next; the last merges happen after the workers stop).
            if let Ok(mut m) = merger.try_lock() {
                merge_ready(&mut m);
            }
        }
    };
    if jobs > 0 {
        pool.broadcast(|_| worker());
    }
    // What the workers left unmerged: every job taken was rendered, so this completes every
    // pass that was not cut short.
    let mut m = merger.into_inner().unwrap_or_else(|e| e.into_inner());
    merge_ready(&mut m);
    let (film, passes_done) = if tiles.is_empty() {
        (m.film, end_pass)
    } else {
        (m.film, m.passes_done)
    };
    Ok(RenderOutcome {
        film,
        passes_done,
        stats: RenderStats {
            samples: samples.into_inner(),
            dropped_nonfinite: dropped.into_inner(),
            no_ray: no_ray.into_inner(),
        },
        elapsed: start.elapsed(),
    })
}

/// Takes sample `index` of every pixel of `tile`.
fn render_tile(
    scene: &RenderScene,
    path: &PathIntegrator,
    tile: PixelRect,
    index: u32,
    buffer: &mut TileBuffer,
) -> RenderStats {
    let mut stats = RenderStats::default();
    // A pinhole ignores the lens sample; the time sample matters only when the shutter is
    // open over an interval and something (the camera or an instance) moves in it. Not
    // drawing what nothing reads saves two of a sample's five camera dimensions and changes
    // no pixel (lights move only as emitting instances, which the geometry reports).
    let uses_lens = scene.camera.uses_lens_sample();
    let uses_time = scene.camera.uses_time_sample()
        && (scene.camera.world_from_camera().is_animated() || scene.geometry.moves());
    // Every pixel's camera ray first, then the tile's paths traced together (their rays go
    // through the geometry in batches), then the samples added in pixel order, so that the
    // tile's sums are the same as one pixel after another would make them.
    let mut streams = Vec::with_capacity(tile.area() as usize);
    let mut rays = Vec::with_capacity(tile.area() as usize);
    // Each pixel's film position and its camera ray's weight (`None`: no ray); the rays
    // themselves are in `rays`, in the same order.
    let mut samples = Vec::with_capacity(tile.area() as usize);
    for y in tile.y0..tile.y1 {
        for x in tile.x0..tile.x1 {
            stats.samples += 1;
            let mut stream = scene.sampler.stream([x, y], index);
            let sample = CameraSample::from_stream(&mut stream, [x, y], uses_lens, uses_time);
            let camera_ray = scene.camera.generate_ray(&sample);
            if let Some(camera_ray) = &camera_ray {
                streams.push(stream);
                rays.push(camera_ray.ray);
            }
            samples.push((sample.p_film.to_glam(), camera_ray.map(|r| r.weight)));
        }
    }
    let mut values = sample_values(scene, path, &rays, &mut streams).into_iter();
    for (p_film, weight) in samples {
        let Some(weight) = weight else {
            // No ray: the sample sees nothing, but still counts in the pixel's mean.
            stats.no_ray += 1;
            buffer.add_sample(p_film, Vec3::ZERO, false);
            continue;
        };
        let (value, hit) = values.next().expect("one value per camera ray");
        let value = value * weight;
        if !value.is_finite() {
            stats.dropped_nonfinite += 1;
            continue;
        }
        buffer.add_sample(p_film, value, hit);
    }
    stats
}

/// [`sample_value`] for each of `rays` with its own stream; the path integrator traces them
/// together ([`PathIntegrator::li_and_hit_batch`]), with the same values.
fn sample_values(
    scene: &RenderScene,
    path: &PathIntegrator,
    rays: &[Ray<World>],
    streams: &mut [SampleStream<'_>],
) -> Vec<(Vec3, bool)> {
    if scene.integrator() != IntegratorKind::Path {
        return rays
            .iter()
            .zip(streams)
            .map(|(ray, stream)| sample_value(scene, path, ray, stream))
            .collect();
    }
    let mut values = path.li_and_hit_batch(&scene.geometry, &scene.shading, rays, streams);
    if let Some(scale) = scene.exposure_scale {
        for (radiance, _) in &mut values {
            *radiance *= scale;
        }
    }
    values
}

/// The integrator's value for one camera ray, and whether the ray hit geometry.
pub fn sample_value(
    scene: &RenderScene,
    path: &PathIntegrator,
    ray: &Ray<World>,
    stream: &mut SampleStream<'_>,
) -> (Vec3, bool) {
    let kind = scene.integrator();
    if kind == IntegratorKind::Path {
        let (radiance, hit) = path.li_and_hit(&scene.geometry, &scene.shading, ray, stream);
        // Photographic exposure scales radiance only, never the AOVs below.
        return match scene.exposure_scale {
            Some(scale) => (radiance * scale, hit),
            None => (radiance, hit),
        };
    }
    let Some(hit) = scene.geometry.intersect(ray) else {
        return (Vec3::ZERO, false);
    };
    let value = match kind {
        IntegratorKind::Depth => {
            let camera_from_world = scene.camera.world_from_camera().at(ray.time).inverse();
            Vec3::splat((camera_from_world * hit.p).z)
        }
        IntegratorKind::Distance => Vec3::splat(hit.p.distance(ray.origin)),
        IntegratorKind::Position => hit.p.to_glam(),
        IntegratorKind::Normal => hit.n_shading.face_forward(-ray.direction).to_glam(),
        IntegratorKind::Albedo => scene
            .shading
            .material(hit.instance)
            .map_or(Vec3::ZERO, |m| m.albedo()),
        IntegratorKind::Path => unreachable!("handled above"),
    };
    (value, true)
}
