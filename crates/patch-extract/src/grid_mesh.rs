//! Regions of a range image and the naive range-image triangulation (thesis L4913–4915).
//!
//! # Grid conventions (shared by [`crate::scanline`], [`crate::chain_code`] and
//! [`crate::trimesh_grow`])
//! * A pixel is `(col, row)`, row 0 at the top (as [`pointcloud::Grid`]).
//! * In pixel space, **pixel centres are the vertices**: pixel `(c, r)` is the point `(c, r)`,
//!   and its 3D position is the cloud point the grid names. Pixel squares (for chain-code
//!   outlines) are `[c − ½, c + ½] × [r − ½, r + ½]`.
//! * A region is a [`RegionMask`]: one flag per pixel. Only pixels that are both in the mask and
//!   valid in the grid take part.

use crate::quality::MeshStats;
use patch_core::Point3;
use pointcloud::{Grid, PointCloud};

/// Why a grid method refused its input.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum GridError {
    /// The cloud is not organised (has no [`Grid`]).
    #[error("the cloud has no grid (it is not organised)")]
    NoGrid,
    /// The mask does not have one flag per grid pixel.
    #[error("mask has {mask} flags, the grid has {pixels} pixels")]
    MaskSize {
        /// Flags in the mask.
        mask: usize,
        /// Pixels in the grid.
        pixels: usize,
    },
}

/// A set of pixels of a `width × height` image, row-major.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RegionMask {
    width: u32,
    height: u32,
    flags: Vec<bool>,
}

impl RegionMask {
    /// The mask from per-pixel flags (row-major, `width × height` of them).
    ///
    /// # Errors
    /// [`GridError::MaskSize`] if the length is wrong.
    pub fn new(width: u32, height: u32, flags: Vec<bool>) -> Result<RegionMask, GridError> {
        let pixels = width as usize * height as usize;
        if flags.len() != pixels {
            return Err(GridError::MaskSize { mask: flags.len(), pixels });
        }
        Ok(RegionMask { width, height, flags })
    }

    /// Every valid pixel of the grid.
    pub fn all_valid(grid: &Grid) -> RegionMask {
        let flags = grid.pixels().iter().map(|&p| p != pointcloud::INVALID_PIXEL).collect();
        RegionMask { width: grid.width(), height: grid.height(), flags }
    }

    /// The pixels of the given points (indices into the cloud the grid belongs to), e.g. a
    /// [`crate::PlanarRegion`]'s `points` or a segmentation's remainder.
    pub fn from_points(grid: &Grid, points: &[u32]) -> RegionMask {
        let mut in_set = vec![false; grid.num_valid()];
        for &p in points {
            if let Some(slot) = in_set.get_mut(p as usize) {
                *slot = true;
            }
        }
        let flags = grid
            .pixels()
            .iter()
            .map(|&p| p != pointcloud::INVALID_PIXEL && in_set.get(p as usize) == Some(&true))
            .collect();
        RegionMask { width: grid.width(), height: grid.height(), flags }
    }

    /// The pixels whose point carries `label` (e.g. the scene-sim surface id).
    /// Empty if the cloud has no labels.
    pub fn from_label(cloud: &PointCloud, grid: &Grid, label: u32) -> RegionMask {
        let labels = cloud.labels();
        let flags = grid
            .pixels()
            .iter()
            .map(|&p| {
                p != pointcloud::INVALID_PIXEL
                    && labels.and_then(|l| l.get(p as usize)) == Some(&label)
            })
            .collect();
        RegionMask { width: grid.width(), height: grid.height(), flags }
    }

    /// Image width.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The flags, row-major.
    pub fn flags(&self) -> &[bool] {
        &self.flags
    }

    /// Whether pixel `(col, row)` is in the mask (false outside the image).
    pub fn contains(&self, col: i64, row: i64) -> bool {
        col >= 0
            && row >= 0
            && col < self.width as i64
            && row < self.height as i64
            && self.flags[row as usize * self.width as usize + col as usize]
    }

    /// The number of pixels in the mask.
    pub fn count(&self) -> usize {
        self.flags.iter().filter(|&&f| f).count()
    }

    /// The mask restricted to pixels that are valid in `grid`.
    ///
    /// # Errors
    /// [`GridError::MaskSize`] if the sizes differ.
    pub fn restricted_to(&self, grid: &Grid) -> Result<RegionMask, GridError> {
        if grid.width() != self.width || grid.height() != self.height {
            return Err(GridError::MaskSize { mask: self.flags.len(), pixels: grid.num_pixels() });
        }
        let flags = self
            .flags
            .iter()
            .zip(grid.pixels())
            .map(|(&f, &p)| f && p != pointcloud::INVALID_PIXEL)
            .collect();
        Ok(RegionMask { width: self.width, height: self.height, flags })
    }
}

/// A triangulation whose vertices are pixels of an organised cloud.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GridMesh {
    /// The vertices' 3D positions (the cloud points).
    pub vertices: Vec<Point3>,
    /// The pixel `[col, row]` of each vertex.
    pub pixels: Vec<[u32; 2]>,
    /// Triangles as indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
    /// Counts and spikyness (in 3D).
    pub stats: MeshStats,
}

