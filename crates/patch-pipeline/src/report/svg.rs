//! Inline SVG pictures: the top and perspective views of a map with its roadmaps (after thesis
//! Fig 6.3 and Fig 6.6) and the time-against-iterations plot (after Fig 6.4).

use super::html::{esc, sig};
use super::raster::{hex, map_colour};
use crate::results::{MapDrawing, P3, PlanRun, TimingCurve};
use roadmap::PlannerKind;
use std::fmt::Write as _;

/// Width the pictures are drawn at, pixels.
pub const WIDTH: f64 = 800.0;
/// Largest height of a map view, pixels.
const MAX_HEIGHT: f64 = 640.0;
/// Margin around the drawing, pixels.
const MARGIN: f64 = 12.0;

/// Colour of a planner's roadmap and path (by the name it reports): fixed for the RRT and the
/// PRM, others from a palette by a hash of the name (so every picture and the legend agree).
pub fn planner_colour(planner: &str) -> &'static str {
    const PALETTE: [&str; 4] = ["#8c564b", "#e377c2", "#17becf", "#bcbd22"];
    match planner.parse() {
        Ok(PlannerKind::Rrt) => "#d95f02",
        Ok(PlannerKind::Prm) => "#7b3294",
        _ => PALETTE[planner.bytes().map(usize::from).sum::<usize>() % PALETTE.len()],
    }
}

/// Colours of the view elements, shared with the legend.
pub mod colours {
    /// Planar patch fill (top view) and base colour (perspective).
    pub const POLYGON: [u8; 3] = [150, 185, 230];
    /// Planar patch outline.
    pub const POLYGON_EDGE: &str = "#5b86b8";
    /// Triangle outline (top view) and base fill (perspective).
    pub const TRIANGLE: [u8; 3] = [205, 200, 190];
    /// Triangle outline.
    pub const TRIANGLE_EDGE: &str = "#8a8578";
    /// Points.
    pub const POINT: &str = "#444444";
    /// Scan positions.
    pub const SCAN: &str = "#000000";
    /// Start.
    pub const START: &str = "#1a9850";
    /// Goals.
    pub const GOAL: &str = "#d7191c";
}

/// What a view draws besides the map: scan positions and the runs on this map.
pub struct Overlay<'a> {
    /// Sensor positions of the scans.
    pub scan_positions: &'a [P3],
    /// Planning runs to draw (roadmap edges faint, paths bold, start and goals).
    pub plans: &'a [&'a PlanRun],
}

/// How 3-D points map to the picture: screen x, screen y (down) and depth (larger is farther).
trait Projection {
    /// `None` if the point cannot be drawn (behind the camera, not finite).
    fn project(&self, p: &P3) -> Option<[f64; 3]>;
    /// Whether faces are sorted and shaded (perspective) or drawn flat in layers (top view).
    fn painter(&self) -> bool;
}

/// Orthographic top view: x right, y up.
struct Top;

impl Projection for Top {
    fn project(&self, p: &P3) -> Option<[f64; 3]> {
        finite(p).then(|| [p[0], -p[1], -p[2]])
    }
    fn painter(&self) -> bool {
        false
    }
}

/// A pinhole camera at `eye` looking along `forward`.
struct Perspective {
    eye: P3,
    right: P3,
    up: P3,
    forward: P3,
    near: f64,
}

impl Perspective {
    /// The fixed camera: above the (min x, min y) corner of `bounds`, outside it, looking at the
    /// centre from about 35° elevation.
    fn looking_at(bounds: &Bounds3) -> Perspective {
        let c = bounds.centre();
        let ext = bounds.extent();
        let span = ext[0].max(ext[1]).max(ext[2]).max(1e-6);
        let mut h = [bounds.min[0] - c[0], bounds.min[1] - c[1]];
        let hl = (h[0] * h[0] + h[1] * h[1]).sqrt();
        if hl < 0.05 * span {
            h = [-0.5 * span, -0.5 * span];
        }
        let hl = (h[0] * h[0] + h[1] * h[1]).sqrt();
        let eye = [c[0] + 1.9 * h[0], c[1] + 1.9 * h[1], bounds.max[2] + 1.3 * hl];
        let forward = normalize(sub(&c, &eye));
        let right = normalize(cross(&forward, &[0.0, 0.0, 1.0]));
        let up = cross(&right, &forward);
        let dist = norm(&sub(&c, &eye));
        Perspective { eye, right, up, forward, near: 1e-3 * dist }
    }
}

