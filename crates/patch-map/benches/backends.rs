//! Collision-query throughput of the patch-map backends (thesis §5.5.3–5.5.4 compared the
//! backends' planning times; this isolates their queries): native polygons without a broad
//! phase ([`PolygonMap`]), patch boxes in a 6D k-d forest ([`BBox6dMap`]), one BVH over all
//! triangles ([`TrimeshMap`]) and one collider per patch in rapier's broad phase
//! ([`RapierMap`]), and the point-cloud map ([`PointCloudMap`], Algorithm 10) of the scene's
//! surfaces sampled every 0.1 m (unspecific queries only, as the thesis scopes it).
//!
//! Scenes:
//! * `random`: 3000 random planar patches (rectangles and star-shaped polygons, 0.2–2 m,
//!   random orientations) in a 60 × 60 × 6 m box, seeded; `random-30k`: 30,000 at the same
//!   density (190 × 190 × 6 m);
//! * `office`: the empty office floor plan of `scene-sim` (walls with doors, floor, ceiling;
//!   §5.5.3, Fig. 5.19), each scene polygon one planar patch (doors that reach a wall's edge
//!   become notches of its outline).
//!
//! Per scene and backend: the time to build the map from its patches, and for steps of 0.2 m,
//! 1 m and 5 m (random start in the scene's box, random direction) the throughput of capsule
//! steps of radius 0.3 m (`capsule_free`: unspecific, `capsule_hit`: specific) and line steps
//! (`line_free`, `line_hit`), in steps per second (`Throughput::Elements`).
//!
//! Run with `cargo bench -p patch-map --bench backends -- --warm-up-time 1 --measurement-time 2`.
//! A backend is one line in [`backends`].

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_main};
use patch_core::{
    Aabb, CapsuleStep, FromPatches, Isometry3, LineStep, Patch, PlanarPatch, Point2, Point3,
    Polygon, Real, SpecificStepIntersector, UnspecificStepIntersector, Vector3, na,
};
#[cfg(feature = "rapier")]
use patch_map::RapierMap;
use patch_map::{
    BBox6dMap, Backend as BackendName, PointCloudMap, PolygonMap, TrimeshMap, sample_patch_points,
};

/// The robot radius.
const RADIUS: Real = 0.3;
/// Step lengths, metres.
const LENGTHS: [Real; 3] = [0.2, 1.0, 5.0];
/// Steps per measured batch.
const BATCH: usize = 256;

/// The backends compared: one line each.
fn backends(c: &mut Criterion, scene: &Scene) {
    bench_backend::<PolygonMap>(c, scene, BackendName::Polygon.name());
    bench_backend::<BBox6dMap>(c, scene, BackendName::BBox6d.name());
    bench_backend::<TrimeshMap>(c, scene, BackendName::Trimesh.name());
    #[cfg(feature = "rapier")]
    bench_backend::<RapierMap>(c, scene, BackendName::Rapier.name());
    bench_point_cloud(c, scene);
}

/// Sample spacing of the point-cloud map, metres: below r/2, the density Algorithm 10 assumes.
const SPACING: Real = 0.1;

/// The point-cloud map of the scene's surfaces sampled at [`SPACING`]: its build time and its
/// two queries (the unspecific ones, all the thesis's point-cloud map offers).
fn bench_point_cloud(c: &mut Criterion, scene: &Scene) {
    let points = sample_patch_points(&scene.patches, SPACING).expect("scene patches");
    let mut g = c.benchmark_group(format!("{}/build", scene.name));
    g.sample_size(10);
    g.throughput(Throughput::Elements(scene.patches.len() as u64));
    let name = BackendName::PointCloud.name();
    g.bench_function(name, |b| {
        b.iter(|| PointCloudMap::from_points(black_box(&points)).expect("finite points"))
    });
    g.finish();
    let map = PointCloudMap::from_points(&points).expect("finite points");
    type Run = fn(&PointCloudMap, &[CapsuleStep]) -> usize;
    let unspecific: [(&str, Run); 2] = [
        ("capsule_free", |m, s| s.iter().filter(|s| !m.is_step_free(*s)).count()),
        ("line_free", |m, s| s.iter().filter(|s| !m.is_step_free(&s.line())).count()),
    ];
    for (query, run) in unspecific {
        let mut g = c.benchmark_group(format!("{}/{query}", scene.name));
        g.throughput(Throughput::Elements(BATCH as u64));
        for (length, steps) in &scene.steps {
            g.bench_with_input(BenchmarkId::new(name, format!("{length} m")), steps, |b, steps| {
                b.iter(|| run(&map, black_box(steps)))
            });
        }
        g.finish();
    }
}

/// Everything a benchmarked backend answers.
trait Backend:
    FromPatches
    + UnspecificStepIntersector
    + SpecificStepIntersector
    + UnspecificStepIntersector<LineStep>
    + SpecificStepIntersector<LineStep>
{
}

