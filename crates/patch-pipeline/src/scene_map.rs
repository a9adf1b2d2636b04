//! The thesis's four map types (§6.1, L6692–6700) built from a simulated scene, so the lab
//! experiments (`patchnav experiment lab-timing`, `lab-volume`) have their maps:
//!
//! | kind | thesis (Lab dataset, 29 ALRF scans) | here (a `scene-sim` scene) |
//! |---|---|---|
//! | `planes` | planar patches extracted from the scans; the non-planar remainder dropped | every planar surface as a [`PlanarPatch`] (polygons with their holes, the six faces of each box, cylinder caps as regular polygons); spheres and cylinder sides dropped |
//! | `hybrid` | planes + the remainder clouds as trimesh patches | `planes` + each curved surface (sphere, cylinder side) as one tessellated [`TrimeshPatch`] |
//! | `trimesh` | every scan triangulated by naive trimesh growing (Alg. 4/5) | every surface triangulated (constrained Delaunay for planar ones) and split until no edge is longer than [`Tessellation::mesh_edge`], one [`TrimeshPatch`] per surface |
//! | `pc` | the raw registered clouds | simulated full-resolution ALRF scans (SICK S300, 541 × 361 beams) from [`Scene::scan_poses`], in the world frame |
//!
//! **Not the thesis's pipeline.** The thesis built planes, hybrid and trimesh maps by patch
//! extraction from the scans (plane segmentation, α-shapes, Douglas–Peucker, trimesh growing);
//! that is separate, later work. Here they come from the scene's exact geometry, so the
//! planes map is what a perfect extraction would give, and the trimesh map's triangle size
//! stands in for the scan grid of naive trimesh growing (default 0.1 m: the thesis's Lab
//! trimesh map has 65× the triangles of its planes map, Table 6.1). Only the `pc` map is
//! made from (simulated) range data, with the sensor's noise.
//!
//! Curved surfaces are tessellated with vertices on the surface (inscribed), so a mesh lies
//! up to `r·(1 − cos(π/n))` inside the true surface for `n` segments around.

use anyhow::{Context, Result, bail};
use patch_core::{FromPatches, Isometry3, Patch, PlanarPatch, Point2, Point3, Real, TrimeshPatch};
use patch_extract::denoise::{BeamDenoiseConfig, denoise_along_beams};
use patch_extract::projection::{AlrfSideColumns, invalidate_alrf_side_columns};
use patch_extract::{
    FreeSpace, MixedPixelConfig, MixedPixelFix, PipelineConfig, TrimeshGrowConfig,
    VisibilityConfig, extract, fix_mixed_pixels, grow_trimeshes,
};
use patch_map::triangulate::triangulate_polygon;
use patch_map::{AnyMap, Backend, PointCloudMap, PolygonMap};
use pointcloud::{BeamModel, PointCloud};
use scene_sim::{Alrf, AlrfConfig, RangeSensor, Scene};
use std::borrow::Cow;
use std::collections::HashMap;

use crate::names::named_enum;

named_enum! {
    /// The map types of the thesis's Table 6.1, in its order of discussion.
    pub enum MapKind ("map kind") {
        /// Planar patches only.
        Planes = "planes", "Planar patches only";
        /// Planar patches plus the curved surfaces as trimesh patches.
        Hybrid = "hybrid", "Planar patches plus the curved surfaces as trimesh patches";
        /// Every surface as a fine triangle mesh.
        Trimesh = "trimesh", "Every surface as a fine triangle mesh";
        /// Simulated ALRF scans as a point-cloud map.
        Pc = "pc", "Simulated ALRF scans as a point-cloud map";
    }
}

/// How curved and meshed surfaces are triangulated. No `Default`: see [`Tessellation::lab`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Tessellation {
    /// Longest edge of the tessellation of curved surfaces (spheres, cylinder sides, and the
    /// regular polygons standing in for cylinder caps), metres.
    pub curved_edge: Real,
    /// Fewest segments around a sphere or cylinder (and vertices of a cap polygon).
    pub min_segments: usize,
    /// Longest triangle edge of the `trimesh` map, metres: every triangle of every surface is
    /// split at its longest edge until no edge is longer.
    pub mesh_edge: Real,
    /// Most triangles in one trimesh patch of the `trimesh` map: a surface's mesh is cut into
    /// spatially compact pieces of at most this many triangles, so backends with a per-patch
    /// broad phase (bbox6d, rapier, polygon) keep one (the thesis's Lab trimesh map averages
    /// 5,600,612 / 17,273 ≈ 324 triangles per patch, Table 6.1).
    pub max_patch_triangles: usize,
}

