//! The Hough space as a picture, like the thesis's Fig 4.3 (L3689–3705): the origin top left,
//! distance bins downwards, the angle pairs to the right with ρy outer and ρx inner (for each ρy
//! all ρx, then the next ρy). Bins above `t_m` of the maximum are white, the others grey scaled
//! uniformly up to that level, so pictures of different frames compare; the floor bin is
//! framed in yellow.

use crate::accumulator::Accumulator;
use crate::error::{HoughError, Result};
use crate::space::Bin;
use std::io::Write;
use std::path::Path;

/// How to draw the histogram.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HistogramStyle {
    /// Pixels per bin side (1–64).
    pub cell: u32,
    /// Bins above `t_m · max` are white (Algorithm 3's `t_m`, 2/3 in the thesis).
    pub t_m: f64,
    /// The bin to frame in yellow (the floor bin), if any.
    pub floor: Option<Bin>,
    /// Draw a dark blue separator column between ρy groups.
    pub separators: bool,
}

impl HistogramStyle {
    /// Fig 4.3's look: 8-pixel cells, `t_m = 2/3`, the floor framed, separators on.
    pub fn thesis(floor: Option<Bin>) -> HistogramStyle {
        HistogramStyle { cell: 8, t_m: 2.0 / 3.0, floor, separators: true }
    }
}

/// The RGB image (width, height, row-major RGB bytes) of an accumulator.
pub fn hough_image(acc: &Accumulator, style: &HistogramStyle) -> Result<(u32, u32, Vec<u8>)> {
    if !(1..=64).contains(&style.cell) {
        return Err(HoughError::BadParameter {
            what: "histogram cell",
            value: style.cell as f64,
            allowed: "1..=64 px",
        });
    }
    if !(0.0..=1.0).contains(&style.t_m) {
        return Err(HoughError::BadParameter { what: "t_m", value: style.t_m, allowed: "[0, 1]" });
    }
    let s = acc.space();
    let (nx, ny, nd) = (s.nx(), s.ny(), s.nd());
    let cell = style.cell as usize;
    let sep = usize::from(style.separators);
    let width = (nx * ny) * cell + (ny.saturating_sub(1)) * sep;
    let height = nd * cell;
    if width * height > 1 << 26 {
        return Err(HoughError::TooManyBins {
            what: "histogram pixels",
            bins: (width * height) as u64,
            limit: 1 << 26,
        });
    }
    let mut rgb = vec![0u8; width * height * 3];
    let max = acc.max_bin().map_or(0, |(_, c)| c) as f64;
    let white = style.t_m * max;
    let column = |ix: usize, iy: usize| (iy * nx + ix) * cell + iy * sep;
    for (x, y) in (0..ny).flat_map(|iy| (0..nx).map(move |ix| (ix, iy))) {
        for id in 0..nd {
            let c = acc.count(Bin { ix: x, iy: y, id }) as f64;
            let v = if max == 0.0 {
                0
            } else if c > white {
                255
            } else if white > 0.0 {
                (200.0 * c / white).round() as u8
            } else {
                0
            };
            let (x0, y0) = (column(x, y), id * cell);
            for py in y0..y0 + cell {
                for px in x0..x0 + cell {
                    let o = (py * width + px) * 3;
                    rgb[o..o + 3].copy_from_slice(&[v, v, v]);
                }
            }
        }
    }
    if style.separators {
        for iy in 1..ny {
            let px = column(0, iy) - 1;
            for py in 0..height {
                let o = (py * width + px) * 3;
                rgb[o..o + 3].copy_from_slice(&[0, 0, 96]);
            }
        }
    }
    if let Some(f) = style.floor.filter(|f| f.ix < nx && f.iy < ny && f.id < nd) {
        let (x0, y0) = (column(f.ix, f.iy), f.id * cell);
        for py in y0..y0 + cell {
            for px in x0..x0 + cell {
                if py == y0 || py == y0 + cell - 1 || px == x0 || px == x0 + cell - 1 {
                    let o = (py * width + px) * 3;
                    rgb[o..o + 3].copy_from_slice(&[255, 220, 0]);
                }
            }
        }
    }
    Ok((width as u32, height as u32, rgb))
}

/// Writes the histogram of `acc` as an 8-bit RGB PNG to `writer`.
pub fn hough_png<W: Write>(acc: &Accumulator, style: &HistogramStyle, writer: W) -> Result<()> {
    let (w, h, rgb) = hough_image(acc, style)?;
    let mut enc = png::Encoder::new(writer, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut out = enc.write_header().map_err(|e| HoughError::Png(e.to_string()))?;
    out.write_image_data(&rgb).map_err(|e| HoughError::Png(e.to_string()))?;
    out.finish().map_err(|e| HoughError::Png(e.to_string()))
}

/// [`hough_png`] into a file at `path`, replaced whole ([`pointcloud::io::write_atomically`]).
pub fn hough_png_file(
    acc: &Accumulator,
    style: &HistogramStyle,
    path: impl AsRef<Path>,
) -> Result<()> {
    pointcloud::io::write_atomically(path, |w| hough_png(acc, style, w))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::space::HoughSpace;

    #[test]
    fn layout_and_shades() {
        let space = HoughSpace::thesis_degrees(15.0).unwrap(); // 5 × 6 × 30
        let mut acc = Accumulator::new(space);
        let top = Bin { ix: 3, iy: 3, id: 14 };
        acc.add(top, 90);
        acc.add(Bin { ix: 1, iy: 0, id: 2 }, 30); // half of 2/3 · 90 = 60 → grey 100
        let style = HistogramStyle { cell: 2, t_m: 2.0 / 3.0, floor: None, separators: false };
        let (w, h, rgb) = hough_image(&acc, &style).unwrap();
        assert_eq!((w, h), (5 * 6 * 2, 30 * 2));
        let px = |x: usize, y: usize| rgb[(y * w as usize + x) * 3];
        // ρy outer, ρx inner: column (iy · nx + ix) · cell; distance down.
        assert_eq!(px((3 * 5 + 3) * 2, 14 * 2), 255);
        assert_eq!(px(2 + 1, 2 * 2 + 1), 100);
        assert_eq!(px(0, 0), 0);
        let mut bytes = Vec::new();
        hough_png(&acc, &HistogramStyle::thesis(Some(top)), &mut bytes).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        let bad = HistogramStyle { cell: 0, ..style };
        assert!(hough_image(&acc, &bad).is_err());
    }
}