impl<M> Backend for M where
    M: FromPatches
        + UnspecificStepIntersector
        + SpecificStepIntersector
        + UnspecificStepIntersector<LineStep>
        + SpecificStepIntersector<LineStep>
{
}

/// A scene: its patches, its box and the steps of each length.
struct Scene {
    name: &'static str,
    patches: Vec<Patch>,
    steps: Vec<(Real, Vec<CapsuleStep>)>,
}

fn bench_backend<M: Backend>(c: &mut Criterion, scene: &Scene, backend: &str) {
    let mut g = c.benchmark_group(format!("{}/build", scene.name));
    g.sample_size(10);
    g.throughput(Throughput::Elements(scene.patches.len() as u64));
    g.bench_function(backend, |b| {
        b.iter(|| M::from_patches(black_box(scene.patches.clone())).expect("scene patches"))
    });
    g.finish();

    let map = M::from_patches(scene.patches.clone()).expect("scene patches");
    for (query, run) in queries::<M>() {
        let mut g = c.benchmark_group(format!("{}/{query}", scene.name));
        g.throughput(Throughput::Elements(BATCH as u64));
        for (length, steps) in &scene.steps {
            g.bench_with_input(
                BenchmarkId::new(backend, format!("{length} m")),
                steps,
                |b, steps| b.iter(|| run(&map, black_box(steps))),
            );
        }
        g.finish();
    }
}

type Query<M> = (&'static str, fn(&M, &[CapsuleStep]) -> usize);

/// The four queries; each returns how many steps collide (so nothing is optimised away).
fn queries<M: Backend>() -> [Query<M>; 4] {
    [
        ("capsule_free", |m, s| {
            s.iter()
                .filter(|s| !UnspecificStepIntersector::<CapsuleStep>::is_step_free(m, s))
                .count()
        }),
        ("capsule_hit", |m, s| {
            s.iter()
                .filter(|s| SpecificStepIntersector::<CapsuleStep>::first_hit(m, s).is_some())
                .count()
        }),
        ("line_free", |m, s| {
            s.iter()
                .filter(|s| !UnspecificStepIntersector::<LineStep>::is_step_free(m, &s.line()))
                .count()
        }),
        ("line_hit", |m, s| {
            s.iter()
                .filter(|s| SpecificStepIntersector::<LineStep>::first_hit(m, &s.line()).is_some())
                .count()
        }),
    ]
}

/// A small seeded generator (xorshift64*), so the scenes need no extra dependency.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> Real {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as Real / (1u64 << 53) as Real
    }

    fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.unit()
    }

    fn direction(&mut self) -> Vector3 {
        loop {
            let v =
                Vector3::new(self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0));
            let n = v.norm();
            if (0.1..=1.0).contains(&n) {
                return v / n;
            }
        }
    }

    fn point(&mut self, bounds: &Aabb) -> Point3 {
        Point3::new(
            self.range(bounds.min.x, bounds.max.x),
            self.range(bounds.min.y, bounds.max.y),
            self.range(bounds.min.z, bounds.max.z),
        )
    }
}

/// `BATCH` steps of each length from random starts in `bounds`.
fn steps(rng: &mut Rng, bounds: &Aabb) -> Vec<(Real, Vec<CapsuleStep>)> {
    LENGTHS
        .iter()
        .map(|&length| {
            let steps = (0..BATCH)
                .map(|_| {
                    let a = rng.point(bounds);
                    CapsuleStep::new(a, a + rng.direction() * length, RADIUS).expect("finite")
                })
                .collect();
            (length, steps)
        })
        .collect()
}

/// `count` random planar patches in a box of `side × side × 6` m.
fn random_scene(name: &'static str, count: usize, side: Real) -> Scene {
    let mut rng = Rng(0x5eed_2010_0000_0001);
    let bounds = Aabb::new(Point3::new(0.0, 0.0, 0.0), Point3::new(side, side, 6.0));
    let mut patches = Vec::new();
    while patches.len() < count {
        let rotation = na::UnitQuaternion::from_scaled_axis(
            rng.direction() * rng.range(0.0, std::f64::consts::PI),
        );
        let pose = Isometry3::from_parts(rng.point(&bounds).coords.into(), rotation);
        let polygon = if rng.unit() < 0.5 {
            let (w, h) = (rng.range(0.2, 2.0), rng.range(0.2, 2.0));
            Polygon::rectangle(Point2::new(-w / 2.0, -h / 2.0), Point2::new(w / 2.0, h / 2.0))
        } else {
            let n = 3 + (rng.unit() * 8.0) as usize;
            let ring = (0..n)
                .map(|k| {
                    let angle =
                        (k as Real + rng.range(0.0, 0.4)) * std::f64::consts::TAU / n as Real;
                    let radius = rng.range(0.1, 1.0);
                    Point2::new(radius * angle.cos(), radius * angle.sin())
                })
                .collect();
            Polygon::new(ring, Vec::new())
        };
        if let Ok(p) = polygon.and_then(|poly| PlanarPatch::new(poly, pose)) {
            patches.push(p.into());
        }
    }
    let steps = steps(&mut rng, &bounds);
    Scene { name, patches, steps }
}

