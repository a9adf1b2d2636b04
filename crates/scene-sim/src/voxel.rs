//! A generated city-like voxel world: a large map of mixed patch sizes for benchmarks.
//!
//! The world is a grid of cubes: a ground slab, blocks of buildings of random heights on a
//! street grid (some with overhangs), and small floating debris cubes. Its surface is the set
//! of exposed cube faces, merged greedily into maximal rectangles per plane and direction
//! (Mikola Lysenko's "greedy meshing"), two triangles each. The merged rectangles range from
//! one voxel face (the debris) to a whole street or façade, so the boxes of the patches have
//! very different sizes, the case that defeats a broad phase over patch boxes.
//!
//! ```
//! use scene_sim::voxel::{VoxelWorld, VoxelWorldConfig};
//! let world = VoxelWorld::generate(&VoxelWorldConfig { size: [24, 24, 8], ..VoxelWorldConfig::city(1) });
//! let mesh = world.mesh();
//! assert!(mesh.num_triangles() > 0);
//! assert!(world.is_free(&world.free_point().unwrap()));
//! ```

use patch_core::{Point3, Real};
use pointcloud::PolygonMesh;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::SceneError;

/// The parameters of [`VoxelWorld::generate`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct VoxelWorldConfig {
    /// Cells along x, y and z; each at least 4 and at most 1024, at most 2²⁸ cells in all.
    pub size: [usize; 3],
    /// Edge length of a cell, metres (finite, positive).
    pub voxel: Real,
    /// Cells from one street to the next along x and y (a block and its street).
    pub block: usize,
    /// Width of a street, cells (less than `block`).
    pub street: usize,
    /// Probability that a building gets an overhang (a floor wider than the one below).
    pub overhang: Real,
    /// Probability that a cell of a building's outer layer (above the ground floor, below
    /// the roof) is a one-cell window recess.
    pub windows: Real,
    /// Floating debris cubes per 1,000 free cells.
    pub debris: Real,
    /// Seed of the heights, overhangs and debris.
    pub seed: u64,
}

impl VoxelWorldConfig {
    /// A city of 192 × 192 × 24 cells of 0.5 m (96 × 96 × 12 m): blocks of 16 cells with
    /// streets of 6, buildings up to 22 cells high, a quarter with overhangs, window recesses
    /// in 35 % of the façade cells, and 3 debris cubes per 1,000 free cells. More than
    /// 100,000 triangles.
    pub fn city(seed: u64) -> VoxelWorldConfig {
        VoxelWorldConfig {
            size: [192, 192, 24],
            voxel: 0.5,
            block: 16,
            street: 6,
            overhang: 0.25,
            windows: 0.35,
            debris: 3.0,
            seed,
        }
    }

    fn validate(&self) -> Result<(), SceneError> {
        let bad = |what: &'static str, value: f64, allowed: &'static str| {
            Err(SceneError::BadParameter { what, value, allowed })
        };
        if let Some(&n) = self.size.iter().find(|&&n| !(4..=1024).contains(&n)) {
            return bad("voxel world side (cells)", n as f64, "4 to 1024");
        }
        let cells = self.size.iter().product::<usize>();
        if cells > 1 << 28 {
            return bad("voxel world cells", cells as f64, "at most 2^28");
        }
        if !(self.voxel.is_finite() && self.voxel > 0.0) {
            return bad("voxel size", self.voxel, "finite and positive");
        }
        if self.street == 0 || self.street >= self.block {
            return bad("street width (cells)", self.street as f64, "1 to the block size − 1");
        }
        if !(0.0..=1.0).contains(&self.overhang) {
            return bad("overhang probability", self.overhang, "[0, 1]");
        }
        if !(0.0..=1.0).contains(&self.windows) {
            return bad("window probability", self.windows, "[0, 1]");
        }
        if !(self.debris.is_finite() && self.debris >= 0.0) {
            return bad("debris density", self.debris, "finite and ≥ 0");
        }
        Ok(())
    }
}

/// A grid of solid and empty cubes; cell `(i, j, k)` spans
/// `[i, i + 1] × [j, j + 1] × [k, k + 1]` times the voxel size, from the origin.
#[derive(Clone, Debug, PartialEq)]
pub struct VoxelWorld {
    size: [usize; 3],
    voxel: Real,
    solid: Vec<bool>,
}

