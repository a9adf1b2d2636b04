//! The thesis's experiments, run on our maps and printed beside the thesis's numbers
//! (`patchnav experiment ...` parses their settings and calls these).
//!
//! * [`lab`]: §6.1 on the simulated lab (Fig 6.4, Tables 6.1, 6.2, 6.4): its maps, corner
//!   starts, timed RRTs and explored volumes.

pub mod extraction;
pub mod lab;
pub mod map_coverage;
pub mod map_safety;
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
