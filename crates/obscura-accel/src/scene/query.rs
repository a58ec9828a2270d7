//! The ray queries: closest hit (full or preliminary) and any hit, through the top level into
//! each item.

use super::{Analytic, Found, Item, PlainRay, Scene, Top, to_object};
use crate::geom::intersect_sphere;
use crate::hit::Hit;
use crate::simd::prefetch;
use crate::wide::{BatchRay, BoxSet, WideBvh};
use glam::{Vec2, Vec3};
use obscura_space::{Bounds3, Ray, World};
use obvhs::ray::RayHit;

/// The closest hit a [`Scene::intersect_preliminary`] query found, before the full [`Hit`] is
/// built: cheap to get (no mesh data is read) and turned into the `Hit` by
/// [`complete`](PreliminaryHit::complete), exactly as [`Scene::intersect`] would have
/// returned it. It borrows the scene, so it cannot be completed against another.
#[derive(Clone, Copy, Debug)]
pub struct PreliminaryHit<'a> {
    scene: &'a Scene,
    ray: PlainRay,
    found: Found,
}

impl PreliminaryHit<'_> {
    /// The ray parameter of the hit (as [`Hit::t`]).
    pub fn t(&self) -> f32 {
        self.found.t()
    }

    /// The instance hit (as [`Hit::instance`]).
    pub fn instance(&self) -> u32 {
        match self.found {
            Found::Flat { hit } => hit.ids[1],
            Found::Moving { item, .. } | Found::Sphere { item, .. } | Found::Quad { item, .. } => {
                match &self.scene.items[item] {
                    Item::Analytic { instance, .. } | Item::MovingMesh { instance, .. } => {
                        *instance
                    }
                    Item::Flat => unreachable!("flattened triangles are found as Found::Flat"),
                }
            }
        }
    }

    /// The triangle hit within its mesh, 0 for spheres and quads (as [`Hit::primitive`]).
    pub fn primitive(&self) -> u32 {
        match self.found {
            Found::Flat { hit } | Found::Moving { hit, .. } => hit.ids[0],
            Found::Sphere { .. } | Found::Quad { .. } => 0,
        }
    }

    /// The primitive's own coordinates of the hit: for a triangle the barycentrics `(b1, b2)`
    /// of its vertices 1 and 2, for a quad `(s, t)` along `edge_u` and `edge_v`; zero for a
    /// sphere, whose coordinates need the hit point (see [`Hit::uv`]).
    pub fn primitive_uv(&self) -> Vec2 {
        match self.found {
            Found::Flat { hit } | Found::Moving { hit, .. } => Vec2::new(hit.tri.b1, hit.tri.b2),
            Found::Quad { quad, .. } => Vec2::new(quad.s, quad.v),
            Found::Sphere { .. } => Vec2::ZERO,
        }
    }

    /// The full hit record: point and error bound, normals, surface coordinates.
    pub fn complete(&self) -> Hit {
        self.scene.finish(&self.ray, self.found)
    }
}

impl Scene {
    /// The closest hit with `t` in `[t_min, t_max]`, moving instances placed at the ray's time.
    /// `None` for a miss, and for rays that cannot hit anything (non-finite origin or
    /// direction, zero direction, NaN or empty range).
    ///
    /// The same as [`intersect_preliminary`](Scene::intersect_preliminary) followed by
    /// [`PreliminaryHit::complete`].
    pub fn intersect(&self, ray: &Ray<World>) -> Option<Hit> {
        // Written out rather than as `intersect_preliminary(ray)?.complete()`, so the hot path
        // does not move a `PreliminaryHit` through (docs/performance.md).
        let r = PlainRay::new(ray)?;
        let found = self.found(&r)?;
        Some(self.finish(&r, found))
    }

