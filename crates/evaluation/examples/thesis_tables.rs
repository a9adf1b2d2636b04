//! The thesis's Table 6.1 (its lab maps' sizes) and the median and quartiles of a few
//! planning times, as the experiments print them.
//!
//! ```sh
//! cargo run -p evaluation --example thesis_tables
//! ```

use evaluation::stats::{median, quartiles};
use evaluation::thesis::TABLE_6_1;

fn main() {
    println!("thesis Table 6.1 (Lab, 29 ALRF scans):");
    for row in TABLE_6_1 {
        println!("  {:<8} {:>6.1} MB", row.map, row.file_size_mb);
    }
    let seconds = [0.012, 0.010, 0.015, 0.011, f64::NAN, 0.013];
    let [q1, m, q3] = quartiles(&seconds).expect("finite values");
    println!(
        "planning times: median {:.4} s (quartiles {q1:.4}–{q3:.4} s), of the finite values",
        median(seconds).expect("finite values")
    );
    assert_eq!(Some(m), median(seconds));
}
