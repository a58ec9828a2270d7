//! The Obscura side of the side-by-side harness (`bench/compare.py` runs it).
//!
//! `cargo run --release --example obscura-side -- MESH SIZE DIR` builds the generated mesh
//! (`icosphere` with SIZE subdivisions, or `grid` of SIZE x SIZE quads), writes it and the ray
//! sets to DIR as raw little-endian arrays so the peers trace exactly the same data, then
//! measures build time and one-thread throughput of the closest hit (the full `Hit`, and the
//! preliminary hit: distance, ids and barycentrics, what `rtcIntersect1` returns) and of
//! occlusion, one ray at a time and in batches of 4096 (`intersect_preliminary_batch`,
//! `occluded_batch`), and prints one JSON object on stdout. Run by hand, never by the test suite.

use camera_obscura::accel::{Placement, Scene, SceneBuilder, Shape, TriangleMesh};
use camera_obscura::space::{Point3, Ray, Transform, Vector3, World};
use std::hint::black_box;
use std::io::Write;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

// obscura-accel's generated meshes (test and benchmark code, not its API); the ray sets in
// the same file are not used on this side.
#[allow(dead_code)]
#[path = "../crates/obscura-accel/tests/it/testmesh.rs"]
mod testmesh;

/// Rays per set: a 256 x 256 pinhole grid, and as many incoherent rays.
const SIDE: usize = 256;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, kind, size, dir] = args.as_slice() else {
        return Err("usage: obscura-side icosphere|grid SIZE DIR".into());
    };
    let size: u32 = size.parse()?;
    let mesh = Arc::new(match kind.as_str() {
        "icosphere" => testmesh::icosphere(size)?,
        "grid" => testmesh::displaced_grid(size)?,
        other => return Err(format!("unknown mesh {other:?}").into()),
    });
    let dir = Path::new(dir);
    std::fs::create_dir_all(dir)?;
    write_mesh(&mesh, dir)?;

    // Bounding sphere of the mesh: every ray set is framed on it.
    let b = mesh.bounds();
    let center = b.min.to_glam().lerp(b.max.to_glam(), 0.5);
    let radius = (b.max.to_glam() - b.min.to_glam()).length() * 0.5;
    let sets = [
        ("primary", primary_rays(center, radius)),
        (
            "random",
            random_rays(center, radius, b.min.to_glam(), b.max.to_glam()),
        ),
        ("miss", miss_rays(center, radius)),
    ];
    for (name, rays) in &sets {
        write_rays(rays, &dir.join(format!("rays_{name}.bin")))?;
    }

    // Build: best of three (the first also pages the mesh in).
    let mut build_s = f64::INFINITY;
    let mut scene = None;
    for _ in 0..3 {
        let start = Instant::now();
        let s = scene_of(&mesh);
        build_s = build_s.min(start.elapsed().as_secs_f64());
        scene = Some(s);
    }
    let scene = scene.expect("built three times");

    let mut out = format!(
        "{{\"triangles\": {}, \"build_s\": {build_s:.6}",
        mesh.triangle_count()
    );
    // Every measure's passes are spread over the whole measuring time, one pass of each in
    // turn, rather than run back to back: this host's noise comes and goes over seconds
    // (docs/performance.md, "The host's noise"), and a measure's best pass should not depend
    // on which second it happened to run in.
    type Pass<'a> = Box<dyn FnMut(&[Ray<World>]) -> usize + 'a>;
    let measures = || -> Vec<(&str, Pass<'_>)> {
        let scene = &scene;
        vec![
            (
                "closest",
                Box::new(|rs: &[Ray<World>]| {
                    rs.iter().filter(|r| scene.intersect(r).is_some()).count()
                }),
            ),
            (
                "occluded",
                Box::new(|rs: &[Ray<World>]| rs.iter().filter(|r| scene.occluded(r)).count()),
            ),
            (
                "preliminary",
                Box::new(|rs: &[Ray<World>]| {
                    rs.iter()
                        .filter(|r| scene.intersect_preliminary(r).is_some())
                        .count()
                }),
            ),
            (
                "preliminary_batch",
                Box::new(|rs: &[Ray<World>]| {
                    rs.chunks(BATCH)
                        .map(|c| {
                            scene
                                .intersect_preliminary_batch(c)
                                .iter()
                                .filter(|h| h.is_some())
                                .count()
                        })
                        .sum()
                }),
            ),
            (
                "occluded_batch",
                Box::new(|rs: &[Ray<World>]| {
                    rs.chunks(BATCH)
                        .map(|c| scene.occluded_batch(c).iter().filter(|&&o| o).count())
                        .sum()
                }),
            ),
        ]
    };
    /// A measure on one ray set, and its fastest pass so far.
    struct Run<'a> {
        label: String,
        rays: &'a [Ray<World>],
        pass: Pass<'a>,
        best: f64,
    }
    let mut runs = Vec::new();
    for (name, rays) in &sets {
        for (key, pass) in measures() {
            runs.push(Run {
                label: format!("{name}_{key}"),
                rays,
                pass,
                best: f64::INFINITY,
            });
        }
    }
    for _ in 0..PASSES {
        for run in &mut runs {
            let start = Instant::now();
            black_box((run.pass)(run.rays));
            run.best = run.best.min(start.elapsed().as_secs_f64());
        }
    }
    for run in &runs {
        let rate = run.rays.len() as f64 / run.best;
        out += &format!(", \"{}_rps\": {rate:.1}", run.label);
    }
    for (name, rays) in &sets {
        let hits = rays.iter().filter(|r| scene.intersect(r).is_some()).count();
        out += &format!(", \"{name}_hits\": {hits}");
    }
    out += "}";
    println!("{out}");
    Ok(())
}