impl Projection for Perspective {
    fn project(&self, p: &P3) -> Option<[f64; 3]> {
        if !finite(p) {
            return None;
        }
        let v = sub(p, &self.eye);
        let depth = dot(&v, &self.forward);
        (depth > self.near)
            .then(|| [dot(&v, &self.right) / depth, -dot(&v, &self.up) / depth, depth])
    }
    fn painter(&self) -> bool {
        true
    }
}

/// Largest coordinate drawn, metres: beyond it a point is treated as garbage and skipped (so
/// spans and scales stay finite).
const MAX_COORD: f64 = 1e9;

/// Is `p` drawable (finite and within [`MAX_COORD`])?
fn finite(p: &P3) -> bool {
    p.iter().all(|v| v.is_finite() && v.abs() <= MAX_COORD)
}
fn sub(a: &P3, b: &P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: &P3, b: &P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: &P3, b: &P3) -> P3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn norm(a: &P3) -> f64 {
    dot(a, a).sqrt()
}
fn normalize(a: P3) -> P3 {
    let n = norm(&a);
    if n > 0.0 { [a[0] / n, a[1] / n, a[2] / n] } else { [1.0, 0.0, 0.0] }
}

/// Newell's normal of a polygon (unit, or zero if degenerate).
fn newell_normal(ring: &[P3]) -> P3 {
    let mut n = [0.0; 3];
    for (i, a) in ring.iter().enumerate() {
        let b = &ring[(i + 1) % ring.len()];
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    let l = norm(&n);
    if l > 0.0 { [n[0] / l, n[1] / l, n[2] / l] } else { [0.0; 3] }
}

/// An axis-aligned box of finite points.
#[derive(Clone, Copy, Debug)]
pub struct Bounds3 {
    /// Smallest corner.
    pub min: P3,
    /// Largest corner.
    pub max: P3,
}

impl Bounds3 {
    /// An empty box.
    pub fn empty() -> Bounds3 {
        Bounds3 { min: [f64::INFINITY; 3], max: [f64::NEG_INFINITY; 3] }
    }
    /// Grows to hold `p` (ignored if not finite).
    pub fn add(&mut self, p: &P3) {
        if finite(p) {
            for (i, v) in p.iter().enumerate() {
                self.min[i] = self.min[i].min(*v);
                self.max[i] = self.max[i].max(*v);
            }
        }
    }
    /// Holds no point?
    pub fn is_empty(&self) -> bool {
        self.min[0] > self.max[0]
    }
    fn centre(&self) -> P3 {
        [
            0.5 * (self.min[0] + self.max[0]),
            0.5 * (self.min[1] + self.max[1]),
            0.5 * (self.min[2] + self.max[2]),
        ]
    }
    fn extent(&self) -> P3 {
        sub(&self.max, &self.min)
    }
}

/// The box of everything a view of `drawing` shows, grown by `scene_box` when that is a real
/// box (not the default zero box).
pub fn view_bounds(drawing: &MapDrawing, scene_box: (&P3, &P3), overlay: &Overlay<'_>) -> Bounds3 {
    let mut b = Bounds3::empty();
    let (lo, hi) = scene_box;
    if finite(lo) && finite(hi) && (0..3).any(|i| hi[i] > lo[i]) {
        b.add(lo);
        b.add(hi);
    }
    drawing.polygons.iter().flatten().for_each(|p| b.add(p));
    drawing.triangles.iter().flatten().for_each(|p| b.add(p));
    drawing.points.iter().for_each(|p| b.add(p));
    overlay.scan_positions.iter().for_each(|p| b.add(p));
    for run in overlay.plans {
        b.add(&run.start);
        run.goals.iter().for_each(|p| b.add(p));
        run.paths.iter().flatten().for_each(|p| b.add(p));
        run.edges.iter().flatten().for_each(|p| b.add(p));
    }
    b
}

/// One thing to draw, projected (world units of the projection).
struct Prim {
    /// CSS class: consecutive primitives with the same class share one `<path>`.
    class: String,
    /// Closed (faces) or open (lines, dots).
    closed: bool,
    pts: Vec<[f64; 2]>,
    depth: f64,
}

/// The CSS classes a picture uses. A class is named after a hash of its rule, so pictures on one
/// page can define the same class without conflict (the rules land in the page's global CSS).
#[derive(Default)]
struct Styles {
    rules: std::collections::BTreeMap<String, String>,
}

impl Styles {
    /// The class for `css` (declarations, e.g. `fill:#fff;stroke:none`).
    fn class(&mut self, css: &str) -> String {
        // FNV-1a, 32 bits.
        let hash =
            css.bytes().fold(0x811c_9dc5u32, |h, b| (h ^ u32::from(b)).wrapping_mul(0x0100_0193));
        let name = format!("v{hash:08x}");
        self.rules.entry(name.clone()).or_insert_with(|| css.to_owned());
        name
    }

    /// A `<style>` element with every rule.
    fn element(&self) -> String {
        let mut out = String::from("<style>");
        for (name, css) in &self.rules {
            let _ = write!(out, ".{name}{{{css}}}");
        }
        out.push_str("</style>\n");
        out
    }
}

/// Builds the primitives of a view in drawing order.
fn primitives(
    drawing: &MapDrawing,
    overlay: &Overlay<'_>,
    proj: &dyn Projection,
    styles: &mut Styles,
) -> (Vec<Prim>, Vec<Prim>) {
    let project_all = |ring: &[P3]| -> Option<(Vec<[f64; 2]>, f64)> {
        let mut pts = Vec::with_capacity(ring.len());
        let mut depth = 0.0;
        for p in ring {
            let q = proj.project(p)?;
            pts.push([q[0], q[1]]);
            depth += q[2];
        }
        (!pts.is_empty()).then(|| (pts, depth / ring.len() as f64))
    };
    // Shading: a fixed light above and to the side; 8 levels so faces of equal shade merge.
    let light = normalize([0.3, 0.5, 1.0]);
    let shade = |base: [u8; 3], normal: P3| -> [u8; 3] {
        let k = 0.55 + 0.45 * dot(&normal, &light).abs();
        let k = (k * 8.0).round() / 8.0;
        base.map(|c| (f64::from(c) * k).round().min(255.0) as u8)
    };
    let painter = proj.painter();
    let mut scene = Vec::new();
    for ring in drawing.polygons.iter().filter(|r| r.len() >= 3) {
        if let Some((pts, depth)) = project_all(ring) {
            let css = if painter {
                let fill = hex(shade(colours::POLYGON, newell_normal(ring)));
                format!("fill:{fill};stroke:{};stroke-width:.4", colours::POLYGON_EDGE)
            } else {
                format!(
                    "fill:{};fill-opacity:.45;stroke:{};stroke-width:.6",
                    hex(colours::POLYGON),
                    colours::POLYGON_EDGE
                )
            };
            scene.push(Prim { class: styles.class(&css), closed: true, pts, depth });
        }
    }
    for tri in &drawing.triangles {
        if let Some((pts, depth)) = project_all(tri) {
            let css = if painter {
                let fill = hex(shade(colours::TRIANGLE, newell_normal(tri)));
                format!("fill:{fill};stroke:{};stroke-width:.25", colours::TRIANGLE_EDGE)
            } else {
                format!("fill:none;stroke:{};stroke-width:.3", colours::TRIANGLE_EDGE)
            };
            scene.push(Prim { class: styles.class(&css), closed: true, pts, depth });
        }
    }
    let dot_class = styles
        .class(&format!("fill:none;stroke:{};stroke-width:2;stroke-linecap:round", colours::POINT));
    for p in &drawing.points {
        if let Some((pts, depth)) = project_all(std::slice::from_ref(p)) {
            scene.push(Prim { class: dot_class.clone(), closed: false, pts, depth });
        }
    }
    if painter {
        // Painter's algorithm: farthest first.
        scene.sort_by(|a, b| b.depth.total_cmp(&a.depth));
    }
    let mut over = Vec::new();
    for run in overlay.plans {
        let c = planner_colour(&run.planner);
        let class =
            styles.class(&format!("fill:none;stroke:{c};stroke-width:.5;stroke-opacity:.35"));
        for e in &run.edges {
            if let Some((pts, depth)) = project_all(e) {
                over.push(Prim { class: class.clone(), closed: false, pts, depth });
            }
        }
    }
    for run in overlay.plans {
        let c = planner_colour(&run.planner);
        let class = styles.class(&format!(
            "fill:none;stroke:{c};stroke-width:2.6;stroke-linejoin:round;stroke-linecap:round"
        ));
        for path in run.paths.iter().filter(|p| p.len() >= 2) {
            if let Some((pts, depth)) = project_all(path) {
                over.push(Prim { class: class.clone(), closed: false, pts, depth });
            }
        }
    }
    (scene, over)
}

/// Writes `x` with at most one decimal, without a trailing `.0`.
fn push_num(out: &mut String, x: f64) {
    let r = (x * 10.0).round() / 10.0;
    if r == r.trunc() {
        let _ = write!(out, "{r:.0}");
    } else {
        let _ = write!(out, "{r:.1}");
    }
}

/// Markers: (position, kind) with kind 0 scan, 1 start, 2 goal.
fn markers(overlay: &Overlay<'_>, proj: &dyn Projection) -> Vec<([f64; 2], u8)> {
    let mut out = Vec::new();
    for p in overlay.scan_positions {
        out.extend(proj.project(p).map(|q| ([q[0], q[1]], 0)));
    }
    for run in overlay.plans {
        out.extend(proj.project(&run.start).map(|q| ([q[0], q[1]], 1)));
        for g in &run.goals {
            out.extend(proj.project(g).map(|q| ([q[0], q[1]], 2)));
        }
    }
    out.dedup_by(|a, b| {
        a.1 == b.1 && (a.0[0] - b.0[0]).abs() < 1e-9 && (a.0[1] - b.0[1]).abs() < 1e-9
    });
    out
}

/// Renders primitives and markers scaled to fit `WIDTH` × at most `MAX_HEIGHT`.
fn render(
    title: &str,
    styles: &Styles,
    scene: &[Prim],
    over: &[Prim],
    marks: &[([f64; 2], u8)],
) -> String {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    let all = scene.iter().chain(over).flat_map(|p| p.pts.iter()).chain(marks.iter().map(|m| &m.0));
    for q in all {
        for i in 0..2 {
            lo[i] = lo[i].min(q[i]);
            hi[i] = hi[i].max(q[i]);
        }
    }
    if lo[0] > hi[0] {
        lo = [0.0; 2];
        hi = [1.0; 2];
    }
    let span = [(hi[0] - lo[0]).max(1e-9), (hi[1] - lo[1]).max(1e-9)];
    let inner_w = WIDTH - 2.0 * MARGIN;
    let mut s = inner_w / span[0];
    if span[1] * s > MAX_HEIGHT - 2.0 * MARGIN {
        s = (MAX_HEIGHT - 2.0 * MARGIN) / span[1];
    }
    let width = WIDTH;
    let height = (span[1] * s + 2.0 * MARGIN).ceil();
    let off = [MARGIN + 0.5 * (inner_w - span[0] * s), MARGIN];
    let xy = |q: &[f64; 2]| [off[0] + (q[0] - lo[0]) * s, off[1] + (q[1] - lo[1]) * s];

    let mut out = String::new();
    let _ = writeln!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 {width} {height}\" width=\"{width}\" height=\"{height}\" \
         role=\"img\"><title>{}</title>\n<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>",
        esc(title)
    );
    out.push_str(&styles.element());
    let emit = |prims: &[Prim], out: &mut String| {
        let mut i = 0;
        while i < prims.len() {
            let class = &prims[i].class;
            let _ = write!(out, "<path class=\"{class}\" d=\"");
            while i < prims.len() && &prims[i].class == class {
                let p = &prims[i];
                for (k, q) in p.pts.iter().enumerate() {
                    let [x, y] = xy(q);
                    out.push(if k == 0 { 'M' } else { 'L' });
                    push_num(out, x);
                    out.push(' ');
                    push_num(out, y);
                }
                if p.closed {
                    out.push('Z');
                } else if p.pts.len() == 1 {
                    out.push_str("h0.1");
                }
                i += 1;
            }
            out.push_str("\"/>\n");
        }
    };
    emit(scene, &mut out);
    emit(over, &mut out);
    for (q, kind) in marks {
        let [x, y] = xy(q);
        let _ = match kind {
            0 => writeln!(
                out,
                "<circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"4\" fill=\"{}\" stroke=\"#fff\" stroke-width=\"1.2\"/>",
                colours::SCAN
            ),
            1 => writeln!(
                out,
                "<circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"6.5\" fill=\"{}\" stroke=\"#000\" stroke-width=\"1.2\"/>",
                colours::START
            ),
            _ => writeln!(
                out,
                "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"11\" height=\"11\" fill=\"{}\" stroke=\"#000\" stroke-width=\"1.2\"/>",
                x - 5.5,
                y - 5.5,
                colours::GOAL
            ),
        };
    }
    out.push_str("</svg>\n");
    out
}

