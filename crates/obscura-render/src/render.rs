//! The parallel tile renderer: passes of one sample per pixel over tiles, merged in order.
//!
//! A render is a sequence of passes; pass `k` takes sample index `k` of every pixel. Within a
//! pass, tiles are rendered in parallel (rayon) into their own buffers, merged in tile order
//! into a pass accumulator (one batch of tiles merging while the next batch, of this pass or
//! the next, renders), and the pass is then added to the film pixel by pixel. The pass schedule depends only on the scene, never on threads or timing,
//! so a render is bit-identical for any thread count, and a render stopped after pass `k` and
//! resumed from there equals one that ran straight through.

use crate::build::RenderScene;
use crate::film::{Film, PixelRect, TileBuffer};
use crate::scene::IntegratorKind;
use glam::{Vec2, Vec3};
use obscura_camera::{Camera, CameraSample};
use obscura_sample::SampleStream;
use obscura_shade::PathIntegrator;
use obscura_space::{Point2, Ray, World};
use rayon::prelude::*;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Tile edge in pixels.
pub const TILE_SIZE: u32 = 16;

/// How many tiles are rendered before they are merged (bounds the memory of tile buffers).
const TILES_PER_BATCH: usize = 256;

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

/// Called after each pass with (passes done, passes in all, the film so far). It may borrow
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
    let (mut film, first_pass) = options
        .resume
        .unwrap_or_else(|| (Film::new(scene.pixel_bounds), 0));
    let tiles = tiles(scene.pixel_bounds);
    let total_tiles = tiles.len() as u64 * u64::from(spp.saturating_sub(first_pass));
    let tiles_done = AtomicU64::new(0);
    let samples = AtomicU64::new(0);
    let dropped = AtomicU64::new(0);
    let no_ray = AtomicU64::new(0);
    let cancelled = || options.cancel.is_some_and(|c| c.load(Ordering::Relaxed));
    let mut passes_done = first_pass;
    let path = PathIntegrator::new(scene.description.integrator.max_depth);

    let on_pass = options.on_pass;
    let batches: Vec<&[PixelRect]> = tiles.chunks(TILES_PER_BATCH).collect();
    if batches.is_empty() {
        passes_done = spp;
    }
    pool.install(|| {
        // A pass's samples are summed here, then added to the film pixel by pixel, so a pass
        // cut short leaves the film untouched and no per-pass copy of it is needed.
        let mut pass_film = Film::new(scene.pixel_bounds);
        // Rendered tile buffers not yet merged, with their pass and whether they close it.
        // They are merged (in tile order, on one thread) while the next batch renders on the
        // others, across pass boundaries too: the next pass's first batch is only merged once
        // this pass has been added to the film and the accumulator cleared.
        let mut pending: Option<(u32, Vec<TileBuffer>, bool)> = None;
        let spare: Mutex<Vec<TileBuffer>> = Mutex::new(Vec::new());
        let settle = |pending: Option<(u32, Vec<TileBuffer>, bool)>,
                      pass_film: &mut Film,
                      film: &mut Film,
                      passes_done: &mut u32| {
            let Some((pass, buffers, closes_pass)) = pending else {
                return;
            };
            for b in &buffers {
                pass_film.merge(b);
            }
            // Merged buffers go back for reuse: no allocation, and no fresh pages to fault in,
            // per tile and pass.
            if let Ok(mut s) = spare.lock() {
                s.extend(buffers);
            }
            if closes_pass {
                film.add(pass_film);
                pass_film.clear();
                *passes_done = pass + 1;
                if let Some(f) = on_pass {
                    f(pass + 1, spp, film);
                }
            }
        };
        'passes: for pass in first_pass..spp {
            for (i, batch) in batches.iter().enumerate() {
                let previous = pending.take();
                let (buffers, ()) = rayon::join(
                    || {
                        batch
                            .par_iter()
                            .map(|&tile| {
                                if cancelled() {
                                    return None;
                                }
                                let recycled = spare.lock().ok().and_then(|mut s| s.pop());
                                let mut buffer = match recycled {
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
                                    f(done, total_tiles);
                                }
                                Some(buffer)
                            })
                            .collect::<Vec<Option<TileBuffer>>>()
                    },
                    || settle(previous, &mut pass_film, &mut film, &mut passes_done),
                );
                if cancelled() || buffers.iter().any(Option::is_none) {
                    // Cancelled: the pass under way is dropped (the one before it, if it was
                    // still pending, was added to the film by the settle just done).
                    break 'passes;
                }
                let closes_pass = i + 1 == batches.len();
                pending = Some((pass, buffers.into_iter().flatten().collect(), closes_pass));
            }
        }
        settle(pending.take(), &mut pass_film, &mut film, &mut passes_done);
    });
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
    for y in tile.y0..tile.y1 {
        for x in tile.x0..tile.x1 {
            stats.samples += 1;
            let mut stream = scene.sampler.stream([x, y], index);
            let dims = stream.camera();
            let p_film = Vec2::new(x as f32, y as f32) + dims.film;
            let sample = CameraSample {
                p_film: Point2::from_glam(p_film),
                p_lens: dims.lens,
                time: dims.time,
            };
            let Some(camera_ray) = scene.camera.generate_ray(&sample) else {
                // No ray: the sample sees nothing, but still counts in the pixel's mean.
                stats.no_ray += 1;
                buffer.add_sample(p_film, Vec3::ZERO, false);
                continue;
            };
            let (value, hit) = sample_value(scene, path, &camera_ray.ray, &mut stream);
            let value = value * camera_ray.weight;
            if !value.is_finite() {
                stats.dropped_nonfinite += 1;
                continue;
            }
            buffer.add_sample(p_film, value, hit);
        }
    }
    stats
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
        return path.li_and_hit(&scene.geometry, &scene.shading, ray, stream);
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