impl GridMesh {
    /// Area of the triangles in pixel space (pixel centres at integer coordinates).
    pub fn pixel_area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| pixel_triangle_area(t.map(|i| self.pixels[i as usize])).abs())
            .sum()
    }
}

/// Signed area of a triangle of pixel centres (positive when counter-clockwise in `(col, row)`
/// coordinates).
pub fn pixel_triangle_area(t: [[u32; 2]; 3]) -> f64 {
    let [a, b, c] = t.map(|p| [p[0] as f64, p[1] as f64]);
    0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
}

/// Collects mesh vertices keyed by pixel: each pixel gets one vertex, on first use.
pub(crate) struct VertexMap<'a> {
    grid: &'a Grid,
    positions: &'a [Point3],
    index: Vec<u32>,
    pub(crate) vertices: Vec<Point3>,
    pub(crate) pixels: Vec<[u32; 2]>,
}

impl<'a> VertexMap<'a> {
    pub(crate) fn new(cloud: &'a PointCloud, grid: &'a Grid) -> Self {
        VertexMap {
            grid,
            positions: cloud.positions(),
            index: vec![u32::MAX; grid.num_pixels()],
            vertices: Vec::new(),
            pixels: Vec::new(),
        }
    }

    /// The vertex of valid pixel `(col, row)`.
    ///
    /// # Panics
    /// If the pixel is invalid: callers only pass region pixels.
    pub(crate) fn vertex(&mut self, col: u32, row: u32) -> u32 {
        let slot = &mut self.index[row as usize * self.grid.width() as usize + col as usize];
        if *slot == u32::MAX {
            let p = self.grid.point_index(col, row).expect("region pixels are valid");
            *slot = self.vertices.len() as u32;
            self.vertices.push(self.positions[p]);
            self.pixels.push([col, row]);
        }
        *slot
    }

    pub(crate) fn finish(self, triangles: Vec<[u32; 3]>, polygons: usize) -> GridMesh {
        let stats = MeshStats::from_triangles(&self.vertices, &triangles, polygons);
        GridMesh { vertices: self.vertices, pixels: self.pixels, triangles, stats }
    }
}

/// The cloud's grid and the mask restricted to its valid pixels.
pub(crate) fn grid_and_region<'a>(
    cloud: &'a PointCloud,
    mask: &RegionMask,
) -> Result<(&'a Grid, RegionMask), GridError> {
    let grid = cloud.grid().ok_or(GridError::NoGrid)?;
    let region = mask.restricted_to(grid)?;
    Ok((grid, region))
}

/// The naive range-image triangulation of a region (thesis L4913–4915: "join every triplet of
/// neighbouring range-image pixels").
///
/// For every 2×2 square of pixels with top-left pixel `(c, r)`:
/// * all four pixels in the region: two triangles `((c,r),(c,r+1),(c+1,r))` and
///   `((c+1,r),(c,r+1),(c+1,r+1))`, split along the anti-diagonal like the seed triangle of
///   trimesh growing (Alg 4, L4545);
/// * exactly three pixels in the region: the one triangle of those three (a right triangle in
///   pixel space, half the square);
/// * fewer: nothing.
///
/// A full `w × h` region gives `2(w − 1)(h − 1)` triangles. The result has one "polygon" per
/// triangle ([`MeshStats::polygons`] = triangles).
///
/// # Errors
/// [`GridError`] if the cloud is not organised or the mask has the wrong size.
///
/// # Complexity
/// `O(w · h)`.
pub fn naive_triangulation(cloud: &PointCloud, mask: &RegionMask) -> Result<GridMesh, GridError> {
    let (grid, region) = grid_and_region(cloud, mask)?;
    let mut map = VertexMap::new(cloud, grid);
    let mut triangles = Vec::new();
    let (w, h) = (grid.width(), grid.height());
    for r in 0..h.saturating_sub(1) {
        for c in 0..w.saturating_sub(1) {
            let inside = |dc: u32, dr: u32| region.contains((c + dc) as i64, (r + dr) as i64);
            let (a, b, d, e) = (inside(0, 0), inside(1, 0), inside(0, 1), inside(1, 1));
            let corners: [(bool, u32, u32); 4] =
                [(a, c, r), (d, c, r + 1), (e, c + 1, r + 1), (b, c + 1, r)];
            match [a, b, d, e].iter().filter(|&&x| x).count() {
                4 => {
                    let [va, vd, vb, ve] = [
                        map.vertex(c, r),
                        map.vertex(c, r + 1),
                        map.vertex(c + 1, r),
                        map.vertex(c + 1, r + 1),
                    ];
                    triangles.push([va, vd, vb]);
                    triangles.push([vb, vd, ve]);
                }
                3 => {
                    // The three present corners, in counter-clockwise order around the square.
                    let mut t = [0u32; 3];
                    let mut k = 0;
                    for &(present, pc, pr) in &corners {
                        if present {
                            t[k] = map.vertex(pc, pr);
                            k += 1;
                        }
                    }
                    triangles.push(t);
                }
                _ => {}
            }
        }
    }
    let n = triangles.len();
    Ok(map.finish(triangles, n))
}