impl Tessellation {
    /// This command's choice for the lab: 0.1 m curved edges (the barrel gets 19 segments,
    /// table legs 8), at least 8 segments, 0.1 m triangles in the trimesh map (a few hundred
    /// thousand triangles; the thesis's naive trimesh growing made triangles at scan-grid size).
    pub fn lab() -> Tessellation {
        Tessellation { curved_edge: 0.1, min_segments: 8, mesh_edge: 0.1, max_patch_triangles: 324 }
    }

    fn check(&self) -> Result<()> {
        for (what, v) in [("curved edge", self.curved_edge), ("mesh edge", self.mesh_edge)] {
            if !(v.is_finite() && v > 0.0) {
                bail!("the {what} must be a positive number of metres, got {v}");
            }
        }
        if self.max_patch_triangles == 0 {
            bail!("a trimesh patch needs room for at least one triangle");
        }
        if self.min_segments < 3 {
            bail!("at least 3 segments are needed, got {}", self.min_segments);
        }
        Ok(())
    }

    /// The tessellation of curved surfaces (`curved_edge`, `min_segments`) as
    /// [`scene_sim::patches`] takes it.
    fn curved(&self) -> scene_sim::patches::Tessellation {
        scene_sim::patches::Tessellation {
            curved_edge: self.curved_edge,
            min_segments: self.min_segments,
        }
    }
}

/// How the `pc` map is scanned. No `Default`: the experiments set every field.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ScanSetup {
    /// Number of scan poses ([`Scene::scan_poses`]).
    pub scans: usize,
    /// Sensor height above the floor, metres.
    pub height: Real,
    /// Angular step of the ALRF in degrees; `None`: the S300's 0.5°.
    pub step_deg: Option<Real>,
    /// Seed of the poses and the sensor noise.
    pub seed: u64,
    /// Multiplier of the sensor's range noise σ (1: the S300 model's 3 cm; 2: twice that;
    /// 0: noise-free, and then no mixed pixels either).
    pub noise: Real,
}

/// A scene's surfaces, split into planar patches and tessellated curved surfaces.
#[derive(Clone, Debug)]
pub struct SceneSurfaces {
    /// Every planar surface.
    pub planar: Vec<PlanarPatch>,
    /// Every curved surface (sphere, cylinder side), tessellated.
    pub curved: Vec<TrimeshPatch>,
}

impl SceneSurfaces {
    /// The surfaces of `scene`.
    ///
    /// # Errors
    /// A polygon that is not a valid patch polygon (after turning holes that touch the
    /// outline's bottom or top edge into notches), or a bad tessellation.
    pub fn of(scene: &Scene, t: &Tessellation) -> Result<SceneSurfaces> {
        t.check()?;
        let patches = scene_sim::patches::scene_patches(scene, &t.curved())
            .with_context(|| format!("the surfaces of scene `{}`", scene.name()))?;
        let mut planar = Vec::new();
        let mut curved = Vec::new();
        for patch in patches {
            match patch {
                Patch::Planar(p) => planar.push(p),
                Patch::Trimesh(m) => curved.push(m),
            }
        }
        Ok(SceneSurfaces { planar, curved })
    }

    /// The patches of a map kind (`None` for [`MapKind::Pc`], which has points).
    ///
    /// # Errors
    /// A triangulation failure in the `trimesh` map.
    pub fn patches(&self, kind: MapKind, t: &Tessellation) -> Result<Option<Vec<Patch>>> {
        let planes = || self.planar.iter().cloned().map(Patch::from);
        Ok(Some(match kind {
            MapKind::Planes => planes().collect(),
            MapKind::Hybrid => {
                planes().chain(self.curved.iter().cloned().map(Patch::from)).collect()
            }
            MapKind::Trimesh => {
                let mut out = Vec::with_capacity(self.planar.len() + self.curved.len());
                let meshes = self.planar.iter().map(planar_triangles).chain(
                    self.curved.iter().map(|m| Ok((m.vertices().to_vec(), m.triangles().to_vec()))),
                );
                for mesh in meshes {
                    let (v, tri) = mesh?;
                    let (v, tri) = subdivided(v, tri, t.mesh_edge)?;
                    out.extend(
                        chunked(&v, &tri, t.max_patch_triangles)?.into_iter().map(Patch::from),
                    );
                }
                out
            }
            MapKind::Pc => return Ok(None),
        }))
    }
}