/// Orthographic top view (xy) of `drawing`: patches filled light, triangles as thin outlines,
/// points as dots, then roadmap edges faint, paths bold, scan positions, start and goals.
pub fn top_view(drawing: &MapDrawing, overlay: &Overlay<'_>) -> String {
    let mut styles = Styles::default();
    let (scene, over) = primitives(drawing, overlay, &Top, &mut styles);
    let marks = markers(overlay, &Top);
    render(&format!("Top view of the {} map", drawing.kind), &styles, &scene, &over, &marks)
}

/// A cutaway of `drawing` for the perspective view: without what lies entirely in the top
/// `band` of `bounds` (the ceiling) or in the `band` next to its minimum-x and minimum-y faces
/// (the two walls between the camera and the room).
fn cutaway(drawing: &MapDrawing, bounds: &Bounds3, band: f64) -> MapDrawing {
    let hidden = |q: &P3| {
        q[2] > bounds.max[2] - band || q[0] < bounds.min[0] + band || q[1] < bounds.min[1] + band
    };
    MapDrawing {
        kind: drawing.kind.clone(),
        polygons: drawing.polygons.iter().filter(|p| !p.iter().all(&hidden)).cloned().collect(),
        triangles: drawing.triangles.iter().filter(|t| !t.iter().all(&hidden)).copied().collect(),
        points: drawing.points.iter().filter(|q| !hidden(q)).copied().collect(),
    }
}