/// The outline of an axis-aligned rectangle with the rectangular holes that touch its bottom
/// or top edge turned into notches (a door reaching the floor); `None` if it is not such a
/// rectangle.
fn notched(outline: &[Point2], holes: &[&[Point2]]) -> Option<(Vec<Point2>, Vec<Vec<Point2>>)> {
    let lo = outline.iter().fold(outline[0], |m, p| m.inf(p));
    let hi = outline.iter().fold(outline[0], |m, p| m.sup(p));
    let boxes: Vec<(Point2, Point2)> = holes
        .iter()
        .map(|h| (h.iter().fold(h[0], |m, p| m.inf(p)), h.iter().fold(h[0], |m, p| m.sup(p))))
        .collect();
    let mut bottom: Vec<_> = boxes.iter().filter(|(l, _)| l.y <= lo.y).collect();
    let mut top: Vec<_> = boxes.iter().filter(|(_, h)| h.y >= hi.y).collect();
    bottom.sort_by(|a, b| a.0.x.total_cmp(&b.0.x));
    top.sort_by(|a, b| b.0.x.total_cmp(&a.0.x));
    let mut ring = vec![lo];
    for (l, h) in bottom {
        ring.extend([Point2::new(l.x, lo.y), Point2::new(l.x, h.y), *h, Point2::new(h.x, lo.y)]);
    }
    ring.extend([Point2::new(hi.x, lo.y), hi]);
    for (l, h) in top {
        ring.extend([Point2::new(h.x, hi.y), Point2::new(h.x, l.y), *l, Point2::new(l.x, hi.y)]);
    }
    ring.push(Point2::new(lo.x, hi.y));
    ring.dedup();
    if ring.first() == ring.last() {
        ring.pop();
    }
    let inner = boxes
        .iter()
        .filter(|(l, h)| l.y > lo.y && h.y < hi.y)
        .map(|(l, h)| vec![*l, Point2::new(h.x, l.y), *h, Point2::new(l.x, h.y)])
        .collect();
    (outline.len() == 4).then_some((ring, inner))
}

/// The empty office floor plan of `scene-sim`, one planar patch per scene polygon.
fn office_scene() -> Scene {
    let scene = scene_sim::office_floorplan().expect("office floor plan");
    let mut patches = Vec::new();
    for primitive in scene.primitives() {
        let scene_sim::Shape::Polygon(p) = &primitive.shape else { continue };
        let holes: Vec<&[Point2]> = p.holes().collect();
        let direct = Polygon::new(p.outline().to_vec(), holes.iter().map(|h| h.to_vec()).collect());
        let polygon = direct.or_else(|e| {
            let (ring, inner) = notched(p.outline(), &holes).ok_or(e.clone())?;
            Polygon::new(ring, inner)
        });
        match polygon.and_then(|poly| PlanarPatch::new(poly, *p.world_from_patch())) {
            Ok(patch) => patches.push(patch.into()),
            Err(e) => eprintln!("office: skipped {}: {e}", primitive.name),
        }
    }
    let b = scene.bounds();
    let inside = Aabb::new(Point3::new(b.min.x, b.min.y, 0.2), Point3::new(b.max.x, b.max.y, 2.3));
    let steps = steps(&mut Rng(0x0ff1_ce00_2010_0002), &inside);
    Scene { name: "office", patches, steps }
}

/// Prints what a scene holds and how many of its steps collide (throughput depends on it).
fn describe(scene: &Scene) {
    let map = TrimeshMap::from_patches(scene.patches.clone()).expect("scene patches");
    let colliding: Vec<String> = scene
        .steps
        .iter()
        .map(|(length, steps)| {
            let capsules = steps.iter().filter(|s| !map.is_step_free(*s)).count();
            let lines = steps.iter().filter(|s| !map.is_step_free(&s.line())).count();
            format!("{length} m: {capsules}/{} capsules, {lines} lines", steps.len())
        })
        .collect();
    eprintln!(
        "scene {}: {} patches, {} triangles; colliding steps {}",
        scene.name,
        scene.patches.len(),
        map.num_triangles(),
        colliding.join("; ")
    );
}

fn all(c: &mut Criterion) {
    // 3000 and 30,000 patches at the same density (the side grows with the square root).
    let scenes = [
        random_scene("random", 3000, 60.0),
        random_scene("random-30k", 30_000, 60.0 * (10.0 as Real).sqrt()),
        office_scene(),
    ];
    for scene in scenes {
        describe(&scene);
        backends(c, &scene);
    }
}

/// The criterion group (its generated function has no doc comment of its own).
#[allow(missing_docs)]
mod group {
    criterion::criterion_group!(benches, super::all);
}

criterion_main!(group::benches);
