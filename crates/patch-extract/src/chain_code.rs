//! Chain-code outlining of range-image regions (thesis §5.3.3, L4831–4837: an indirect method
//! for range cameras; the thesis does not describe it, nor its heuristic for removing
//! self-intersections).
//!
//! # What is traced
//! Tracing boundary *pixels* (Moore-neighbour tracing) gives rings through pixel centres that
//! fold back on themselves along one-pixel-wide parts, which is where the thesis's
//! self-intersection heuristic came in. Here the boundary of the **union of pixel squares** is
//! followed instead (crack following: the Freeman chain code with four directions on the pixel
//! corners, `0 = +col, 1 = +row, 2 = −col, 3 = −row`). Its rings never cross. Two rules make them
//! simple:
//! * **Pinches** (two region pixels touching only at a corner): the tracer turns towards the
//!   region (a right turn in image coordinates), so diagonal neighbours are separated: regions
//!   are 4-connected, the background is 8-connected.
//! * **Self-touching rings** (a 4-connected region whose boundary passes a pinch twice): the
//!   traced closed walk is split at every repeated corner into loops, each of which is simple.
//!   A loop split off an outer boundary is a hole that touches the outer ring in one vertex.
//!
//! Rings keep only their turning corners (collinear corners are dropped). Coordinates follow the
//! pixel-centre convention of [`crate::grid_mesh`]: pixel `(c, r)` is the square
//! `[c − ½, c + ½] × [r − ½, r + ½]`, so ring vertices are half-integers. Outer rings have a
//! positive shoelace area in `(col, row)` coordinates, holes a negative one, and the areas of an
//! outline's rings add up to its pixel count.
//!
//! # Complexity
//! `O(w · h)`.

use crate::grid_mesh::{GridError, RegionMask};
use pointcloud::PointCloud;

/// One closed ring of an outline.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainRing {
    /// The corner the chain code starts at, `[col, row]` of the pixel corner (the top-left corner
    /// of pixel `(c, r)` is `[c, r]`).
    pub start: [i64; 2],
    /// The Freeman crack code: one direction per unit edge (`0 = +col, 1 = +row, 2 = −col,
    /// 3 = −row`).
    pub code: Vec<u8>,
    /// The turning corners in pixel-centre coordinates (`[col − ½, row − ½]` of the corner).
    pub vertices: Vec<[f64; 2]>,
    /// Shoelace area of `vertices` in `(col, row)` coordinates: positive for outer rings,
    /// negative for holes.
    pub signed_area: f64,
}

/// The outline of one 4-connected component of a region: an outer ring and its holes.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainOutline {
    /// The outer ring.
    pub outer: ChainRing,
    /// The holes.
    pub holes: Vec<ChainRing>,
    /// The number of pixels of the component (= the sum of the rings' signed areas).
    pub pixels: usize,
}

impl ChainOutline {
    /// The rings as plain point lists, outer first, as [`patch_core::triangulate`] takes them.
    pub fn rings(&self) -> Vec<Vec<[f64; 2]>> {
        std::iter::once(&self.outer).chain(&self.holes).map(|r| r.vertices.clone()).collect()
    }

    /// The number of ring vertices.
    pub fn num_vertices(&self) -> usize {
        self.outer.vertices.len() + self.holes.iter().map(|h| h.vertices.len()).sum::<usize>()
    }
}

const STEP: [(i64, i64); 4] = [(1, 0), (0, 1), (-1, 0), (0, -1)];

/// Outlines of the region's pixels valid in the cloud's grid.
///
/// # Errors
/// [`GridError`] if the cloud is not organised or the mask has the wrong size.
pub fn chain_code_outlines(
    cloud: &PointCloud,
    mask: &RegionMask,
) -> Result<Vec<ChainOutline>, GridError> {
    let grid = cloud.grid().ok_or(GridError::NoGrid)?;
    Ok(outline_mask(&mask.restricted_to(grid)?))
}

/// 4-connected component labels (`u32::MAX` outside) and the component sizes.
fn components(mask: &RegionMask) -> (Vec<u32>, Vec<usize>) {
    let (w, h) = (mask.width() as i64, mask.height() as i64);
    let mut label = vec![u32::MAX; mask.flags().len()];
    let mut sizes = Vec::new();
    let mut stack = Vec::new();
    for start in 0..label.len() {
        if !mask.flags()[start] || label[start] != u32::MAX {
            continue;
        }
        let id = sizes.len() as u32;
        let mut size = 0;
        label[start] = id;
        stack.push(start);
        while let Some(i) = stack.pop() {
            size += 1;
            let (c, r) = (i as i64 % w, i as i64 / w);
            for (dc, dr) in STEP {
                let (nc, nr) = (c + dc, r + dr);
                if nc >= 0 && nr >= 0 && nc < w && nr < h {
                    let j = (nr * w + nc) as usize;
                    if mask.flags()[j] && label[j] == u32::MAX {
                        label[j] = id;
                        stack.push(j);
                    }
                }
            }
        }
        sizes.push(size);
    }
    (label, sizes)
}

