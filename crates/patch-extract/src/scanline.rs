//! The scan-line triangulation of range-image regions by convex grid polygons (thesis §5.3.3,
//! Alg 7 L4944–5023, Alg 8 L5025–5069, prose L4911–4927, L5071–5146).
//!
//! The region is read row by row as *stretches* (maximal runs of region pixels in a row). The
//! band between rows `i` and `i + 1` is covered by one *piece* per pair of overlapping stretches
//! `s` (row `i`) and `s′` (row `i + 1`); pieces are stacked downwards into open convex grid
//! polygons while the stack stays convex, and a polygon is emitted when it cannot be extended.
//! Each emitted polygon is triangulated; all vertices are pixel centres (see
//! [`crate::grid_mesh`] for the conventions), so the triangles live in 3D on the cloud points.
//!
//! # Pieces
//! * The **link polygon** `L(s, s′) = (TL, BL, BR, TR)` of Alg 8: `TL = max(a, a′ − 1)`,
//!   `BL = max(a′, a − 1)`, `TR = min(b, b′ + 1)`, `BR = min(b′, b + 1)` for `s = [a, b]`,
//!   `s′ = [a′, b′]`. It is exactly the area the naive triangulation
//!   ([`crate::grid_mesh::naive_triangulation`]) covers between the two stretches, and its edges
//!   are horizontal, vertical or 2×2 diagonals.
//! * **V1** uses link polygons only, so it covers exactly the naive triangulation's area, and
//!   every polygon edge is horizontal, vertical or the diagonal of a 2×2 pixel square.
//! * **V2** ("more types of diagonal lines", L5140–5146; the set is not given) uses the convex
//!   hull of the two whole stretches, `(a, i), (a′, i + 1), (b′, i + 1), (b, i)`, whenever `s`
//!   and `s′` overlap only each other (a one-to-one continuation): its side edges may be *any
//!   diagonal spanning one row*. Splits and merges keep link polygons. V2 therefore covers the
//!   naive area plus the slivers next to stretch ends that shift by more than one column
//!   (Fig 5.10's "less accurate coverage"), with fewer, larger polygons.
//!
//! # Differences from Alg 7 as printed
//! * Alg 7 compares each stretch with the left-most open polygon only and removes that polygon
//!   after use, which leaves the band between a polygon and a second stretch below it (a split)
//!   uncovered. Here every overlapping pair of stretches gets its piece, so splits and merges
//!   are covered.
//! * Alg 7 restarts after a failed extension with "`s′ + s` if convex, else the link polygon
//!   plus a lone `s`". A piece is always convex, so it simply opens a new polygon.
//! * Convexity is decided row by row from the two chains (left chain slopes non-decreasing,
//!   right chain slopes non-increasing, chains apart except at the top and bottom rows).
//!
//! # Triangulation and watertightness
//! Polygon vertices are the corners (strict turns) of its boundary. Where a corner of one
//! polygon lies on the boundary of another (link-polygon corners on a neighbour's horizontal
//! edge, the 'L' marks of Fig 5.8b, L5122–5128), it is inserted into that neighbour, so the mesh
//! has no T-junctions. Each convex polygon with `n` vertices (inserted ones included) is
//! triangulated into `n − 2` non-degenerate triangles by zipping its two boundary chains between
//! two corners, taking the shorter diagonal at each step (instead of the thesis's fixed octagon
//! pattern with degenerate triangles dropped, which cannot place inserted vertices).
//!
//! # Complexity
//! `O(w · h)` for the pass over the pixels plus `O(n log n)` in the number of polygon corners for
//! the watertightness bookkeeping.

use std::collections::HashSet;

use crate::grid_mesh::{GridError, GridMesh, RegionMask, VertexMap, grid_and_region};
use pointcloud::PointCloud;

/// Which scan-line variant (thesis L5140–5146).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum ScanLineVersion {
    /// Horizontal, vertical and 2×2 diagonal edges only; covers exactly the naive area.
    V1,
    /// Also any diagonal spanning one row, for one-to-one stretch continuations.
    V2,
}