/// A built map with what it holds: one row of our Table 6.1 analogue.
#[derive(Debug)]
pub struct BuiltMap {
    /// The map type.
    pub kind: MapKind,
    /// The map in its backend.
    pub map: AnyMap,
    /// Planar patches.
    pub planar_patches: usize,
    /// Trimesh patches.
    pub trimesh_patches: usize,
    /// Triangles: of the trimesh patches plus the constrained Delaunay triangulation of the
    /// planar patches (as the thesis counts the triangles its Bullet maps hold).
    pub triangles: usize,
    /// Scans (point clouds) in a `pc` map.
    pub point_clouds: usize,
    /// Points in a `pc` map.
    pub points: usize,
}

impl BuiltMap {
    /// Heap bytes of the map in its backend ([`patch_map::MemoryUsage`]).
    pub fn memory_bytes(&self) -> usize {
        self.map.memory_bytes()
    }
}

/// Builds the map of `kind` for `scene`: patch maps in `backend` (a patch backend), the `pc` map
/// (always a [`PointCloudMap`]: thesis §6.1, Algorithm 10) from `scans` cleaned as `pc` says.
///
/// # Errors
/// As [`SceneSurfaces::of`], a backend refusing the patches or points, or no scan pose found.
#[allow(clippy::too_many_arguments)]
pub fn build_map(
    scene: &Scene,
    surfaces: &SceneSurfaces,
    kind: MapKind,
    backend: Backend,
    t: &Tessellation,
    scans: &ScanSetup,
    source: MapSource,
    pc: &PcCleaning,
) -> Result<BuiltMap> {
    // Scanned once, for extraction and for the pc map alike.
    let clouds = if source == MapSource::Scans || kind == MapKind::Pc {
        scan_clouds(scene, scans)?
    } else {
        Vec::new()
    };
    let patches = match source {
        MapSource::Scene => surfaces.patches(kind, t)?,
        MapSource::Scans => extracted_patches(&clouds, kind)?,
    };
    let Some(patches) = patches else {
        let points = pc_points(&clouds, pc)?;
        let map = AnyMap::PointCloud(PointCloudMap::from_points(&points)?);
        return Ok(BuiltMap {
            kind,
            map,
            planar_patches: 0,
            trimesh_patches: 0,
            triangles: 0,
            point_clouds: scans.scans,
            points: points.len(),
        });
    };
    let mut built = BuiltMap {
        kind,
        map: AnyMap::Polygon(PolygonMap::from_patches(Vec::new())?),
        planar_patches: 0,
        trimesh_patches: 0,
        triangles: 0,
        point_clouds: 0,
        points: 0,
    };
    for p in &patches {
        match p {
            Patch::Planar(p) => {
                built.planar_patches += 1;
                built.triangles += planar_triangles(p)?.1.len();
            }
            Patch::Trimesh(m) => {
                built.trimesh_patches += 1;
                built.triangles += m.num_triangles();
            }
        }
    }
    built.map = patch_map(patches, backend)?;
    Ok(built)
}

/// Loads `patches` into `backend`, a patch backend ([`Backend::holds_patches`]; the
/// point-cloud backend is [`patch_map::AnyMapError::NeedsSpacing`]).
pub fn patch_map(patches: Vec<Patch>, backend: Backend) -> Result<AnyMap> {
    Ok(AnyMap::from_patches(backend, patches, None)?)
}

/// How a pc map is made from organised scans. `Default`: nothing, the raw points (the
/// occlusion floor of `patchnav map compare`).
#[derive(Clone, Debug, Default)]
pub struct PcCleaning {
    /// Find mixed pixels with this configuration, then remove or snap them.
    pub mixed_pixels: Option<(MixedPixelConfig, MixedPixelFix)>,
    /// Then move locally planar points along their beams onto their neighbourhood's plane.
    pub denoise: Option<BeamDenoiseConfig>,
    /// Last, drop the points another scan saw through ([`FreeSpace`]), every scan's cleaned
    /// points standing for its beams.
    pub carve: Option<VisibilityConfig>,
}