    /// The closest hit as [`intersect`](Scene::intersect) finds it, before its full record is
    /// built: the distance, the instance and primitive, and the primitive's own coordinates,
    /// with no mesh data read (the role of Embree's `rtcIntersect1` or Mitsuba's preliminary
    /// intersection). For queries that need only what was hit and how far away (depth and id
    /// buffers, lidar returns), and for deciding which hits deserve
    /// [`complete`](PreliminaryHit::complete).
    ///
    /// ```
    /// use obscura_accel::{Placement, SceneBuilder, Shape};
    /// use obscura_space::{Point3, Ray, Transform, Vector3, World};
    /// use obscura_space::glam::Vec3;
    ///
    /// let mut builder = SceneBuilder::new();
    /// let quad = Shape::Quad {
    ///     origin: Vec3::new(-1.0, -1.0, 0.0),
    ///     edge_u: Vec3::new(2.0, 0.0, 0.0),
    ///     edge_v: Vec3::new(0.0, 2.0, 0.0),
    /// };
    /// let id = builder.add(quad, Placement::Static(Transform::IDENTITY))?;
    /// let scene = builder.build()?;
    /// let ray = Ray::<World>::new(Point3::new(0.5, 0.0, 3.0), Vector3::new(0.0, 0.0, -1.0), 0.0);
    /// let found = scene.intersect_preliminary(&ray).expect("the ray meets the quad");
    /// assert_eq!((found.instance(), found.t()), (id, 3.0));
    /// assert_eq!(found.primitive_uv().to_array(), [0.75, 0.5]);
    /// assert_eq!(found.complete(), scene.intersect(&ray).unwrap());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn intersect_preliminary(&self, ray: &Ray<World>) -> Option<PreliminaryHit<'_>> {
        let r = PlainRay::new(ray)?;
        let found = self.found(&r)?;
        Some(PreliminaryHit {
            scene: self,
            ray: r,
            found,
        })
    }

    /// Whether the batch queries ([`intersect_batch`](Scene::intersect_batch),
    /// [`occluded_batch`](Scene::occluded_batch)) can be faster than one ray at a time here:
    /// only the static triangles' BVH is traversed in turns, and only when it is too large
    /// for the caches nearest the core (a few MB: about 40,000 triangles or more) and the
    /// scene has at most eight items besides (more go through obvhs's top-level tree, one ray
    /// at a time). Spheres, quads, moving meshes and small meshes are answered one ray at a
    /// time either way, so a caller that would gather rays just for the batch need not when
    /// this is false. The answers are the same either way.
    pub fn batches(&self) -> bool {
        self.pausable_flat().is_some_and(WideBvh::interleaves)
    }

    /// The flattened triangles' BVH when a ray's walk over the top level can pause at it
    /// (no top level, or a few boxes visited nearest first), as the batch queries need.
    fn pausable_flat(&self) -> Option<&WideBvh> {
        match self.tlas {
            Top::One | Top::Few { sorted: true, .. } => self.flat.as_ref(),
            Top::Few { sorted: false, .. } | Top::Two(_) | Top::Quads { .. } | Top::Tree(..) => {
                None
            }
        }
    }

    /// The closest hit of each ray in `rays`, in order: the same as [`intersect`](Scene::intersect)
    /// on each, but on a large mesh several rays are traversed in turns so that their cache
    /// misses overlap (faster per ray where the BVH does not fit the cache).
    pub fn intersect_batch(&self, rays: &[Ray<World>]) -> Vec<Option<Hit>> {
        let found = self.found_batch(rays, |r, found| (r, found));
        // A mesh hit's record reads the triangle's vertex indices, then its vertices' normals,
        // at random in arrays of megabytes: ask for the indices of every hit, then, once
        // they have come, for the normals, so that the records' misses overlap. A mesh
        // without normals (nor uvs asked for) reads neither.
        let mesh_hits = || {
            found.iter().filter_map(|f| match f {
                Some((_, Found::Flat { hit })) => {
                    let [primitive, instance] = hit.ids;
                    let mesh = self.meshes.get(instance as usize)?.as_ref()?;
                    if mesh.normals().is_none() && !(self.uv && mesh.uvs().is_some()) {
                        return None;
                    }
                    Some((mesh, mesh.triangles().get(primitive as usize)?))
                }
                _ => None,
            })
        };
        if self.batches() {
            for (_, vertices) in mesh_hits() {
                prefetch(vertices, 0);
            }
            for (mesh, vertices) in mesh_hits() {
                if let Some(normals) = mesh.normals() {
                    for &v in vertices {
                        if let Some(n) = normals.get(v as usize) {
                            prefetch(n, 0);
                        }
                    }
                }
            }
        }
        found
            .into_iter()
            .map(|f| f.map(|(r, found)| self.finish(&r, found)))
            .collect()
    }

    /// The closest hit of each ray in `rays` before its record is built, in order: the same
    /// as [`intersect_preliminary`](Scene::intersect_preliminary) on each, with the batch
    /// traversal of [`intersect_batch`](Scene::intersect_batch).
    pub fn intersect_preliminary_batch(
        &self,
        rays: &[Ray<World>],
    ) -> Vec<Option<PreliminaryHit<'_>>> {
        self.found_batch(rays, |ray, found| PreliminaryHit {
            scene: self,
            ray,
            found,
        })
    }

    /// What [`found`](Scene::found) gives for each ray, with the ray as checked. Each ray
    /// visits the items exactly as `found` does; where that order reaches the flattened
    /// triangles, the ray waits, and the waiting rays go through their BVH together
    /// ([`WideBvh::closest_batch`]) before each goes on with the items after it. Each answer
    /// is made into the caller's record by `make` where it is found, so that no array of
    /// intermediate records is written and copied again.
    fn found_batch<T>(
        &self,
        rays: &[Ray<World>],
        make: impl Fn(PlainRay, Found) -> T,
    ) -> Vec<Option<T>> {
        let plain = rays.iter().map(PlainRay::new);
        let Some(flat) = self.pausable_flat() else {
            return plain
                .map(|r| r.and_then(|r| Some(make(r, self.found(&r)?))))
                .collect();
        };
        if let Top::One = self.tlas {
            // The flattened triangles are the only item: every valid ray goes to their BVH,
            // over its whole range, with no walk over items to pause and resume.
            let plain: Vec<Option<PlainRay>> = plain.collect();
            let batch: Vec<BatchRay> = plain.iter().flatten().map(BatchRay::from).collect();
            let mut hits = vec![None; batch.len()];
            flat.closest_batch(&batch, &mut hits);
            let mut hits = hits.into_iter();
            return plain
                .into_iter()
                .map(|r| {
                    let r = r?;
                    let hit = hits.next().flatten()?;
                    Some(make(r, Found::Flat { hit }))
                })
                .collect();
        }
        // Each ray's walk over the items it enters, as in `found`: nearest first under a few
        // boxes, the one item (the flattened triangles) with no top level. It runs up to the
        // flattened triangles and, after the batch, on from there.
        struct Walk {
            r: PlainRay,
            entered: [(usize, f32); BoxSet::CAPACITY],
            n: usize,
            next: usize,
            best: Option<Found>,
            t_best: f32,
        }
        let walk = |w: &mut Walk| -> bool {
            while w.next < w.n {
                let (item, t_entry) = w.entered[w.next];
                if t_entry > w.t_best {
                    w.next = w.n;
                    break;
                }
                if matches!(self.items[item], Item::Flat) {
                    return true;
                }
                w.next += 1;
                if let Some(f) = self.intersect_item(item, &w.r, w.t_best) {
                    w.t_best = f.t();
                    w.best = Some(f);
                }
            }
            false
        };
        let mut walks: Vec<Option<Walk>> = plain
            .map(|r| {
                let r = r?;
                let mut entered = [(0, r.t_min); BoxSet::CAPACITY];
                let n = match &self.tlas {
                    Top::Few { set, .. } => set.entered(r.o, r.d, r.t_min, r.t_max, &mut entered),
                    _ => 1,
                };
                Some(Walk {
                    r,
                    entered,
                    n,
                    next: 0,
                    best: None,
                    t_best: r.t_max,
                })
            })
            .collect();
        // At most one entry per ray: sized once, so that pushing never reallocates.
        let mut waiting = Vec::with_capacity(walks.len());
        let mut batch = Vec::with_capacity(walks.len());
        for (k, w) in walks.iter_mut().enumerate() {
            if let Some(w) = w
                && walk(w)
            {
                waiting.push(k);
                batch.push(BatchRay {
                    t_max: w.t_best,
                    ..BatchRay::from(&w.r)
                });
            }
        }
        let mut hits = vec![None; batch.len()];
        flat.closest_batch(&batch, &mut hits);
        for (k, hit) in waiting.into_iter().zip(hits) {
            if let Some(w) = &mut walks[k] {
                w.next += 1;
                if let Some(hit) = hit {
                    w.t_best = hit.tri.t;
                    w.best = Some(Found::Flat { hit });
                }
                // One flat item only: the rest of the walk needs no batch.
                walk(w);
            }
        }
        walks
            .into_iter()
            .map(|w| w.and_then(|w| Some(make(w.r, w.best?))))
            .collect()
    }

    /// Whether anything is hit, for each ray in `rays`, in order: the same as
    /// [`occluded`](Scene::occluded) on each, with the flattened triangles' BVH queried for
    /// all the rays together as in [`intersect_batch`](Scene::intersect_batch) (any-hit
    /// queries visit items in no particular order, so the answer is the same).
    pub fn occluded_batch(&self, rays: &[Ray<World>]) -> Vec<bool> {
        let Some(flat) = self.pausable_flat() else {
            return rays.iter().map(|r| self.occluded(r)).collect();
        };
        let flat_lane = self.items.iter().position(|i| matches!(i, Item::Flat));
        let mut out = Vec::with_capacity(rays.len());
        let mut waiting = Vec::with_capacity(rays.len());
        let mut batch = Vec::with_capacity(rays.len());
        for ray in rays {
            let Some(r) = PlainRay::new(ray) else {
                out.push(false);
                continue;
            };
            let mask = match &self.tlas {
                Top::Few { set, .. } => set.entered_mask(r.o, r.d, r.t_min, r.t_max),
                _ => 1,
            };
            let flat_bit = flat_lane.map_or(0, |lane| 1 << lane) & mask;
            let mut others = mask & !flat_bit;
            let mut hit = false;
            while others != 0 && !hit {
                let item = others.trailing_zeros() as usize;
                others &= others - 1;
                hit = self.occluded_item(item, &r);
            }
            if !hit && flat_bit != 0 {
                waiting.push(out.len());
                batch.push(BatchRay::from(&r));
            }
            out.push(hit);
        }
        let mut hits = vec![false; batch.len()];
        flat.any_batch(&batch, &mut hits);
        for (k, hit) in waiting.into_iter().zip(hits) {
            out[k] = hit;
        }
        out
    }

    /// The closest hit on any item, before its record is built.
    #[inline]
    fn found(&self, r: &PlainRay) -> Option<Found> {
        match &self.tlas {
            Top::One if self.items.len() == 1 => self.intersect_item(0, r, r.t_max),
            Top::One => None,
            Top::Few { set, sorted: true } => {
                let mut entered = [(0, 0.0); BoxSet::CAPACITY];
                let n = set.entered(r.o, r.d, r.t_min, r.t_max, &mut entered);
                // The best distance is kept beside the best hit, not read back from it: a
                // `Found` is a 72-byte enum, and matching it for its `t` before every item
                // would put a jump table and stack copies in the hottest loop of small scenes.
                let mut best: Option<Found> = None;
                let mut t_best = r.t_max;
                for &(item, t_entry) in &entered[..n] {
                    if t_entry > t_best {
                        break;
                    }
                    if let Some(f) = self.intersect_item(item, r, t_best) {
                        t_best = f.t();
                        best = Some(f);
                    }
                }
                best
            }
            Top::Few { set, sorted: false } => {
                // Spheres and quads in index order: the sort (and the zeroed array it fills)
                // costs more than the item tests it would spare (docs/performance.md). One
                // entered beyond the best hit so far is still skipped.
                let (mut best, mut t_best) = (None, r.t_max);
                self.closest_in_order(set, |lane| lane, r, &mut best, &mut t_best);
                best
            }
            Top::Two(sets) => {
                let (mut best, mut t_best) = (None, r.t_max);
                for (base, set) in [0, BoxSet::CAPACITY].into_iter().zip(sets) {
                    self.closest_in_order(set, |lane| base + lane, r, &mut best, &mut t_best);
                }
                best
            }
            Top::Quads {
                quads,
                boxes,
                others,
            } => {
                let (mut best, mut t_best) = (None, r.t_max);
                if let Some((item, quad)) = quads.closest(r.o, r.d, r.t_min, r.t_max) {
                    t_best = quad.t;
                    best = Some(Found::Quad { item, quad });
                }
                if let Some(set) = boxes {
                    self.closest_in_order(set, |lane| others[lane], r, &mut best, &mut t_best);
                }
                best
            }
            Top::Tree(tlas, order) => {
                let top = obvhs::ray::Ray::new(r.o, r.d, r.t_min, r.t_max);
                let mut ray_hit = RayHit::none();
                let mut best = None;
                tlas.ray_traverse(top, &mut ray_hit, |top, slot| {
                    match self.intersect_item(order[slot] as usize, r, top.tmax) {
                        Some(f) => {
                            best = Some(f);
                            f.t()
                        }
                        None => f32::INFINITY,
                    }
                });
                best
            }
        }
    }

    /// True when anything is hit with `t` in `[t_min, t_max]` (for shadow rays); stops at the
    /// first hit found.
    pub fn occluded(&self, ray: &Ray<World>) -> bool {
        let Some(r) = PlainRay::new(ray) else {
            return false;
        };
        match &self.tlas {
            Top::One if self.items.len() == 1 => self.occluded_item(0, &r),
            Top::One => false,
            // Any order will do for a shadow ray.
            Top::Few { set, .. } => self.any_in(set, |lane| lane, &r),
            Top::Two(sets) => [0, BoxSet::CAPACITY]
                .into_iter()
                .zip(sets)
                .any(|(base, set)| self.any_in(set, |lane| base + lane, &r)),
            Top::Quads {
                quads,
                boxes,
                others,
            } => {
                quads.any(r.o, r.d, r.t_min, r.t_max)
                    || boxes
                        .as_ref()
                        .is_some_and(|set| self.any_in(set, |lane| others[lane], &r))
            }
            Top::Tree(tlas, order) => {
                let top = obvhs::ray::Ray::new(r.o, r.d, r.t_min, r.t_max);
                !tlas.ray_traverse_miss(top, |_, slot| {
                    if self.occluded_item(order[slot] as usize, &r) {
                        f32::NEG_INFINITY
                    } else {
                        f32::INFINITY
                    }
                })
            }
        }
    }

    /// True when some instance moves (a placement given at shutter close): only then does a
    /// ray's time change what it hits. Constant time (found at build), so a renderer may ask
    /// per tile.
    pub fn moves(&self) -> bool {
        self.moves
    }

    /// The box of everything in the scene, over all times.
    pub fn bounds(&self) -> Bounds3<World> {
        self.bounds
    }

    /// The number of instances added.
    pub fn instance_count(&self) -> usize {
        self.meshes.len()
    }

    /// Bytes held by the triangle BVHs (nodes and leaf triangles; the meshes themselves and
    /// the few-box top level are not counted), for memory budgets and the performance notes.
    pub fn bvh_bytes(&self) -> usize {
        let flat = self.flat.as_ref().map_or(0, WideBvh::heap_bytes);
        flat + self.blases.iter().map(WideBvh::heap_bytes).sum::<usize>()
    }

    /// Tests the items whose boxes in `set` the ray enters (lane `k`'s item is `item_of(k)`)
    /// in lane order, each with the best distance so far as its `t_max`, and keeps the
    /// closest hit in `best` and its distance in `t_best`. An item whose box is entered
    /// beyond the best hit so far is skipped.
    #[inline(always)]
    fn closest_in_order(
        &self,
        set: &BoxSet,
        item_of: impl Fn(usize) -> usize,
        r: &PlainRay,
        best: &mut Option<Found>,
        t_best: &mut f32,
    ) {
        let (t_near, mut mask) = set.test(r.o, r.d, r.t_min, *t_best);
        while mask != 0 {
            let lane = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            if t_near[lane] > *t_best {
                continue;
            }
            if let Some(f) = self.intersect_item(item_of(lane), r, *t_best) {
                *t_best = f.t();
                *best = Some(f);
            }
        }
    }

    /// Whether the ray hits an item whose box in `set` it enters (lane `k`'s item is
    /// `item_of(k)`).
    #[inline(always)]
    fn any_in(&self, set: &BoxSet, item_of: impl Fn(usize) -> usize, r: &PlainRay) -> bool {
        let mut mask = set.entered_mask(r.o, r.d, r.t_min, r.t_max);
        while mask != 0 {
            let lane = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            if self.occluded_item(item_of(lane), r) {
                return true;
            }
        }
        false
    }

    /// The closest hit on one item with `t` in `[r.t_min, t_max]`.
    #[inline]
    fn intersect_item(&self, item: usize, r: &PlainRay, t_max: f32) -> Option<Found> {
        match &self.items[item] {
            Item::Flat => {
                let hit = self.flat.as_ref()?.closest(r.o, r.d, r.t_min, t_max)?;
                Some(Found::Flat { hit })
            }
            Item::MovingMesh {
                blas,
                world_from_object,
                ..
            } => {
                let (o, d) = to_object(&world_from_object.at(r.time).inverse_matrix(), r);
                let hit = self.blases[*blas].closest(o, d, r.t_min, t_max)?;
                Some(Found::Moving { item, hit })
            }
            Item::Analytic { shape, xform, .. } => {
                let (o, d) = xform.ray_to_object(r);
                let (o, d) = (Vec3::from(o), Vec3::from(d));
                match *shape {
                    Analytic::Sphere { center, radius } => {
                        let t = intersect_sphere(o, d, r.t_min, t_max, center, radius)?;
                        Some(Found::Sphere { item, t })
                    }
                    Analytic::Quad(parallelogram) => {
                        let quad = parallelogram.intersect(o, d, r.t_min, t_max)?;
                        Some(Found::Quad { item, quad })
                    }
                }
            }
        }
    }

    /// True when one item is hit with `t` in `[r.t_min, r.t_max]`.
    #[inline]
    fn occluded_item(&self, item: usize, r: &PlainRay) -> bool {
        match &self.items[item] {
            Item::Flat => self
                .flat
                .as_ref()
                .is_some_and(|blas| blas.any(r.o, r.d, r.t_min, r.t_max)),
            Item::MovingMesh {
                blas,
                world_from_object,
                ..
            } => {
                let (o, d) = to_object(&world_from_object.at(r.time).inverse_matrix(), r);
                self.blases[*blas].any(o, d, r.t_min, r.t_max)
            }
            Item::Analytic { .. } => self.intersect_item(item, r, r.t_max).is_some(),
        }
    }
}
