//! The thesis's experiments, run on our maps and printed beside the thesis's numbers
//! (`patchnav experiment ...` parses their settings and calls these).
//!
//! * [`office`]: §5.5.3, every planner on every backend on the office floor plan (Tables
//!   5.3–5.11);
//! * [`lab`]: §6.1 on the simulated lab (Fig 6.4, Tables 6.1, 6.2, 6.4): its maps, corner
//!   starts, timed RRTs and explored volumes;
//! * [`extraction`]: §5.3, segmentation quality (SegComp), the outlining survey
//!   (Figs 5.12–5.14), outline fidelity and patch sizes (Table 5.1);
//! * [`map_safety`]: maps built from scans against the exact scene (unsafe and overcautious
//!   steps, sizes, extraction time, roadmap edges re-checked);
//! * [`map_coverage`]: the share of each real scan's points its planes and hybrid maps hold;
//! * [`tof`]: Table 2.4, the adaptive amplitude threshold against amplitude thresholds.
//!
//! Each takes a settings struct whose [`Default`] is the command line's default and a
//! [`Progress`](crate::Progress) that receives its bars and its result tables.

pub mod extraction;
pub mod lab;
pub mod map_coverage;
pub mod map_safety;
pub mod office;
pub mod tof;

/// A writer that only counts the bytes written: a file's size without the file.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct ByteCount(pub u64);

impl std::io::Write for ByteCount {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0 += buf.len() as u64;
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}