/// The points of a pc map made from `clouds` (sensor frame with poses), cleaned as `cleaning`
/// says, moved to the world frame. Unorganised clouds skip the mixed-pixel fix and the
/// denoising (both need the grid); carving tests all their points.
///
/// # Errors
/// The filter, the denoising or the carving refusing its parameters or a pose.
pub fn pc_points(clouds: &[PointCloud], cleaning: &PcCleaning) -> Result<Vec<Point3>> {
    // Clouds are copied only when a step changes them.
    let mut cleaned: Vec<Cow<'_, PointCloud>> = Vec::with_capacity(clouds.len());
    for cloud in clouds {
        let mut cloud = Cow::Borrowed(cloud);
        if cloud.grid().is_some() {
            if let Some((config, fix)) = &cleaning.mixed_pixels {
                cloud = Cow::Owned(fix_mixed_pixels(&cloud, config, *fix)?.0);
            }
            if let Some(d) = &cleaning.denoise {
                cloud = Cow::Owned(denoise_along_beams(&cloud, d)?.0);
            }
        }
        cleaned.push(cloud);
    }
    if let Some(config) = &cleaning.carve {
        let clouds: Vec<PointCloud> = cleaned.into_iter().map(Cow::into_owned).collect();
        let carved = FreeSpace::new(&clouds, config)?.carve_clouds(&clouds)?.0;
        cleaned = carved.into_iter().map(Cow::Owned).collect();
    }
    let mut out = Vec::with_capacity(cleaned.iter().map(|c| c.len()).sum());
    for cloud in &cleaned {
        out.extend_from_slice(cloud.to_world().positions());
    }
    Ok(out)
}

/// Simulated ALRF scans of `scene` from [`Scene::scan_poses`]: organised clouds in the sensor
/// frame with their poses, the ±90° columns dropped (thesis App. A) — the input of patch
/// extraction.
///
/// # Errors
/// A bad angular step, or fewer poses than asked for.
pub fn scan_clouds(scene: &Scene, setup: &ScanSetup) -> Result<Vec<PointCloud>> {
    simulated_scans(scene, setup, None)
}

/// [`scan_clouds`] without the phantoms: the pixels the simulator blended across a depth edge
/// (its mixed pixels) whose range is more than `tolerance` metres off their own surface's. The
/// pc map a perfect mixed-pixel filter would give: a reference for the real one
/// (`patchnav experiment map-safety`), not a pipeline input.
///
/// # Errors
/// As [`scan_clouds`].
pub fn scan_clouds_without_phantoms(
    scene: &Scene,
    setup: &ScanSetup,
    tolerance: Real,
) -> Result<Vec<PointCloud>> {
    simulated_scans(scene, setup, Some(tolerance))
}

fn simulated_scans(
    scene: &Scene,
    setup: &ScanSetup,
    phantom_tolerance: Option<Real>,
) -> Result<Vec<PointCloud>> {
    let mut config = match setup.step_deg {
        None => AlrfConfig::sick_s300(),
        Some(step) => AlrfConfig::sick_s300_with_step(step.to_radians())
            .with_context(|| format!("ALRF step {step}°"))?,
    };
    if !(setup.noise.is_finite() && (0.0..=100.0).contains(&setup.noise)) {
        bail!("the noise multiplier must be in [0, 100], got {}", setup.noise);
    }
    config.range_sigma *= setup.noise;
    if setup.noise == 0.0 {
        config.mixed_pixels = None;
    }
    let alrf = Alrf::new(config)?;
    let bodies = scene.scan_poses(setup.scans, setup.height, setup.seed);
    if bodies.len() < setup.scans {
        bail!(
            "scene `{}` has room for only {} scan poses at height {} m",
            scene.name(),
            bodies.len(),
            setup.height
        );
    }
    bodies
        .iter()
        .enumerate()
        .map(|(i, body)| {
            let seed = scene_sim::sensors::derive_seed(setup.seed, i as u64);
            let scan = alrf.scan(scene, &alrf.mount(body), seed);
            let mut cloud = scan.to_cloud().context("building a scan's cloud")?;
            if let (Some(tol), Some(grid)) = (phantom_tolerance, cloud.grid()) {
                let ranges = scan.image.ranges();
                let mut phantom = vec![false; cloud.len()];
                for (k, &i) in grid.pixels().iter().enumerate() {
                    if i != pointcloud::INVALID_PIXEL
                        && scan.truth.mixed_pixel[k]
                        && let (Some(r), Some(t)) = (ranges[k], scan.truth.true_range[k])
                    {
                        phantom[i as usize] = (Real::from(r) - Real::from(t)).abs() > tol;
                    }
                }
                cloud = cloud.retain_indices(|i| !phantom[i]);
            }
            Ok(match scan.image.beams() {
                BeamModel::ActuatedLrf(model) => {
                    invalidate_alrf_side_columns(&cloud, model, &AlrfSideColumns::thesis())?.0
                }
                _ => cloud,
            })
        })
        .collect()
}