impl VoxelWorld {
    /// Generates the world of `config` (see the module docs); the same config gives the same
    /// world.
    ///
    /// # Errors
    /// [`SceneError::BadParameter`] for a config outside its documented ranges.
    pub fn try_generate(config: &VoxelWorldConfig) -> Result<VoxelWorld, SceneError> {
        config.validate()?;
        let [nx, ny, nz] = config.size;
        let mut world =
            VoxelWorld { size: config.size, voxel: config.voxel, solid: vec![false; nx * ny * nz] };
        let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
        // The ground slab.
        for i in 0..nx {
            for j in 0..ny {
                world.set(i, j, 0);
            }
        }
        // Buildings: one per block, inset from the streets by a random margin.
        let (b, s) = (config.block, config.street);
        for bx in (0..nx).step_by(b) {
            for by in (0..ny).step_by(b) {
                let (x0, y0) = (bx + s, by + s);
                let (x1, y1) = ((bx + b).min(nx), (by + b).min(ny));
                if x0 + 2 > x1 || y0 + 2 > y1 {
                    continue;
                }
                let inset = |rng: &mut ChaCha8Rng, lo: usize, hi: usize| {
                    let m = rng.random_range(0..=((hi - lo) / 4));
                    (lo + m, hi - m)
                };
                let (x0, x1) = inset(&mut rng, x0, x1);
                let (y0, y1) = inset(&mut rng, y0, y1);
                let top = rng.random_range(2..nz.max(3) - 1);
                for i in x0..x1 {
                    for j in y0..y1 {
                        for k in 1..=top {
                            world.set(i, j, k);
                        }
                    }
                }
                // Window recesses in the outer layer.
                for k in 2..top {
                    for i in x0..x1 {
                        for j in y0..y1 {
                            let outer = i == x0 || i + 1 == x1 || j == y0 || j + 1 == y1;
                            if outer && rng.random_bool(config.windows) {
                                let n = world.index(i, j, k);
                                world.solid[n] = false;
                            }
                        }
                    }
                }
                // An overhang: one floor reaching over the street on one side.
                if top > 4 && rng.random_bool(config.overhang) {
                    let k = rng.random_range(3..top);
                    let reach = (s / 2).max(1);
                    let (ox0, ox1) = (x0.saturating_sub(reach), (x1 + reach).min(nx));
                    for i in ox0..ox1 {
                        for j in y0..y1 {
                            world.set(i, j, k);
                        }
                    }
                }
            }
        }
        // Debris: single floating cubes in free cells.
        let free = world.solid.iter().filter(|s| !**s).count();
        let count = (config.debris * free as Real / 1000.0).round() as usize;
        for _ in 0..count {
            let (i, j, k) =
                (rng.random_range(0..nx), rng.random_range(0..ny), rng.random_range(2..nz));
            world.set(i, j, k);
        }
        Ok(world)
    }

    /// [`try_generate`](VoxelWorld::try_generate) for a config known to be valid.
    ///
    /// # Panics
    /// If the config is invalid.
    pub fn generate(config: &VoxelWorldConfig) -> VoxelWorld {
        VoxelWorld::try_generate(config).expect("a valid voxel world config")
    }

    fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.size[1] + j) * self.size[0] + i
    }

    fn set(&mut self, i: usize, j: usize, k: usize) {
        let n = self.index(i, j, k);
        self.solid[n] = true;
    }

    /// Whether cell `c` is solid; cells outside the grid are empty.
    pub fn is_solid(&self, c: [i64; 3]) -> bool {
        let inside = (0..3).all(|d| c[d] >= 0 && (c[d] as usize) < self.size[d]);
        inside && self.solid[self.index(c[0] as usize, c[1] as usize, c[2] as usize)]
    }

    /// Cells along x, y and z.
    pub fn size(&self) -> [usize; 3] {
        self.size
    }

    /// The edge length of a cell, metres.
    pub fn voxel(&self) -> Real {
        self.voxel
    }

    /// The world's box: from the origin to `size · voxel`.
    pub fn bounds(&self) -> (Point3, Point3) {
        let [x, y, z] = self.size.map(|n| n as Real * self.voxel);
        (Point3::origin(), Point3::new(x, y, z))
    }

    /// Whether `p` lies in an empty cell (points outside the grid are free).
    pub fn is_free(&self, p: &Point3) -> bool {
        let cell = [p.x, p.y, p.z].map(|c| (c / self.voxel).floor() as i64);
        !self.is_solid(cell)
    }

    /// The centre of an empty cell on the street level with at least one empty cell on every
    /// side (a start for planners), if there is one: [`clear_point_near`] the middle of the
    /// world.
    ///
    /// [`clear_point_near`]: VoxelWorld::clear_point_near
    pub fn free_point(&self) -> Option<Point3> {
        let [nx, ny, _] = self.size;
        self.clear_point_near([nx / 2, ny / 2, 2])
    }

    /// The centre of the cell nearest to `cell` along x (same y and z) that is empty with its
    /// 26 neighbours, if any: a sphere of radius up to one cell fits there.
    pub fn clear_point_near(&self, cell: [usize; 3]) -> Option<Point3> {
        let [i0, j, k] = cell;
        let nx = self.size[0];
        let clear = |i: usize| {
            (-1i64..=1).all(|di| {
                (-1i64..=1).all(|dj| {
                    (-1i64..=1)
                        .all(|dk| !self.is_solid([i as i64 + di, j as i64 + dj, k as i64 + dk]))
                })
            })
        };
        (0..2 * nx)
            .filter_map(|o| {
                if o % 2 == 0 { i0.checked_add(o / 2) } else { i0.checked_sub(o.div_ceil(2)) }
            })
            .filter(|&i| i < nx)
            .find(|&i| clear(i))
            .map(|i| self.centre(i, j, k))
    }

    fn centre(&self, i: usize, j: usize, k: usize) -> Point3 {
        Point3::new(i as Real + 0.5, j as Real + 0.5, k as Real + 0.5) * self.voxel
    }

    /// The exposed faces (between a solid and an empty cell, the outside counting as empty),
    /// merged greedily into maximal rectangles per plane and direction, as quads
    /// `[p0, p1, p2, p3]` counter-clockwise seen from the empty side.
    pub fn rectangles(&self) -> Vec<[Point3; 4]> {
        let mut out = Vec::new();
        for d in 0..3 {
            let (u, v) = ((d + 1) % 3, (d + 2) % 3);
            let (nu, nv) = (self.size[u], self.size[v]);
            let mut mask = vec![0i8; nu * nv];
            for plane in 0..=self.size[d] {
                // +1: the face looks along +d (solid below the plane); −1: along −d.
                for b in 0..nv {
                    for a in 0..nu {
                        let mut c = [0i64; 3];
                        c[u] = a as i64;
                        c[v] = b as i64;
                        c[d] = plane as i64 - 1;
                        let below = self.is_solid(c);
                        c[d] = plane as i64;
                        let above = self.is_solid(c);
                        mask[b * nu + a] = i8::from(below && !above) - i8::from(above && !below);
                    }
                }
                for b in 0..nv {
                    let mut a = 0;
                    while a < nu {
                        let m = mask[b * nu + a];
                        if m == 0 {
                            a += 1;
                            continue;
                        }
                        let mut w = 1;
                        while a + w < nu && mask[b * nu + a + w] == m {
                            w += 1;
                        }
                        let mut h = 1;
                        while b + h < nv && (a..a + w).all(|x| mask[(b + h) * nu + x] == m) {
                            h += 1;
                        }
                        for y in b..b + h {
                            mask[y * nu + a..y * nu + a + w].fill(0);
                        }
                        let corner = |du: usize, dv: usize| {
                            let mut p = [0.0; 3];
                            p[d] = plane as Real * self.voxel;
                            p[u] = (a + du) as Real * self.voxel;
                            p[v] = (b + dv) as Real * self.voxel;
                            Point3::from(p)
                        };
                        let quad = [corner(0, 0), corner(w, 0), corner(w, h), corner(0, h)];
                        // (u, v, d) is right-handed: counter-clockwise in (u, v) looks along +d.
                        out.push(if m > 0 { quad } else { [quad[0], quad[3], quad[2], quad[1]] });
                        a += w;
                    }
                }
            }
        }
        out
    }

    /// The surface as a triangle mesh: each of [`rectangles`](VoxelWorld::rectangles) as two
    /// triangles with its own four vertices.
    pub fn mesh(&self) -> PolygonMesh {
        let rects = self.rectangles();
        let vertices: Vec<Point3> = rects.iter().flatten().copied().collect();
        let faces = (0..rects.len() as u32)
            .flat_map(|r| [vec![4 * r, 4 * r + 1, 4 * r + 2], vec![4 * r, 4 * r + 2, 4 * r + 3]])
            .collect();
        PolygonMesh::new(vertices, faces).expect("indices are in range")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small(seed: u64) -> VoxelWorldConfig {
        VoxelWorldConfig { size: [32, 24, 10], block: 8, street: 3, ..VoxelWorldConfig::city(seed) }
    }

    #[test]
    fn merged_rectangles_cover_exactly_the_exposed_faces() {
        let world = VoxelWorld::generate(&small(3));
        let [nx, ny, nz] = world.size();
        let mut exposed = 0usize;
        for k in -1..=nz as i64 {
            for j in -1..=ny as i64 {
                for i in -1..=nx as i64 {
                    if !world.is_solid([i, j, k]) {
                        continue;
                    }
                    for d in 0..3 {
                        for s in [-1, 1] {
                            let mut c = [i, j, k];
                            c[d] += s;
                            exposed += usize::from(!world.is_solid(c));
                        }
                    }
                }
            }
        }
        let rects = world.rectangles();
        let area: Real = rects.iter().map(|r| (r[1] - r[0]).cross(&(r[3] - r[0])).norm()).sum();
        let face = world.voxel() * world.voxel();
        assert!((area / face - exposed as Real).abs() < 1e-6, "{area} vs {exposed} faces");
        assert!(rects.len() * 3 < exposed, "{} rectangles for {exposed} faces", rects.len());
        // Each rectangle faces empty space: a point just in front of its centre is free, one
        // just behind is solid.
        for r in &rects {
            let n = (r[1] - r[0]).cross(&(r[3] - r[0])).normalize();
            let c = Point3::from((r[0].coords + r[2].coords) / 2.0);
            let off = 0.01 * world.voxel();
            assert!(world.is_free(&(c + n * off)), "{r:?}");
            assert!(!world.is_free(&(c - n * off)), "{r:?}");
        }
        let sizes: Vec<Real> = rects.iter().map(|r| (r[2] - r[0]).norm()).collect();
        let (lo, hi) =
            sizes.iter().fold((Real::MAX, 0.0 as Real), |(a, b), &s| (a.min(s), b.max(s)));
        assert!(hi > 10.0 * lo, "sizes from {lo} to {hi} m");
    }

    #[test]
    fn the_same_seed_gives_the_same_world_and_the_city_is_large() {
        assert_eq!(VoxelWorld::generate(&small(5)), VoxelWorld::generate(&small(5)));
        assert_ne!(VoxelWorld::generate(&small(5)), VoxelWorld::generate(&small(6)));
        let city = VoxelWorld::generate(&VoxelWorldConfig::city(1));
        let triangles = city.mesh().num_triangles();
        assert!(triangles >= 100_000, "{triangles} triangles");
        println!("city: {triangles} triangles");
        let start = city.free_point().unwrap();
        assert!(city.is_free(&start));
    }

    #[test]
    fn bad_configs_are_errors() {
        let base = small(1);
        for bad in [
            VoxelWorldConfig { size: [2, 8, 8], ..base },
            VoxelWorldConfig { size: [1024, 1024, 1024], ..base },
            VoxelWorldConfig { voxel: Real::NAN, ..base },
            VoxelWorldConfig { voxel: 0.0, ..base },
            VoxelWorldConfig { street: 8, ..base },
            VoxelWorldConfig { street: 0, ..base },
            VoxelWorldConfig { overhang: 1.5, ..base },
            VoxelWorldConfig { windows: Real::NAN, ..base },
            VoxelWorldConfig { debris: -1.0, ..base },
        ] {
            assert!(
                matches!(VoxelWorld::try_generate(&bad), Err(SceneError::BadParameter { .. })),
                "{bad:?}"
            );
        }
    }
}
