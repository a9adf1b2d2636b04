//! Raster pictures of the report: the ToF pixel outcomes and the explored-volume slice.

use super::encode::Rgb;
use crate::results::{TofSection, VolumeSection};

/// Largest picture side accepted from the data, pixels (a guard against absurd sizes).
const MAX_SIDE: u32 = 8192;

/// Pixel outcome codes of [`TofSection::outcomes`].
pub const TOF_KEPT: u8 = 0;
/// Unwrapped.
pub const TOF_UNWRAPPED: u8 = 1;
/// Dropped (any other code, 3 in the model, is "no measurement").
pub const TOF_DROPPED: u8 = 2;

/// Colour of a dropped pixel.
pub const TOF_DROPPED_RGB: [u8; 3] = [220, 30, 30];
/// Colour of a pixel without measurement.
pub const TOF_NONE_RGB: [u8; 3] = [0, 0, 0];

/// Shade of a kept (grey) or unwrapped (blue) pixel at `range` on a scale up to `max_range`:
/// near is light, far is dark.
pub fn tof_colour(outcome: u8, range: f32, max_range: f32) -> [u8; 3] {
    let t = if max_range > 0.0 && range.is_finite() {
        (range / max_range).clamp(0.0, 1.0)
    } else {
        0.5
    };
    let level = |hi: f32, lo: f32| (hi + (lo - hi) * t).round() as u8;
    match outcome {
        TOF_KEPT => {
            let g = level(235.0, 60.0);
            [g, g, g]
        }
        TOF_UNWRAPPED => [level(170.0, 10.0), level(200.0, 40.0), level(255.0, 150.0)],
        TOF_DROPPED => TOF_DROPPED_RGB,
        _ => TOF_NONE_RGB,
    }
}

/// Why a picture could not be drawn.
#[derive(Clone, Debug, PartialEq)]
pub struct Unusable(pub String);

/// The ToF outcome picture at its native size (one pixel per camera pixel) and the largest range
/// shaded. Unknown outcome codes draw as "no measurement"; a missing or short `radial` shades at
/// mid-range.
pub fn tof_image(tof: &TofSection) -> Result<(Rgb, f32), Unusable> {
    let (w, h) = (tof.width, tof.height);
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(Unusable(format!("image size {w} × {h} out of range")));
    }
    let n = w as usize * h as usize;
    if tof.outcomes.len() != n {
        return Err(Unusable(format!("{} outcomes for {w} × {h} pixels", tof.outcomes.len())));
    }
    let range = |i: usize| tof.radial.get(i).copied().filter(|r| r.is_finite() && *r > 0.0);
    let max_range = (0..n)
        .filter(|&i| matches!(tof.outcomes[i], TOF_KEPT | TOF_UNWRAPPED))
        .filter_map(range)
        .fold(0.0f32, f32::max);
    let mut img = Rgb::filled(w, h, TOF_NONE_RGB);
    for (i, &o) in tof.outcomes.iter().enumerate() {
        let r = range(i).unwrap_or(f32::NAN);
        img.set((i % w as usize) as u32, (i / w as usize) as u32, tof_colour(o, r, max_range));
    }
    Ok((img, max_range))
}

/// Colour of each map type in pictures and plots: the four thesis map types fixed, others from
/// a palette by index.
pub fn map_colour(kind: &str, index: usize) -> [u8; 3] {
    const PALETTE: [[u8; 3]; 6] = [
        [148, 103, 189],
        [140, 86, 75],
        [227, 119, 194],
        [127, 127, 127],
        [188, 189, 34],
        [23, 190, 207],
    ];
    match kind {
        "planes" => [31, 119, 180],
        "hybrid" => [44, 160, 44],
        "trimesh" => [255, 127, 14],
        "pc" => [214, 39, 40],
        _ => PALETTE[index % PALETTE.len()],
    }
}