/// The scene's exact surfaces as patches (its hybrid map): the truth that maps built from
/// scans are compared with ([`patch_map::compare`]).
///
/// # Errors
/// As [`SceneSurfaces::of`].
pub fn truth_patches(scene: &Scene) -> Result<Vec<Patch>> {
    let t = Tessellation::lab();
    SceneSurfaces::of(scene, &t)?
        .patches(MapKind::Hybrid, &t)?
        .context("the exact hybrid map has patches")
}

named_enum! {
    /// Where the patches of the planes, hybrid and trimesh maps come from.
    pub enum MapSource ("map source") {
        /// The scene's exact geometry.
        Scene = "scene", "The scene's exact geometry";
        /// Patch extraction from the simulated ALRF scans, as the thesis built its maps (§6.1):
        /// planes = planar patches merged across scans, hybrid = planes + trimesh patches grown
        /// on each scan's remainder, trimesh = whole scans meshed by trimesh growing
        /// (Algorithms 4, 5).
        Scans = "scans",
            "Patch extraction from the simulated ALRF scans, as the thesis built its maps (§6.1)";
    }
}

/// The patches of map type `kind` extracted from `clouds` (see [`MapSource::Scans`]); `None`
/// for the pc map.
pub fn extracted_patches(clouds: &[PointCloud], kind: MapKind) -> Result<Option<Vec<Patch>>> {
    extracted_patches_with(clouds, kind, PipelineConfig::alrf(), TrimeshGrowConfig::alrf(), None)
}

/// [`extracted_patches`] with the extraction thresholds `pipeline` and the trimesh growing
/// `grow` of another sensor preset (`patchnav extract --sensor`); the trimesh map's triangles
/// that another scan saw through are dropped as `trimesh_carve` says (`None`: all kept; the
/// hybrid map's remainder meshes follow [`PipelineConfig::carve`]).
pub fn extracted_patches_with(
    clouds: &[PointCloud],
    kind: MapKind,
    pipeline: PipelineConfig,
    grow: TrimeshGrowConfig,
    trimesh_carve: Option<VisibilityConfig>,
) -> Result<Option<Vec<Patch>>> {
    Ok(match kind {
        MapKind::Planes => Some(extract(clouds, &pipeline, |_| {})?.into_map_patches()),
        MapKind::Hybrid => {
            Some(extract(clouds, &pipeline.with_remainder(grow), |_| {})?.into_map_patches())
        }
        MapKind::Trimesh => {
            let space = match &trimesh_carve {
                Some(config) => Some(FreeSpace::new(clouds, config)?),
                None => None,
            };
            let mut patches = Vec::new();
            for (index, cloud) in clouds.iter().enumerate() {
                let motion = cloud
                    .sensor_pose()
                    .map_or_else(Isometry3::identity, |pose| pose.world_from_sensor);
                let denoised;
                let cloud = match (&pipeline.denoise, cloud.grid()) {
                    (Some(d), Some(_)) => {
                        denoised = denoise_along_beams(cloud, d)?.0;
                        &denoised
                    }
                    _ => cloud,
                };
                let grown: Vec<_> = grow_trimeshes(cloud, &grow)?
                    .into_patches()
                    .into_iter()
                    .map(|mesh| mesh.transformed(&motion))
                    .collect();
                let grown = match &space {
                    Some(space) => space.carve_trimeshes(&grown, Some(index)).0,
                    None => grown,
                };
                patches.extend(grown.into_iter().map(Patch::Trimesh));
            }
            Some(patches)
        }
        MapKind::Pc => None,
    })
}

