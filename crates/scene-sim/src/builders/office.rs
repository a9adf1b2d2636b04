//! The office floor plan of the thesis's preliminary planning experiment (§5.5.3, Fig. 5.19):
//! "Each wall was transformed into a planar patch of fixed height, with a door if specified.
//! A floor and ceiling were added."
//!
//! The layout is the one of the project's shared benchmark (`floorplan.json`, bounds
//! 20 × 15 × 2.5 m), so maps built from simulated scans of this scene are comparable with the
//! peer programs' results (x east, y north, z up, metres):
//!
//! * building 20 × 15 m, walls 2.5 m high and 0.1 m thick (centre lines on the numbers below),
//!   floor at z = 0 and ceiling at z = 2.5;
//! * a corridor y ∈ [6.5, 8.5] over the full width;
//! * south rooms (y 0–6.5): S1 x 0–5, S2 5–10, S3 10–15, S4 15–20;
//!   north rooms (y 8.5–15): N1 x 0–6, N2 6–14, N3 14–20;
//! * one door (1.0 m wide, 2.0 m high) from every room to the corridor, plus doors S2–S3 and
//!   N2–N3;
//! * start (10, 7.5) in the corridor, regions of interest (1.5, 1.5), (18.5, 1.5),
//!   (1.5, 13.5), (18.5, 13.5) in the corner rooms (see [`START`], [`GOALS`]).
//!
//! Every wall is two planar polygons (its faces, door openings as holes) plus end caps and door
//! reveals (jambs and the lintel's underside): the thesis's patches, with thickness. The
//! seeded [`office`] adds furniture (desks with legs, cabinets, bins, cardboard boxes) in the
//! rooms, keeping door passages, the corridor and the regions of interest free;
//! [`office_floorplan`] is the empty building.
//!
//! Simplified: no windows, no furniture detail below 2 cm, walls meet without overlap only on
//! their centre-line layout (hidden overlaps inside walls are harmless for ray casting).

use super::geometry::{horizontal_rect, vertical_rect};
use crate::shapes::Point2;
use crate::{Cuboid, Cylinder, Material, Scene, SceneBuilder, SceneError};
use pointcloud::{Point3, Real, Vector3};
use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;

/// Building width (x), metres.
pub const WIDTH: Real = 20.0;
/// Building depth (y), metres.
pub const DEPTH: Real = 15.0;
/// Wall height, metres.
pub const HEIGHT: Real = 2.5;
/// Wall thickness, metres.
pub const THICKNESS: Real = 0.1;
/// Door height, metres.
pub const DOOR_HEIGHT: Real = 2.0;
/// The planning start (x, y) in the corridor.
pub const START: [Real; 2] = [10.0, 7.5];
/// The four regions of interest (x, y) in the corner rooms.
pub const GOALS: [[Real; 2]; 4] = [[1.5, 1.5], [18.5, 1.5], [1.5, 13.5], [18.5, 13.5]];

const H: Real = THICKNESS / 2.0;

/// A wall: runs along `axis` (0 = x, 1 = y) on the centre line `c` of the other coordinate,
/// from `a0` to `a1`, with door intervals along it.
struct Wall {
    axis: usize,
    c: Real,
    a0: Real,
    a1: Real,
    doors: &'static [(Real, Real)],
}