/// The result of [`scan_line`]: the convex polygons and their triangulation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ScanLineMesh {
    /// The convex polygons as pixel `[col, row]` vertex loops (inserted watertightness vertices
    /// included, no repeated vertex).
    pub polygons: Vec<Vec<[u32; 2]>>,
    /// Their triangles; `mesh.stats.polygons` is `polygons.len()`.
    pub mesh: GridMesh,
}

/// A stretch `[a, b]` of region pixels in one row (inclusive columns).
#[derive(Copy, Clone, Debug)]
struct Stretch {
    a: i64,
    b: i64,
}

/// A piece covering the band between two rows: `[tl, tr]` on the upper row, `[bl, br]` on the
/// lower one.
#[derive(Copy, Clone, Debug)]
struct Piece {
    tl: i64,
    tr: i64,
    bl: i64,
    br: i64,
}

/// A convex grid polygon: its left and right chain, one column per row from `top`.
#[derive(Clone, Debug)]
struct GridPolygon {
    top: i64,
    left: Vec<i64>,
    right: Vec<i64>,
}

impl GridPolygon {
    fn from_piece(top: i64, p: &Piece) -> Self {
        GridPolygon { top, left: vec![p.tl, p.bl], right: vec![p.tr, p.br] }
    }

    fn bottom(&self) -> (i64, i64) {
        (*self.left.last().expect("non-empty"), *self.right.last().expect("non-empty"))
    }

    /// Appends `p` below if the polygon stays convex.
    fn try_extend(&mut self, p: &Piece) -> bool {
        let k = self.left.len() - 1;
        let (l, r) = (self.left[k], self.right[k]);
        debug_assert!((l, r) == (p.tl, p.tr));
        if l >= r || k == 0 {
            return false;
        }
        let convex_left = p.bl - l >= l - self.left[k - 1];
        let convex_right = p.br - r <= r - self.right[k - 1];
        if convex_left && convex_right {
            self.left.push(p.bl);
            self.right.push(p.br);
            true
        } else {
            false
        }
    }

    /// The boundary as lattice points `(col, row)`: down the left chain, up the right chain
    /// (horizontal edges are implicit between consecutive points), without repeats.
    fn boundary(&self) -> Vec<(i64, i64)> {
        let n = self.left.len();
        let mut pts = Vec::with_capacity(2 * n);
        for (k, &x) in self.left.iter().enumerate() {
            pts.push((x, self.top + k as i64));
        }
        for (k, &x) in self.right.iter().enumerate().rev() {
            let p = (x, self.top + k as i64);
            if pts.last() != Some(&p) {
                pts.push(p);
            }
        }
        if pts.len() > 1 && pts.first() == pts.last() {
            let _ = pts.pop();
        }
        pts
    }
}