/// The constrained Delaunay triangulation of a planar patch, in the world.
pub fn planar_triangles(p: &PlanarPatch) -> Result<(Vec<Point3>, Vec<[u32; 3]>)> {
    let rings: Vec<Vec<[f64; 2]>> =
        p.polygon().rings().map(|r| r.points().iter().map(|q| [q.x, q.y]).collect()).collect();
    let t = triangulate_polygon(&rings)?;
    let vertices = t.vertices.iter().map(|&[x, y]| p.to_world(&Point2::new(x, y))).collect();
    Ok((vertices, t.triangles))
}

/// Most triangles one surface may be split into (a guard against a tiny `mesh_edge`).
const MAX_TRIANGLES_PER_SURFACE: usize = 20_000_000;

/// The mesh with every triangle split at the midpoint of its longest edge until no edge is
/// longer than `max_edge` (midpoints shared by the triangles on both sides of an edge). The
/// triangles come out depth first, so consecutive ones lie close together.
fn subdivided(
    mut vertices: Vec<Point3>,
    triangles: Vec<[u32; 3]>,
    max_edge: Real,
) -> Result<(Vec<Point3>, Vec<[u32; 3]>)> {
    let key = |p: &Point3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let mut index: HashMap<[u64; 3], u32> =
        vertices.iter().enumerate().map(|(i, p)| (key(p), i as u32)).collect();
    let mut stack = triangles;
    let mut out = Vec::new();
    let limit = max_edge * max_edge;
    while let Some(t) = stack.pop() {
        let p = t.map(|i| vertices[i as usize]);
        let len = |e: usize| (p[(e + 1) % 3] - p[e]).norm_squared();
        let e = (0..3).max_by(|&a, &b| len(a).total_cmp(&len(b))).unwrap_or(0);
        if len(e) <= limit {
            out.push(t);
            if out.len() > MAX_TRIANGLES_PER_SURFACE {
                bail!("a surface needs more than {MAX_TRIANGLES_PER_SURFACE} triangles");
            }
            continue;
        }
        let (a, b, c) = (t[e], t[(e + 1) % 3], t[(e + 2) % 3]);
        let m = Point3::from((p[e].coords + p[(e + 1) % 3].coords) * 0.5);
        let mi = *index.entry(key(&m)).or_insert_with(|| {
            vertices.push(m);
            (vertices.len() - 1) as u32
        });
        stack.push([a, mi, c]);
        stack.push([mi, b, c]);
    }
    Ok((vertices, out))
}