const WALLS: [Wall; 11] = [
    Wall { axis: 0, c: 0.0, a0: -H, a1: WIDTH + H, doors: &[] },
    Wall { axis: 0, c: DEPTH, a0: -H, a1: WIDTH + H, doors: &[] },
    Wall { axis: 1, c: 0.0, a0: H, a1: DEPTH - H, doors: &[] },
    Wall { axis: 1, c: WIDTH, a0: H, a1: DEPTH - H, doors: &[] },
    Wall {
        axis: 0,
        c: 6.5,
        a0: H,
        a1: WIDTH - H,
        doors: &[(3.5, 4.5), (7.0, 8.0), (12.0, 13.0), (15.5, 16.5)],
    },
    Wall { axis: 0, c: 8.5, a0: H, a1: WIDTH - H, doors: &[(4.5, 5.5), (9.5, 10.5), (14.5, 15.5)] },
    Wall { axis: 1, c: 5.0, a0: H, a1: 6.5 - H, doors: &[] },
    Wall { axis: 1, c: 10.0, a0: H, a1: 6.5 - H, doors: &[(2.0, 3.0)] },
    Wall { axis: 1, c: 15.0, a0: H, a1: 6.5 - H, doors: &[] },
    Wall { axis: 1, c: 6.0, a0: 8.5 + H, a1: DEPTH - H, doors: &[] },
    Wall { axis: 1, c: 14.0, a0: 8.5 + H, a1: DEPTH - H, doors: &[(11.0, 12.0)] },
];

/// Rooms by name and centre-line bounds (x0, x1, y0, y1).
const ROOMS: [(&str, [Real; 4]); 7] = [
    ("S1", [0.0, 5.0, 0.0, 6.5]),
    ("S2", [5.0, 10.0, 0.0, 6.5]),
    ("S3", [10.0, 15.0, 0.0, 6.5]),
    ("S4", [15.0, 20.0, 0.0, 6.5]),
    ("N1", [0.0, 6.0, 8.5, 15.0]),
    ("N2", [6.0, 14.0, 8.5, 15.0]),
    ("N3", [14.0, 20.0, 8.5, 15.0]),
];

fn unit(axis: usize) -> Vector3 {
    if axis == 0 { Vector3::x() } else { Vector3::y() }
}

/// World point of wall coordinates (u along, v across from the centre line, height w).
fn to_xyz(wall: &Wall, u: Real, v: Real, w: Real) -> Point3 {
    if wall.axis == 0 { Point3::new(u, wall.c + v, w) } else { Point3::new(wall.c + v, u, w) }
}

fn add_walls(b: &mut SceneBuilder) -> Result<(), SceneError> {
    let wall_mat = Material::WHITE_MASONRY;
    for (i, wall) in WALLS.iter().enumerate() {
        let along = unit(wall.axis);
        let across = unit(1 - wall.axis);
        for (side, sign) in [("side+", 1.0), ("side-", -1.0)] {
            let normal = across * sign;
            let t = Vector3::z().cross(&normal);
            let s = along.dot(&t);
            let origin = to_xyz(wall, 0.0, sign * H, 0.0);
            let holes: Vec<_> =
                wall.doors.iter().map(|&(d0, d1)| (s * d0, s * d1, 0.0, DOOR_HEIGHT)).collect();
            let face =
                vertical_rect(origin, normal, (s * wall.a0, s * wall.a1), (0.0, HEIGHT), &holes)?;
            b.add(format!("wall-{i}/{side}"), face, wall_mat)?;
        }
        // End caps and door jambs: vertical rectangles across the wall thickness.
        let mut caps = vec![("end-0", wall.a0, -along, HEIGHT), ("end-1", wall.a1, along, HEIGHT)];
        for &(d0, d1) in wall.doors {
            caps.push(("jamb", d0, along, DOOR_HEIGHT));
            caps.push(("jamb", d1, -along, DOOR_HEIGHT));
        }
        for (k, (name, u, normal, top)) in caps.into_iter().enumerate() {
            let origin = to_xyz(wall, u, 0.0, 0.0);
            let rect = vertical_rect(origin, normal, (-H, H), (0.0, top), &[])?;
            b.add(format!("wall-{i}/{name}-{k}"), rect, wall_mat)?;
        }
        for (k, &(d0, d1)) in wall.doors.iter().enumerate() {
            let (p, q) = (to_xyz(wall, d0, -H, 0.0), to_xyz(wall, d1, H, 0.0));
            let lo = Point2::new(p.x.min(q.x), p.y.min(q.y));
            let hi = Point2::new(p.x.max(q.x), p.y.max(q.y));
            b.add(
                format!("wall-{i}/lintel-{k}"),
                horizontal_rect(lo, hi, DOOR_HEIGHT, false, &[])?,
                wall_mat,
            )?;
        }
    }
    let (lo, hi) = (Point2::new(-H, -H), Point2::new(WIDTH + H, DEPTH + H));
    b.add("floor", horizontal_rect(lo, hi, 0.0, true, &[])?, Material::CONCRETE)?;
    b.add("ceiling", horizontal_rect(lo, hi, HEIGHT, false, &[])?, Material::WHITE_MASONRY)?;
    Ok(())
}