/// Perspective view of `drawing` from a fixed camera above a corner of `bounds`, looking at its
/// centre, cut away so the inside shows (no ceiling, no walls on the camera's side: [`cutaway`]);
/// faces shaded by their normal and drawn farthest first (painter's algorithm), the same
/// overlays on top.
pub fn perspective_view(drawing: &MapDrawing, overlay: &Overlay<'_>, bounds: &Bounds3) -> String {
    let cam = if bounds.is_empty() {
        let mut unit = Bounds3::empty();
        unit.add(&[0.0; 3]);
        unit.add(&[1.0; 3]);
        Perspective::looking_at(&unit)
    } else {
        Perspective::looking_at(bounds)
    };
    let shown = if bounds.is_empty() {
        drawing.clone()
    } else {
        let e = bounds.extent();
        cutaway(drawing, bounds, 0.05 * e[0].min(e[1]).min(e[2]).max(0.0) + 0.1)
    };
    let mut styles = Styles::default();
    let (scene, over) = primitives(&shown, overlay, &cam, &mut styles);
    let marks = markers(overlay, &cam);
    render(&format!("Perspective view of the {} map", drawing.kind), &styles, &scene, &over, &marks)
}

/// Ticks 1-2-5 × 10ⁿ covering [lo, hi], about `target` of them.
fn nice_ticks(lo: f64, hi: f64, target: usize) -> Vec<f64> {
    if hi <= lo || !lo.is_finite() || !hi.is_finite() {
        return vec![lo];
    }
    let raw = (hi - lo) / target.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).take(100).map(|k| k as f64 * step).collect()
}