fn cross(o: (i64, i64), a: (i64, i64), b: (i64, i64)) -> i64 {
    (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
}

/// Indices of the strict corners of a closed loop.
fn corners(pts: &[(i64, i64)]) -> Vec<usize> {
    let n = pts.len();
    (0..n).filter(|&i| cross(pts[(i + n - 1) % n], pts[i], pts[(i + 1) % n]) != 0).collect()
}

fn stretches_of_row(region: &RegionMask, row: u32) -> Vec<Stretch> {
    let w = region.width() as usize;
    let flags = &region.flags()[row as usize * w..(row as usize + 1) * w];
    let mut out = Vec::new();
    let mut c = 0;
    while c < w {
        if flags[c] {
            let a = c;
            while c + 1 < w && flags[c + 1] {
                c += 1;
            }
            out.push(Stretch { a: a as i64, b: c as i64 });
        }
        c += 1;
    }
    out
}

/// The pieces of the band between two rows' stretches, left to right.
fn band_pieces(up: &[Stretch], down: &[Stretch], version: ScanLineVersion) -> Vec<Piece> {
    let mut pairs = Vec::new();
    let (mut i, mut j) = (0, 0);
    while i < up.len() && j < down.len() {
        let (s, t) = (up[i], down[j]);
        if s.a <= t.b && t.a <= s.b {
            pairs.push((i, j));
        }
        if s.b < t.b {
            i += 1;
        } else {
            j += 1;
        }
    }
    let mut up_count = vec![0u32; up.len()];
    let mut down_count = vec![0u32; down.len()];
    for &(i, j) in &pairs {
        up_count[i] += 1;
        down_count[j] += 1;
    }
    pairs
        .iter()
        .map(|&(i, j)| {
            let (s, t) = (up[i], down[j]);
            if version == ScanLineVersion::V2 && up_count[i] == 1 && down_count[j] == 1 {
                Piece { tl: s.a, tr: s.b, bl: t.a, br: t.b }
            } else {
                Piece {
                    tl: s.a.max(t.a - 1),
                    tr: s.b.min(t.b + 1),
                    bl: t.a.max(s.a - 1),
                    br: t.b.min(s.b + 1),
                }
            }
        })
        // Two single points above each other cover no area.
        .filter(|p| p.tl < p.tr || p.bl < p.br)
        .collect()
}

/// The convex grid polygons covering the region (Alg 7 with the changes in the module docs).
fn convex_polygons(region: &RegionMask, version: ScanLineVersion) -> Vec<GridPolygon> {
    let mut done = Vec::new();
    let mut open: Vec<GridPolygon> = Vec::new();
    let h = region.height();
    let mut up = if h > 0 { stretches_of_row(region, 0) } else { Vec::new() };
    for row in 1..h {
        let down = stretches_of_row(region, row);
        let pieces = band_pieces(&up, &down, version);
        let mut next = Vec::with_capacity(pieces.len());
        let mut old = open.into_iter().peekable();
        for p in &pieces {
            while old.peek().is_some_and(|q| q.bottom() < (p.tl, p.tr)) {
                done.push(old.next().expect("peeked"));
            }
            match old.next_if(|q| q.bottom() == (p.tl, p.tr)) {
                Some(mut q) => {
                    if q.try_extend(p) {
                        next.push(q);
                    } else {
                        done.push(q);
                        next.push(GridPolygon::from_piece(row as i64 - 1, p));
                    }
                }
                None => next.push(GridPolygon::from_piece(row as i64 - 1, p)),
            }
        }
        done.extend(old);
        open = next;
        up = down;
    }
    done.extend(open);
    done
}

/// Triangulates a convex loop (collinear points allowed) into `n − 2` non-degenerate triangles
/// by zipping the two chains between two corners. Returns indices into `pts`.
fn zip_triangulate(pts: &[(i64, i64)]) -> Vec<[usize; 3]> {
    let n = pts.len();
    if n < 3 {
        return Vec::new();
    }
    if n == 3 {
        return if cross(pts[0], pts[1], pts[2]) != 0 { vec![[0, 1, 2]] } else { Vec::new() };
    }
    let cs = corners(pts);
    if cs.len() < 3 {
        return Vec::new();
    }
    // Two corners at loop distance ≥ 2 both ways.
    let dist = |u: usize, w: usize| (w + n - u) % n;
    let (u, w) = if cs.len() >= 4 {
        (cs[0], cs[cs.len() / 2])
    } else {
        let pairs = [(cs[0], cs[1]), (cs[1], cs[2]), (cs[2], cs[0])];
        *pairs
            .iter()
            .find(|&&(u, w)| dist(u, w) >= 2 && dist(w, u) >= 2)
            .expect("a triangle with an extra point has such a pair")
    };
    let a: Vec<usize> = (0..=dist(u, w)).map(|k| (u + k) % n).collect();
    let b: Vec<usize> = (0..=dist(w, u)).map(|k| (u + n - k) % n).collect();
    let (m, nb) = (a.len() - 1, b.len() - 1);
    let d2 = |p: usize, q: usize| {
        let (dx, dy) = (pts[p].0 - pts[q].0, pts[p].1 - pts[q].1);
        dx * dx + dy * dy
    };
    let mut tris = vec![[u, a[1], b[1]]];
    let (mut i, mut j) = (1, 1);
    while i + 1 < m || j + 1 < nb {
        let advance_a = if i + 1 >= m {
            false
        } else if j + 1 >= nb {
            true
        } else {
            d2(a[i + 1], b[j]) <= d2(a[i], b[j + 1])
        };
        if advance_a {
            tris.push([a[i], a[i + 1], b[j]]);
            i += 1;
        } else {
            tris.push([a[i], b[j], b[j + 1]]);
            j += 1;
        }
    }
    tris.push([a[m - 1], w, b[nb - 1]]);
    tris
}

/// Triangulates a region by the scan-line method (see the module docs).
///
/// # Errors
/// [`GridError`] if the cloud is not organised or the mask has the wrong size.
///
/// # Complexity
/// Linear in the number of pixels (plus sorting the polygon corners per row).
pub fn scan_line(
    cloud: &PointCloud,
    mask: &RegionMask,
    version: ScanLineVersion,
) -> Result<ScanLineMesh, GridError> {
    let (grid, region) = grid_and_region(cloud, mask)?;
    let polys = convex_polygons(&region, version);
    let boundaries: Vec<Vec<(i64, i64)>> = polys.iter().map(GridPolygon::boundary).collect();

    // Corners of every polygon: the vertices other polygons must not have inside an edge.
    let mut required: HashSet<(i64, i64)> = HashSet::new();
    let mut per_row: Vec<Vec<i64>> = vec![Vec::new(); region.height() as usize];
    for pts in &boundaries {
        for c in corners(pts) {
            if required.insert(pts[c]) {
                per_row[pts[c].1 as usize].push(pts[c].0);
            }
        }
    }
    for row in &mut per_row {
        row.sort_unstable();
    }

    let mut map = VertexMap::new(cloud, grid);
    let mut triangles = Vec::new();
    let mut polygons = Vec::with_capacity(boundaries.len());
    for pts in &boundaries {
        let cs: HashSet<usize> = corners(pts).into_iter().collect();
        if cs.len() < 3 {
            continue;
        }
        let n = pts.len();
        let mut loop_pts: Vec<(i64, i64)> = Vec::with_capacity(n + 4);
        for k in 0..n {
            let p = pts[k];
            if cs.contains(&k) || required.contains(&p) {
                loop_pts.push(p);
            }
            // A horizontal edge to the next point: insert other polygons' corners inside it.
            let q = pts[(k + 1) % n];
            if p.1 == q.1 && (p.0 - q.0).abs() > 1 {
                let row = &per_row[p.1 as usize];
                let (lo, hi) = (p.0.min(q.0), p.0.max(q.0));
                let start = row.partition_point(|&x| x <= lo);
                let end = row.partition_point(|&x| x < hi);
                let inside = &row[start..end];
                if p.0 < q.0 {
                    loop_pts.extend(inside.iter().map(|&x| (x, p.1)));
                } else {
                    loop_pts.extend(inside.iter().rev().map(|&x| (x, p.1)));
                }
            }
        }
        let vids: Vec<u32> =
            loop_pts.iter().map(|&(c, r)| map.vertex(c as u32, r as u32)).collect();
        for t in zip_triangulate(&loop_pts) {
            triangles.push(t.map(|k| vids[k]));
        }
        polygons.push(loop_pts.iter().map(|&(c, r)| [c as u32, r as u32]).collect());
    }
    let count = polygons.len();
    Ok(ScanLineMesh { polygons, mesh: map.finish(triangles, count) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zip_handles_collinear_points() {
        // A triangle with two extra points on one side and one on another.
        let pts = [(0, 0), (1, 0), (2, 0), (3, 0), (0, 3), (0, 1)];
        let pts: Vec<(i64, i64)> = pts.to_vec();
        let tris = zip_triangulate(&pts);
        assert_eq!(tris.len(), pts.len() - 2);
        let area: i64 = tris.iter().map(|t| cross(pts[t[0]], pts[t[1]], pts[t[2]]).abs()).sum();
        assert_eq!(area, 9);
        assert!(tris.iter().all(|t| cross(pts[t[0]], pts[t[1]], pts[t[2]]) != 0));
    }
}