/// The empty office building (walls with doors, floor, ceiling): the geometry of the shared
/// benchmark floor plan, with no furniture.
pub fn office_floorplan() -> Result<Scene, SceneError> {
    let mut b = SceneBuilder::new("office-empty");
    add_walls(&mut b)?;
    b.build()
}

/// An axis-aligned footprint rectangle (x0, x1, y0, y1).
type Rect = [Real; 4];

fn overlaps(a: &Rect, b: &Rect) -> bool {
    a[0] < b[1] && b[0] < a[1] && a[2] < b[3] && b[2] < a[3]
}

/// Areas furniture must keep free: door passages on both sides and the regions of interest.
fn keep_out() -> Vec<Rect> {
    let mut r = Vec::new();
    for wall in &WALLS {
        for &(d0, d1) in wall.doors {
            let (p, q) = (to_xyz(wall, d0 - 0.3, -1.2, 0.0), to_xyz(wall, d1 + 0.3, 1.2, 0.0));
            r.push([p.x.min(q.x), p.x.max(q.x), p.y.min(q.y), p.y.max(q.y)]);
        }
    }
    for g in GOALS {
        r.push([g[0] - 1.0, g[0] + 1.0, g[1] - 1.0, g[1] + 1.0]);
    }
    r
}

/// The building of [`office_floorplan`] with seeded furniture: in each of the seven rooms two
/// to four items, each either a desk (1.2–1.6 × 0.7–0.8 m top at 0.72–0.76 m on four legs), a
/// cabinet (0.6–1.0 × 0.4–0.5 × 1.2–2.0 m), both against a wall, a waste bin (upright cylinder,
/// radius 0.15–0.2 m, 0.3–0.45 m high) or a cardboard box (0.3–0.6 m, any yaw). Door passages
/// (1.2 m to either side of a door), the corridor and 1 m around each region of interest stay
/// free.
pub fn office(seed: u64) -> Result<Scene, SceneError> {
    let mut b = SceneBuilder::new("office");
    add_walls(&mut b)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut taken = keep_out();
    for (room, c) in ROOMS {
        let inner = [c[0] + H, c[1] - H, c[2] + H, c[3] - H];
        let items = rng.random_range(2..=4);
        for item in 0..items {
            let kind = rng.random_range(0..4u32);
            for _attempt in 0..40 {
                let name = format!("{room}/item-{item}");
                if place_item(&mut b, &mut rng, &mut taken, &inner, kind, &name)? {
                    break;
                }
            }
        }
    }
    b.build()
}