/// `#rrggbb` of a colour.
pub fn hex(c: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

/// One colour of the slice picture.
#[derive(Clone, Debug, PartialEq)]
pub struct SliceKey {
    /// The bit set (bit i = map i explored the cell).
    pub bits: u8,
    /// Its colour.
    pub colour: [u8; 3],
    /// Cells with it.
    pub cells: usize,
}

/// The colour of a cell explored by the maps in `bits` (of `n_maps`): white if none, dark grey
/// if all (the black of Fig 6.2c), the map's colour if one, else the mean of the members' colours.
pub fn slice_colour(bits: u8, maps: &[String]) -> [u8; 3] {
    let n = maps.len().min(8);
    let all = if n == 8 { u8::MAX } else { (1u8 << n) - 1 };
    let bits = bits & all;
    if bits == 0 {
        return [255, 255, 255];
    }
    if bits == all {
        return [40, 40, 40];
    }
    let members: Vec<[u8; 3]> =
        (0..n).filter(|i| bits & (1 << i) != 0).map(|i| map_colour(&maps[i], i)).collect();
    let mean = |c: usize| {
        (members.iter().map(|m| u32::from(m[c])).sum::<u32>() / members.len() as u32) as u8
    };
    [mean(0), mean(1), mean(2)]
}

/// The slice of Fig 6.1 with y up (row 0 of the data, the smallest y, at the bottom), and the
/// colours used, most frequent first.
pub fn slice_image(vol: &VolumeSection) -> Result<(Rgb, Vec<SliceKey>), Unusable> {
    let [w, h] = vol.slice_size;
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(Unusable(format!("slice size {w} × {h} out of range")));
    }
    if vol.slice_bits.len() != w as usize * h as usize {
        return Err(Unusable(format!("{} cells for a {w} × {h} slice", vol.slice_bits.len())));
    }
    let mut counts = [0usize; 256];
    let mut img = Rgb::filled(w, h, [255, 255, 255]);
    let mask = if vol.maps.len() >= 8 { u8::MAX } else { (1u8 << vol.maps.len()) - 1 };
    for (i, &b) in vol.slice_bits.iter().enumerate() {
        let b = b & mask;
        counts[b as usize] += 1;
        let (x, row) = ((i % w as usize) as u32, (i / w as usize) as u32);
        img.set(x, h - 1 - row, slice_colour(b, &vol.maps));
    }
    let mut keys: Vec<SliceKey> = (0..=255u8)
        .filter(|&b| counts[b as usize] > 0)
        .map(|b| SliceKey {
            bits: b,
            colour: slice_colour(b, &vol.maps),
            cells: counts[b as usize],
        })
        .collect();
    keys.sort_by(|a, b| b.cells.cmp(&a.cells).then(a.bits.cmp(&b.bits)));
    Ok((img, keys))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tof(w: u32, h: u32, outcomes: Vec<u8>, radial: Vec<f32>) -> TofSection {
        TofSection {
            scene: "s".into(),
            width: w,
            height: h,
            outcomes,
            radial,
            method: "m".into(),
            discarded_percent: 0.0,
            wrapped_percent: 0.0,
            unwrapped_correct_percent: 0.0,
            wrong_percent: 0.0,
            yield_percent: 0.0,
            millis: 0.0,
        }
    }

    #[test]
    fn tof_pixels_get_their_outcome_colour() {
        let t = tof(4, 1, vec![0, 1, 2, 3], vec![1.0, 8.0, 2.0, 0.0]);
        let (img, max) = tof_image(&t).unwrap();
        assert_eq!(max, 8.0);
        let px = |i: usize| [img.data[3 * i], img.data[3 * i + 1], img.data[3 * i + 2]];
        assert!(
            px(0)[0] == px(0)[1] && px(0)[1] == px(0)[2] && px(0)[0] > 150,
            "near kept is light grey"
        );
        assert!(px(1)[2] > px(1)[0], "unwrapped is blue");
        assert_eq!(px(2), TOF_DROPPED_RGB);
        assert_eq!(px(3), TOF_NONE_RGB);
        // Farther kept pixels are darker.
        assert!(tof_colour(TOF_KEPT, 7.0, 8.0)[0] < tof_colour(TOF_KEPT, 1.0, 8.0)[0]);
    }

    #[test]
    fn tof_rejects_wrong_sizes_without_panicking() {
        assert!(tof_image(&tof(4, 2, vec![0; 7], vec![])).is_err());
        assert!(tof_image(&tof(0, 2, vec![], vec![])).is_err());
        assert!(tof_image(&tof(u32::MAX, u32::MAX, vec![], vec![])).is_err());
        // Short radial and NaN ranges still draw.
        assert!(tof_image(&tof(2, 1, vec![0, 9], vec![f32::NAN])).is_ok());
    }

    #[test]
    fn slice_is_flipped_and_counted() {
        let vol = VolumeSection {
            planner: "rrt".into(),
            runs: 1,
            iterations: 10,
            cell: 0.1,
            maps: vec!["planes".into(), "pc".into()],
            volumes_m3: vec![],
            table: vec![],
            slice_z: 0.3,
            slice_origin: [0.0, 0.0],
            slice_size: [2, 2],
            slice_bits: vec![3, 1, 0, 2],
        };
        let (img, keys) = slice_image(&vol).unwrap();
        // Row 0 (y smallest) is the bottom image row.
        assert_eq!(&img.data[6..9], &slice_colour(3, &vol.maps));
        assert_eq!(&img.data[0..3], &[255, 255, 255]);
        assert_eq!(keys.len(), 4);
        assert!(keys.iter().all(|k| k.cells == 1));
        assert_eq!(slice_colour(1, &vol.maps), map_colour("planes", 0));
        let bad = VolumeSection { slice_bits: vec![0; 3], ..vol };
        assert!(slice_image(&bad).is_err());
    }
}
