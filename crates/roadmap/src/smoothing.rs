//! Path shortcutting: a post-process that shortens a planner's path by replacing parts of it
//! with straight capsule steps that are free (not in the thesis, which reports unsmoothed
//! paths, §5.5.4; the two passes are the usual greedy and random shortcutting of the
//! literature).
//!
//! # Guarantees
//! For any `path`, `radius` and seed, [`shortcut_path`] returns a path that
//! * starts and ends at the same points as `path` (an empty path stays empty);
//! * consists of segments of two kinds only: segments of `path`, kept verbatim, and segments
//!   whose capsule of radius `radius` the `map` reported free. So if every segment of `path`
//!   is free for `map`, so is every segment of the result;
//! * is never longer than `path`, as measured by [`path_length`]: a change is taken only if
//!   the whole path's computed length does not grow (a random shortcut only if it shrinks),
//!   so not even rounding can lengthen the path.
//!
//! Pieces of a segment cut at a random point are checked again rather than assumed free,
//! which keeps the second guarantee exact for any map, also where touching contacts make the
//! answer sensitive to rounding. A step that cannot be built (non-finite points, an invalid
//! radius) counts as colliding, so such input comes back unchanged.

use patch_core::{CapsuleStep, Point3, Real, UnspecificStepIntersector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::metrics::path_length;

/// The choices of [`shortcut_path`]. No `Default`: pick [`ShortcutConfig::standard`] and change
/// fields.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct ShortcutConfig {
    /// Run the greedy pass first: from each vertex, jump to the farthest later vertex that one
    /// free capsule step reaches.
    pub greedy: bool,
    /// How many random shortcuts to attempt after the greedy pass: each draws two points
    /// uniformly by arc length on the path (anywhere on its segments) and replaces the part
    /// between them by the straight step if that is free and shortens the path.
    pub random_attempts: usize,
}

impl ShortcutConfig {
    /// This crate's choice (the thesis does not smooth paths): the greedy pass, then 100
    /// random attempts.
    pub fn standard() -> ShortcutConfig {
        ShortcutConfig { greedy: true, random_attempts: 100 }
    }
}

/// Shortens `path` for a spherical robot of `radius` on `map`: the greedy pass (if
/// [`ShortcutConfig::greedy`]), then [`ShortcutConfig::random_attempts`] random shortcuts.
/// Deterministic: the same arguments and `seed` (ChaCha8) give the same path.
///
/// See the [module docs](self) for what the result guarantees.
///
/// # Complexity
/// The greedy pass makes at most `n(n − 1)/2` capsule checks for `n` vertices (fewer the more
/// it shortcuts) and each random attempt at most three; every free candidate costs `O(n)` to
/// measure.
pub fn shortcut_path<M: UnspecificStepIntersector + ?Sized>(
    map: &M,
    path: &[Point3],
    radius: Real,
    config: &ShortcutConfig,
    seed: u64,
) -> Vec<Point3> {
    let free = |a: &Point3, b: &Point3| {
        CapsuleStep::new(*a, *b, radius).is_ok_and(|step| map.is_step_free(&step))
    };
    let mut current = path.to_vec();
    let mut length = path_length(&current);
    if config.greedy {
        greedy_pass(&mut current, &mut length, &free);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for _ in 0..config.random_attempts {
        random_shortcut(&mut current, &mut length, &free, &mut rng);
    }
    current
}

/// From each vertex `i`, tries the later vertices from the last one backwards and jumps to
/// the first whose step from `i` is free and does not lengthen the path.
fn greedy_pass(
    path: &mut Vec<Point3>,
    length: &mut Real,
    free: &impl Fn(&Point3, &Point3) -> bool,
) {
    let mut i = 0;
    while i + 2 < path.len() {
        for j in (i + 2..path.len()).rev() {
            if !free(&path[i], &path[j]) {
                continue;
            }
            let candidate: Vec<Point3> = path[..=i].iter().chain(&path[j..]).copied().collect();
            let candidate_length = path_length(&candidate);
            if candidate_length <= *length {
                *path = candidate;
                *length = candidate_length;
                break;
            }
        }
        i += 1;
    }
}

/// The point at arc length `s` of `path` (given its cumulative lengths `cumulative`, one per
/// vertex): the segment index and the point.
fn point_at(path: &[Point3], cumulative: &[Real], s: Real) -> (usize, Point3) {
    let segment = cumulative.partition_point(|&c| c <= s).saturating_sub(1).min(path.len() - 2);
    let (a, b) = (path[segment], path[segment + 1]);
    let span = cumulative[segment + 1] - cumulative[segment];
    let t = if span > 0.0 { ((s - cumulative[segment]) / span).clamp(0.0, 1.0) } else { 0.0 };
    (segment, a + (b - a) * t)
}

/// One random shortcut: two points drawn uniformly by arc length; if they lie on different
/// segments `i < j`, the path between them is replaced by the straight step when the step and
/// the two cut pieces of segments `i` and `j` are free and the path gets shorter.
fn random_shortcut(
    path: &mut Vec<Point3>,
    length: &mut Real,
    free: &impl Fn(&Point3, &Point3) -> bool,
    rng: &mut ChaCha8Rng,
) {
    if path.len() < 3 {
        return;
    }
    let mut cumulative = Vec::with_capacity(path.len());
    let mut total = 0.0;
    cumulative.push(total);
    for w in path.windows(2) {
        total += (w[1] - w[0]).norm();
        cumulative.push(total);
    }
    let (u, v) = (rng.random::<Real>() * total, rng.random::<Real>() * total);
    if !(total > 0.0 && total.is_finite()) {
        return;
    }
    let (i, a) = point_at(path, &cumulative, u.min(v));
    let (j, b) = point_at(path, &cumulative, u.max(v));
    if i >= j {
        return;
    }
    let keep_a = a != path[i];
    let keep_b = b != path[j + 1];
    let from = if keep_a { a } else { path[i] };
    let to = if keep_b { b } else { path[j + 1] };
    let pieces_free =
        free(&from, &to) && (!keep_a || free(&path[i], &a)) && (!keep_b || free(&b, &path[j + 1]));
    if !pieces_free {
        return;
    }
    let mut candidate = Vec::with_capacity(path.len() + 2);
    candidate.extend_from_slice(&path[..=i]);
    candidate.extend(keep_a.then_some(a));
    candidate.extend(keep_b.then_some(b));
    candidate.extend_from_slice(&path[j + 1..]);
    let candidate_length = path_length(&candidate);
    if candidate_length < *length {
        *path = candidate;
        *length = candidate_length;
    }
}