fn scene_of(mesh: &Arc<TriangleMesh>) -> Scene {
    let mut builder = SceneBuilder::new();
    builder
        .add(
            Shape::Mesh(mesh.clone()),
            Placement::Static(Transform::IDENTITY),
        )
        .expect("a generated mesh is valid");
    builder.build().expect("a generated mesh builds")
}

/// Passes of each measure over its ray set; each measure keeps its fastest.
const PASSES: usize = 5;

/// Rays per batch query.
const BATCH: usize = 4096;

/// A pinhole grid from outside the bounding sphere, its field just covering the sphere.
fn primary_rays(center: glam::Vec3, radius: f32) -> Vec<Ray<World>> {
    let back = glam::Vec3::new(0.2, 0.6, 1.0).normalize();
    let eye = center + back * (2.5 * radius);
    // Camera frame looking at the centre.
    let w = -back;
    let u = w.cross(glam::Vec3::Y).normalize();
    let v = u.cross(w);
    let half = (1.0f32 / 2.5).asin().tan();
    let mut rays = Vec::with_capacity(SIDE * SIDE);
    for j in 0..SIDE {
        for i in 0..SIDE {
            let x = ((i as f32 + 0.5) / SIDE as f32 * 2.0 - 1.0) * half;
            let y = (1.0 - (j as f32 + 0.5) / SIDE as f32 * 2.0) * half;
            let d = (w + u * x + v * y).normalize();
            rays.push(ray(eye, d));
        }
    }
    rays
}

/// From random points on a sphere of 1.5x the bounding radius to random points in the box
/// (a fixed xorshift sequence, so every run traces the same rays).
fn random_rays(center: glam::Vec3, radius: f32, lo: glam::Vec3, hi: glam::Vec3) -> Vec<Ray<World>> {
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut u = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    (0..SIDE * SIDE)
        .map(|_| {
            let dir = loop {
                let v = glam::Vec3::new(2.0 * u() - 1.0, 2.0 * u() - 1.0, 2.0 * u() - 1.0);
                let l = v.length();
                if l > 0.1 && l <= 1.0 {
                    break v / l;
                }
            };
            let origin = center + dir * (1.5 * radius);
            let target = lo + (hi - lo) * glam::Vec3::new(u(), u(), u());
            ray(origin, (target - origin).normalize())
        })
        .collect()
}

/// Rays that start outside the box and point away from it: they measure the fixed cost of a
/// query (for embreex, mostly the Python-to-Embree call).
fn miss_rays(center: glam::Vec3, radius: f32) -> Vec<Ray<World>> {
    (0..SIDE * SIDE)
        .map(|k| {
            let a = k as f32 * 0.001;
            let d = glam::Vec3::new(1.0, 0.3 * a.sin(), 0.3 * a.cos()).normalize();
            ray(center + d * (2.0 * radius), d)
        })
        .collect()
}

fn ray(o: glam::Vec3, d: glam::Vec3) -> Ray<World> {
    Ray::new(Point3::from_glam(o), Vector3::from_glam(d), 0.0)
}

fn write_mesh(mesh: &TriangleMesh, dir: &Path) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(dir.join("positions.f32"))?);
    for p in mesh.positions() {
        for c in p.to_array() {
            f.write_all(&c.to_le_bytes())?;
        }
    }
    f.flush()?;
    let mut f = std::io::BufWriter::new(std::fs::File::create(dir.join("triangles.u32"))?);
    for t in mesh.triangles() {
        for c in t {
            f.write_all(&c.to_le_bytes())?;
        }
    }
    f.flush()
}

/// Six f32 per ray: origin then unit direction.
fn write_rays(rays: &[Ray<World>], path: &Path) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    for r in rays {
        for c in r.origin.to_glam().to_array() {
            f.write_all(&c.to_le_bytes())?;
        }
        for c in r.direction.to_glam().to_array() {
            f.write_all(&c.to_le_bytes())?;
        }
    }
    f.flush()
}