/// Tries once to place one item; `Ok(false)` if the drawn spot was taken.
fn place_item(
    b: &mut SceneBuilder,
    rng: &mut ChaCha8Rng,
    taken: &mut Vec<Rect>,
    inner: &Rect,
    kind: u32,
    name: &str,
) -> Result<bool, SceneError> {
    let gap = 0.02;
    match kind {
        0 | 1 => {
            // Desk or cabinet against a wall: size along the wall × depth × height.
            let (w, d, h) = if kind == 0 {
                (
                    rng.random_range(1.2..1.6),
                    rng.random_range(0.7..0.8),
                    rng.random_range(0.72..0.76),
                )
            } else {
                (rng.random_range(0.6..1.0), rng.random_range(0.4..0.5), rng.random_range(1.2..2.0))
            };
            let side = rng.random_range(0..4u32);
            let along_x = side < 2;
            let (sx, sy) = if along_x { (w, d) } else { (d, w) };
            if inner[1] - inner[0] < sx + 2.0 * gap || inner[3] - inner[2] < sy + 2.0 * gap {
                return Ok(false);
            }
            let (cx, cy) = match side {
                0 => (
                    rng.random_range(inner[0] + sx / 2.0..inner[1] - sx / 2.0),
                    inner[2] + gap + sy / 2.0,
                ),
                1 => (
                    rng.random_range(inner[0] + sx / 2.0..inner[1] - sx / 2.0),
                    inner[3] - gap - sy / 2.0,
                ),
                2 => (
                    inner[0] + gap + sx / 2.0,
                    rng.random_range(inner[2] + sy / 2.0..inner[3] - sy / 2.0),
                ),
                _ => (
                    inner[1] - gap - sx / 2.0,
                    rng.random_range(inner[2] + sy / 2.0..inner[3] - sy / 2.0),
                ),
            };
            let fp = [cx - sx / 2.0, cx + sx / 2.0, cy - sy / 2.0, cy + sy / 2.0];
            if taken.iter().any(|t| overlaps(t, &fp)) {
                return Ok(false);
            }
            taken.push([fp[0] - 0.1, fp[1] + 0.1, fp[2] - 0.1, fp[3] + 0.1]);
            let size = Vector3::new(sx, sy, 0.0);
            if kind == 0 {
                let top = 0.03;
                b.add(
                    format!("{name}/desk-top"),
                    Cuboid::standing(Point2::new(cx, cy), h - top, Vector3::new(sx, sy, top), 0.0)?,
                    Material::WOOD,
                )?;
                let leg = 0.05;
                for (k, (fx, fy)) in
                    [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)].into_iter().enumerate()
                {
                    let p =
                        Point2::new(cx + fx * (size.x / 2.0 - leg), cy + fy * (size.y / 2.0 - leg));
                    b.add(
                        format!("{name}/desk-leg-{k}"),
                        Cuboid::standing(p, 0.0, Vector3::new(leg, leg, h - top), 0.0)?,
                        Material::WOOD,
                    )?;
                }
            } else {
                b.add(
                    format!("{name}/cabinet"),
                    Cuboid::standing(Point2::new(cx, cy), 0.0, Vector3::new(sx, sy, h), 0.0)?,
                    Material::WOOD,
                )?;
            }
            Ok(true)
        }
        _ => {
            // A bin or a box anywhere in the room.
            let r =
                if kind == 2 { rng.random_range(0.15..0.2) } else { rng.random_range(0.3..0.6) };
            let reach = if kind == 2 { r } else { r * std::f64::consts::FRAC_1_SQRT_2 };
            let cx = rng.random_range(inner[0] + reach + gap..inner[1] - reach - gap);
            let cy = rng.random_range(inner[2] + reach + gap..inner[3] - reach - gap);
            let fp = [cx - reach, cx + reach, cy - reach, cy + reach];
            if taken.iter().any(|t| overlaps(t, &fp)) {
                return Ok(false);
            }
            taken.push([fp[0] - 0.1, fp[1] + 0.1, fp[2] - 0.1, fp[3] + 0.1]);
            if kind == 2 {
                let h = rng.random_range(0.3..0.45);
                b.add(
                    format!("{name}/bin"),
                    Cylinder::upright(Point3::new(cx, cy, 0.0), r, h)?,
                    Material::ASPHALT,
                )?;
            } else {
                let yaw = rng.random_range(0.0..std::f64::consts::FRAC_PI_2);
                let h = rng.random_range(0.3..0.6);
                b.add(
                    format!("{name}/box"),
                    Cuboid::standing(Point2::new(cx, cy), 0.0, Vector3::new(r, r, h), yaw)?,
                    Material::NEWSPAPER,
                )?;
            }
            Ok(true)
        }
    }
}