/// The mesh cut into patches of at most `max` consecutive triangles, each with its own
/// vertices.
fn chunked(vertices: &[Point3], triangles: &[[u32; 3]], max: usize) -> Result<Vec<TrimeshPatch>> {
    let patches = triangles.chunks(max.max(1)).map(|chunk| {
        let mut local: HashMap<u32, u32> = HashMap::new();
        let mut v = Vec::new();
        let t: Vec<[u32; 3]> = chunk
            .iter()
            .map(|tri| {
                tri.map(|i| {
                    *local.entry(i).or_insert_with(|| {
                        v.push(vertices[i as usize]);
                        (v.len() - 1) as u32
                    })
                })
            })
            .collect();
        TrimeshPatch::new(v, t)
    });
    Ok(patches.collect::<Result<_, _>>()?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use patch_core::Vector3;
    use scene_sim::{Cuboid, Cylinder, Material, SceneBuilder, Shape, Sphere};

    fn one_box() -> Scene {
        let mut b = SceneBuilder::new("one box");
        let c = Cuboid::new(
            Isometry3::new(Vector3::new(1.0, 2.0, 0.5), Vector3::new(0.1, 0.2, 0.7)),
            Vector3::new(0.5, 1.0, 1.5),
        )
        .unwrap();
        b.add("box", c, Material::WOOD).unwrap();
        b.build().unwrap()
    }

    fn area(patches: &[Patch]) -> Real {
        patches.iter().map(Patch::area).sum()
    }

    #[test]
    fn planes_of_one_box_are_its_six_faces() {
        let t = Tessellation::lab();
        let s = SceneSurfaces::of(&one_box(), &t).unwrap();
        let planes = s.patches(MapKind::Planes, &t).unwrap().unwrap();
        assert_eq!(planes.len(), 6);
        assert!(planes.iter().all(|p| p.as_planar().is_some()));
        // 2·(1·2 + 1·3 + 2·3) = 22 m².
        assert!((area(&planes) - 22.0).abs() < 1e-9, "{}", area(&planes));
        // Each face's normal points away from the box centre.
        let centre = Point3::new(1.0, 2.0, 0.5);
        for p in &planes {
            let p = p.as_planar().unwrap();
            let on = p.to_world(&p.polygon().outer().points()[0]);
            assert!(p.normal().dot(&(on - centre)) > 0.0);
        }
    }

    #[test]
    fn hybrid_contains_planes_and_trimesh_covers_the_same_area() {
        let mut b = SceneBuilder::new("mixed");
        b.add("floor", one_box().primitives()[0].shape.clone(), Material::WOOD).unwrap();
        b.add("ball", Sphere::new(Point3::new(4.0, 0.0, 1.0), 0.5).unwrap(), Material::WOOD)
            .unwrap();
        let cyl = Cylinder::upright(Point3::new(-3.0, 0.0, 0.0), 0.3, 1.0).unwrap();
        b.add("barrel", cyl, Material::WOOD).unwrap();
        let scene = b.build().unwrap();
        let t = Tessellation {
            curved_edge: 0.2,
            min_segments: 8,
            mesh_edge: 0.25,
            max_patch_triangles: 50,
        };
        let s = SceneSurfaces::of(&scene, &t).unwrap();
        let planes = s.patches(MapKind::Planes, &t).unwrap().unwrap();
        let hybrid = s.patches(MapKind::Hybrid, &t).unwrap().unwrap();
        let trimesh = s.patches(MapKind::Trimesh, &t).unwrap().unwrap();
        assert_eq!(planes.len(), 6 + 2, "box faces and cylinder caps");
        assert_eq!(hybrid.len(), planes.len() + 2, "plus sphere and cylinder side");
        for p in &planes {
            assert!(hybrid.contains(p), "hybrid ⊇ planes");
        }
        assert!(trimesh.iter().all(|p| p.as_trimesh().is_some()));
        assert!(trimesh.len() > hybrid.len(), "surfaces cut into patches of ≤ 50 triangles");
        let triangles = |p: &Patch| p.as_trimesh().unwrap().num_triangles();
        assert!(trimesh.iter().all(|p| triangles(p) <= 50));
        assert!((area(&trimesh) - area(&hybrid)).abs() < 1e-6 * area(&hybrid));
        for p in &trimesh {
            for [a, b, c] in
                p.as_trimesh().unwrap().triangles().iter().map(|t| t.map(|i| i as usize))
            {
                let v = p.as_trimesh().unwrap().vertices();
                for (x, y) in [(a, b), (b, c), (c, a)] {
                    assert!((v[x] - v[y]).norm() <= 0.25 + 1e-12);
                }
            }
        }
        // The tessellated sphere is inscribed: a little less than 4πr².
        let sphere_area = hybrid.iter().filter_map(Patch::as_trimesh).next().unwrap().area();
        let exact = 4.0 * std::f64::consts::PI * 0.25;
        assert!(sphere_area < exact && sphere_area > 0.9 * exact, "{sphere_area}");
    }

    #[test]
    fn door_touching_the_floor_becomes_a_notch() {
        let lab = scene_sim::lab(0).unwrap();
        let t = Tessellation::lab();
        let s = SceneSurfaces::of(&lab, &t).unwrap();
        let Shape::Polygon(south) =
            &lab.primitives().iter().find(|p| p.name == "wall-south").unwrap().shape
        else {
            panic!("the south wall is a polygon");
        };
        let patch = scene_sim::patches::polygon_patch(south).unwrap();
        assert!((patch.area() - (12.0 * 4.0 - 1.2 * 2.1)).abs() < 1e-9);
        assert!((patch.area() - south.area()).abs() < 1e-9);
        assert!(!s.planar.is_empty() && !s.curved.is_empty());
    }
}