/// A tick value: whole numbers with thousands separators, others to 3 significant figures.
fn tick_label(t: f64) -> String {
    if t.is_finite() && t.abs() < 1e15 && t == t.round() {
        super::html::fixed(t, 0)
    } else {
        sig(t, 3)
    }
}

/// Time against iterations (Fig 6.4 layout): per map type the median line with markers and the
/// quartile band, time on a log axis. `None` if no curve has a positive, finite time.
pub fn time_plot(curves: &[TimingCurve]) -> Option<String> {
    // (map, colour, points (iterations, q1, median, q3)) with non-positive times dropped.
    let series: Vec<(String, String, Vec<[f64; 4]>)> = curves
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let n = c.iterations.len().min(c.median_ms.len()).min(c.q1_ms.len()).min(c.q3_ms.len());
            let pts = (0..n)
                .map(|k| [c.iterations[k] as f64, c.q1_ms[k], c.median_ms[k], c.q3_ms[k]])
                .filter(|p| p.iter().all(|v| v.is_finite()) && p[2] > 0.0)
                .map(|p| {
                    let q1 = if p[1] > 0.0 { p[1].min(p[2]) } else { p[2] };
                    [p[0], q1, p[2], p[3].max(p[2])]
                })
                .collect();
            (c.map.clone(), hex(map_colour(&c.map, i)), pts)
        })
        .collect();
    let all: Vec<&[f64; 4]> = series.iter().flat_map(|s| s.2.iter()).collect();
    if all.is_empty() {
        return None;
    }
    let x_max = all.iter().map(|p| p[0]).fold(0.0, f64::max).max(1.0);
    let x_min = all.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min).min(0.0);
    let y_lo = all.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min).log10().floor();
    let mut y_hi = all.iter().map(|p| p[3]).fold(0.0, f64::max).log10().ceil();
    if y_hi <= y_lo {
        y_hi = y_lo + 1.0;
    }
    let (w, h) = (WIDTH, 420.0);
    let (left, right, top, bottom) = (70.0, 130.0, 15.0, 50.0);
    let pw = w - left - right;
    let ph = h - top - bottom;
    let sx = |x: f64| left + (x - x_min) / (x_max - x_min) * pw;
    let sy = |ms: f64| top + (y_hi - ms.log10()) / (y_hi - y_lo) * ph;

    let mut out = String::new();
    let _ = writeln!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 {w} {h}\" width=\"{w}\" height=\"{h}\" role=\"img\" \
         font-family=\"sans-serif\" font-size=\"12\"><title>Time per run against iterations</title>\n\
         <rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>"
    );
    // Grid and tick labels.
    for e in (y_lo as i32)..=(y_hi as i32) {
        let y = sy(10f64.powi(e));
        let label = sig(10f64.powi(e), 1);
        let _ = writeln!(
            out,
            "<line x1=\"{left}\" x2=\"{:.1}\" y1=\"{y:.1}\" y2=\"{y:.1}\" stroke=\"#ddd\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{label}</text>",
            left + pw,
            left - 6.0,
            y + 4.0
        );
        for m in 2..10 {
            let y = sy(f64::from(m) * 10f64.powi(e));
            if e < y_hi as i32 {
                let _ = writeln!(
                    out,
                    "<line x1=\"{left}\" x2=\"{:.1}\" y1=\"{y:.1}\" y2=\"{y:.1}\" stroke=\"#f2f2f2\"/>",
                    left + pw
                );
            }
        }
    }
    for t in nice_ticks(x_min, x_max, 6) {
        let x = sx(t);
        let _ = writeln!(
            out,
            "<line x1=\"{x:.1}\" x2=\"{x:.1}\" y1=\"{top}\" y2=\"{:.1}\" stroke=\"#eee\"/>\
             <text x=\"{x:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>",
            top + ph,
            top + ph + 16.0,
            tick_label(t)
        );
    }
    let _ = writeln!(
        out,
        "<rect x=\"{left}\" y=\"{top}\" width=\"{pw}\" height=\"{ph}\" fill=\"none\" stroke=\"#333\"/>\n\
         <text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">iterations</text>\n\
         <text transform=\"translate(18 {:.1}) rotate(-90)\" text-anchor=\"middle\">time per run [ms] (log scale)</text>",
        left + pw / 2.0,
        h - 12.0,
        top + ph / 2.0
    );
    // Bands, then lines, then the legend.
    for (_, colour, pts) in &series {
        if pts.len() >= 2 {
            out.push_str("<path d=\"");
            for (k, p) in pts.iter().enumerate() {
                let _ = write!(
                    out,
                    "{}{:.1} {:.1}",
                    if k == 0 { 'M' } else { 'L' },
                    sx(p[0]),
                    sy(p[3])
                );
            }
            for p in pts.iter().rev() {
                let _ = write!(out, "L{:.1} {:.1}", sx(p[0]), sy(p[1]));
            }
            let _ = writeln!(out, "Z\" fill=\"{colour}\" fill-opacity=\"0.18\" stroke=\"none\"/>");
        }
        for p in pts {
            let x = sx(p[0]);
            let _ = writeln!(
                out,
                "<line x1=\"{x:.1}\" x2=\"{x:.1}\" y1=\"{:.1}\" y2=\"{:.1}\" stroke=\"{colour}\" stroke-width=\"1\"/>",
                sy(p[1]),
                sy(p[3])
            );
        }
    }
    for (_, colour, pts) in &series {
        if pts.is_empty() {
            continue;
        }
        out.push_str("<path d=\"");
        for (k, p) in pts.iter().enumerate() {
            let _ =
                write!(out, "{}{:.1} {:.1}", if k == 0 { 'M' } else { 'L' }, sx(p[0]), sy(p[2]));
        }
        let _ = writeln!(out, "\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"2\"/>");
        for p in pts {
            let _ = writeln!(
                out,
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"2.5\" fill=\"{colour}\"/>",
                sx(p[0]),
                sy(p[2])
            );
        }
    }
    for (k, (name, colour, _)) in series.iter().enumerate() {
        let y = top + 12.0 + 20.0 * k as f64;
        let x = left + pw + 14.0;
        let _ = writeln!(
            out,
            "<line x1=\"{x:.1}\" x2=\"{:.1}\" y1=\"{y:.1}\" y2=\"{y:.1}\" stroke=\"{colour}\" stroke-width=\"3\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\">{}</text>",
            x + 22.0,
            x + 28.0,
            y + 4.0,
            esc(name)
        );
    }
    out.push_str("</svg>\n");
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(map: &str) -> PlanRun {
        PlanRun {
            map: map.into(),
            backend: "b".into(),
            planner: "rrt".into(),
            seed: 1,
            solved: true,
            seconds: 0.1,
            iterations: 10,
            vertices: 5,
            collision_checks: 20,
            path_length: 3.0,
            turns: 1,
            steep_turns: 0,
            curviness_deg: 10.0,
            start: [1.0, 1.0, 1.0],
            goals: vec![[4.0, 4.0, 1.0]],
            paths: vec![vec![[1.0, 1.0, 1.0], [2.0, 3.0, 1.0], [4.0, 4.0, 1.0]]],
            edges: vec![[[1.0, 1.0, 1.0], [2.0, 3.0, 1.0]]],
        }
    }

    fn drawing() -> MapDrawing {
        MapDrawing {
            kind: "hybrid".into(),
            polygons: vec![vec![
                [0.0, 0.0, 0.0],
                [5.0, 0.0, 0.0],
                [5.0, 5.0, 0.0],
                [0.0, 5.0, 0.0],
            ]],
            triangles: vec![[[0.0, 0.0, 0.0], [0.0, 5.0, 0.0], [0.0, 5.0, 3.0]]],
            points: vec![[2.0, 2.0, 2.0], [f64::NAN, 0.0, 0.0]],
        }
    }

    #[test]
    fn top_view_puts_y_up_and_keeps_aspect() {
        let r = run("hybrid");
        let plans = [&r];
        let overlay = Overlay { scan_positions: &[[2.5, 2.5, 1.0]], plans: &plans };
        let svg = top_view(&drawing(), &overlay);
        assert_eq!(svg.matches("<svg").count(), 1);
        assert_eq!(svg.matches("</svg>").count(), 1);
        // A square scene: 800 wide would be 800 high, over the cap, so height is the cap.
        assert!(svg.contains(&format!("height=\"{MAX_HEIGHT}\"")), "{svg}");
        // Start at y=1 is drawn below the goal at y=4 (screen y grows down).
        let cy = |marker: &str| -> f64 {
            let i = svg.find(marker).unwrap();
            let rest = &svg[..i];
            let j = rest.rfind("cy=\"").unwrap() + 4;
            rest[j..].split('"').next().unwrap().parse().unwrap()
        };
        let start_y = cy(&format!("fill=\"{}\"", colours::START));
        let scan_y = cy(&format!("fill=\"{}\"", colours::SCAN));
        assert!(start_y > scan_y, "start y=1 below scan y=2.5: {start_y} vs {scan_y}");
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
    }

    #[test]
    fn perspective_draws_far_faces_first() {
        let far = [[10.0, 10.0, 0.0], [11.0, 10.0, 0.0], [11.0, 11.0, 0.0]];
        let near = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]];
        let d = MapDrawing {
            kind: "trimesh".into(),
            polygons: vec![],
            triangles: vec![near, far],
            points: vec![],
        };
        let overlay = Overlay { scan_positions: &[], plans: &[] };
        let b = view_bounds(&d, (&[0.0; 3], &[0.0; 3]), &overlay);
        let cam = Perspective::looking_at(&b);
        let (scene, _) = primitives(&d, &overlay, &cam, &mut Styles::default());
        assert_eq!(scene.len(), 2);
        assert!(scene[0].depth > scene[1].depth);
        // The far triangle (x ≈ 10) comes first: the camera sits beyond the min corner.
        let svg = perspective_view(&d, &overlay, &b);
        assert_eq!(svg.matches("<svg").count(), 1);
        assert!(!svg.contains("NaN"));
    }

    #[test]
    fn empty_inputs_draw_an_empty_frame() {
        let overlay = Overlay { scan_positions: &[], plans: &[] };
        let d = MapDrawing::default();
        let b = view_bounds(&d, (&[0.0; 3], &[0.0; 3]), &overlay);
        assert!(b.is_empty());
        for svg in [top_view(&d, &overlay), perspective_view(&d, &overlay, &b)] {
            assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
            assert!(!svg.contains("NaN") && !svg.contains("inf"));
        }
        assert!(time_plot(&[]).is_none());
    }

    #[test]
    fn absurd_coordinates_are_skipped() {
        let mut d = drawing();
        d.points.push([1e300, -1e300, 0.0]);
        d.triangles.push([[f64::MAX, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]);
        let overlay = Overlay { scan_positions: &[[-1e200, 0.0, 0.0]], plans: &[] };
        let b = view_bounds(&d, (&[0.0; 3], &[f64::INFINITY; 3]), &overlay);
        assert_eq!((b.min, b.max), ([0.0; 3], [5.0, 5.0, 3.0]));
        for svg in [top_view(&d, &overlay), perspective_view(&d, &overlay, &b)] {
            assert!(!svg.contains("NaN") && !svg.contains("inf"), "{svg}");
            assert!(!svg.contains("e+") && !svg.contains("e3"), "no huge numbers");
        }
    }

    #[test]
    fn time_plot_spans_the_decades_of_the_data() {
        let c = TimingCurve {
            map: "pc".into(),
            iterations: vec![100, 1000, 10_000],
            median_ms: vec![0.5, 5.0, 40.0],
            q1_ms: vec![0.4, 4.0, 30.0],
            q3_ms: vec![0.7, 6.0, 80.0],
        };
        let svg = time_plot(&[c]).unwrap();
        for label in [">0.1<", ">1<", ">10<", ">100<", "iterations", "log scale", ">pc<"] {
            assert!(svg.contains(label), "{label} missing");
        }
        assert!(!svg.contains(">1,000<"), "no decade beyond the data");
        assert!(svg.contains(">10,000<") && svg.contains(">2,000<"), "x ticks");
        assert_eq!(tick_label(0.25), "0.250");
        assert_eq!(
            nice_ticks(0.0, 10_000.0, 5),
            vec![0.0, 2000.0, 4000.0, 6000.0, 8000.0, 10_000.0]
        );
    }
}