/// Outlines of every 4-connected component of the mask (all its pixels count), ordered by
/// the component's first pixel in raster order.
pub fn outline_mask(mask: &RegionMask) -> Vec<ChainOutline> {
    let (w, h) = (mask.width() as i64, mask.height() as i64);
    let cw = (w + 1) as usize;
    let inside = |c: i64, r: i64| mask.contains(c, r);
    // Outgoing boundary edges per corner, one bit per direction; the region lies to the right
    // of every edge (in image coordinates, row axis pointing down).
    let mut out = vec![0u8; cw * (h + 1) as usize];
    let corner = |x: i64, y: i64| y as usize * cw + x as usize;
    for r in 0..h {
        for c in 0..w {
            if !inside(c, r) {
                continue;
            }
            if !inside(c, r - 1) {
                out[corner(c, r)] |= 1 << 0;
            }
            if !inside(c + 1, r) {
                out[corner(c + 1, r)] |= 1 << 1;
            }
            if !inside(c, r + 1) {
                out[corner(c + 1, r + 1)] |= 1 << 2;
            }
            if !inside(c - 1, r) {
                out[corner(c, r + 1)] |= 1 << 3;
            }
        }
    }
    let (label, sizes) = components(mask);
    // The pixel to the right of an edge leaving corner (x, y) in direction d.
    let pixel_right_of = |x: i64, y: i64, d: u8| -> usize {
        let (c, r) = match d {
            0 => (x, y),
            1 => (x - 1, y),
            2 => (x - 1, y - 1),
            _ => (x, y - 1),
        };
        (r * w + c) as usize
    };

    let mut outers: Vec<Option<ChainRing>> = vec![None; sizes.len()];
    let mut holes: Vec<Vec<ChainRing>> = vec![Vec::new(); sizes.len()];
    let mut visit = vec![u32::MAX; out.len()];
    for y in 0..=h {
        for x in 0..=w {
            while out[corner(x, y)] != 0 {
                let d0 = out[corner(x, y)].trailing_zeros() as u8;
                let comp = label[pixel_right_of(x, y, d0)] as usize;
                // Trace the closed walk, preferring right turns.
                let mut walk = vec![(x, y)];
                let mut code = Vec::new();
                let (mut px, mut py, mut d) = (x, y, d0);
                loop {
                    out[corner(px, py)] &= !(1 << d);
                    code.push(d);
                    px += STEP[d as usize].0;
                    py += STEP[d as usize].1;
                    if (px, py) == (x, y) && out[corner(px, py)] & (1 << d0) == 0 {
                        break;
                    }
                    walk.push((px, py));
                    let bits = out[corner(px, py)];
                    d = [(d + 1) % 4, d, (d + 3) % 4]
                        .into_iter()
                        .find(|&nd| bits & (1 << nd) != 0)
                        .expect("boundary edges form closed walks");
                }
                for ring in split_walk(&walk, &code, &mut visit, cw) {
                    // A 4-connected component has exactly one positive loop; should that ever
                    // fail, the largest one is the outer ring and the others are kept as rings.
                    let slot = &mut outers[comp];
                    if ring.signed_area > 0.0
                        && slot.as_ref().is_none_or(|o| o.signed_area < ring.signed_area)
                    {
                        if let Some(old) = slot.replace(ring) {
                            holes[comp].push(old);
                        }
                    } else {
                        holes[comp].push(ring);
                    }
                }
            }
        }
    }
    outers
        .into_iter()
        .zip(holes)
        .zip(sizes)
        .filter_map(|((outer, holes), pixels)| Some(ChainOutline { outer: outer?, holes, pixels }))
        .collect()
}

/// Splits a closed walk (corners `walk[k]`, edge `code[k]` from `walk[k]` to the next) at
/// repeated corners into simple loops.
fn split_walk(walk: &[(i64, i64)], code: &[u8], visit: &mut [u32], cw: usize) -> Vec<ChainRing> {
    let key = |p: (i64, i64)| p.1 as usize * cw + p.0 as usize;
    let mut rings = Vec::new();
    // Stack of (corner, code of the edge leaving it).
    let mut stack: Vec<((i64, i64), u8)> = Vec::with_capacity(walk.len());
    for (&p, &d) in walk.iter().zip(code) {
        let slot = visit[key(p)];
        if slot != u32::MAX {
            let tail = stack.split_off(slot as usize);
            for &(q, _) in &tail {
                visit[key(q)] = u32::MAX;
            }
            rings.push(make_ring(&tail));
        }
        visit[key(p)] = stack.len() as u32;
        stack.push((p, d));
    }
    for &(q, _) in &stack {
        visit[key(q)] = u32::MAX;
    }
    if !stack.is_empty() {
        rings.push(make_ring(&stack));
    }
    rings
}

fn make_ring(loop_: &[((i64, i64), u8)]) -> ChainRing {
    let n = loop_.len();
    let code: Vec<u8> = loop_.iter().map(|&(_, d)| d).collect();
    let mut vertices = Vec::new();
    let mut twice_area = 0i64;
    for k in 0..n {
        let (p, d) = loop_[k];
        let (q, _) = loop_[(k + 1) % n];
        twice_area += p.0 * q.1 - q.0 * p.1;
        let prev = loop_[(k + n - 1) % n].1;
        if prev != d {
            vertices.push([p.0 as f64 - 0.5, p.1 as f64 - 0.5]);
        }
    }
    ChainRing {
        start: [loop_[0].0.0, loop_[0].0.1],
        code,
        vertices,
        signed_area: twice_area as f64 / 2.0,
    }
}
