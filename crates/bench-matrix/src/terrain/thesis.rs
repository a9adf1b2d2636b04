//! The thesis's Chapter 4 numbers (spec `tof-hough.md` §3, §5) to print beside ours.

/// One row of Table 4.3: sensor, dataset, success, false negatives, false positives, ms.
pub(crate) struct DriveRow {
    /// `Stereo` or `TOF`.
    pub sensor: &'static str,
    /// Arena, Outdoor 1–3.
    pub dataset: &'static str,
    /// Success share.
    pub success: f64,
    /// False negatives.
    pub fneg: f64,
    /// False positives.
    pub fpos: f64,
    /// ms per snapshot.
    pub ms: f64,
}

/// Table 4.3 (L3790–3810), drivability at 45°; Stereo Outdoor 2 was excluded.
pub(crate) const TABLE_4_3: [DriveRow; 7] = [
    DriveRow { sensor: "Stereo", dataset: "Arena", success: 1.0, fneg: 0.0, fpos: 0.0, ms: 4.0 },
    DriveRow {
        sensor: "Stereo",
        dataset: "Outdoor 1",
        success: 0.987,
        fneg: 0.0,
        fpos: 0.013,
        ms: 53.0,
    },
    DriveRow {
        sensor: "Stereo",
        dataset: "Outdoor 3",
        success: 0.977,
        fneg: 0.016,
        fpos: 0.007,
        ms: 29.0,
    },
    DriveRow { sensor: "TOF", dataset: "Arena", success: 0.831, fneg: 0.169, fpos: 0.0, ms: 11.0 },
    DriveRow { sensor: "TOF", dataset: "Outdoor 1", success: 1.0, fneg: 0.0, fpos: 0.0, ms: 8.0 },
    DriveRow { sensor: "TOF", dataset: "Outdoor 2", success: 1.0, fneg: 0.0, fpos: 0.0, ms: 12.0 },
    DriveRow {
        sensor: "TOF",
        dataset: "Outdoor 3",
        success: 0.830,
        fneg: 0.031,
        fpos: 0.139,
        ms: 12.0,
    },
];

/// A scene row of Tables 4.6/4.7: `scene label #PC avgPts: rate/ms @45 | @15 | @9`.
pub(crate) type SceneRow = (u32, char, u32, u32, [(f64, f64); 3]);

/// Table 4.6 (stereo, L4034–4070) as reconstructed in spec §3.
pub(crate) const TABLE_4_6: [SceneRow; 12] = [
    (1, 'F', 32, 5058, [(1.0, 4.0), (0.0, 20.0), (0.0, 51.0)]),
    (2, 'O', 30, 22151, [(1.0, 16.0), (1.0, 92.0), (1.0, 232.0)]),
    (3, 'O', 1, 71646, [(1.0, 60.0), (1.0, 320.0), (1.0, 850.0)]),
    (4, 'F', 2, 11367, [(1.0, 15.0), (1.0, 60.0), (1.0, 160.0)]),
    (5, 'R', 47, 107173, [(0.0, 78.0), (0.0, 431.0), (0.0, 1089.0)]),
    (6, 'O', 1, 15267, [(0.0, 10.0), (0.0, 50.0), (0.0, 130.0)]),
    (7, 'F', 1, 32686, [(0.0, 1.0), (0.0, 30.0), (0.0, 70.0)]),
    (8, 'O', 30, 27139, [(1.0, 22.0), (1.0, 109.0), (1.0, 279.0)]),
    (9, 'O', 41, 25141, [(1.0, 19.0), (1.0, 100.0), (1.0, 255.0)]),
    (10, 'O', 2, 77342, [(0.0, 35.0), (0.5, 180.0), (0.5, 455.0)]),
    (11, 'R', 27, 10770, [(0.0, 8.0), (0.0, 42.0), (0.0, 109.0)]),
    (12, 'O', 23, 113368, [(1.0, 84.0), (1.0, 457.0), (1.0, 1163.0)]),
];

/// Table 4.6's printed mean (L4070): rate/ms at 45°, 15°, 9°.
pub(crate) const TABLE_4_6_MEAN: [(f64, f64); 3] = [(0.58, 29.0), (0.54, 158.0), (0.54, 404.0)];

/// Table 4.7 (SR-3000, L4125–4197) as reconstructed in spec §3.
pub(crate) const TABLE_4_7: [SceneRow; 30] = [
    (13, 'F', 55, 23484, [(0.98, 12.0), (0.96, 59.0), (0.96, 148.0)]),
    (14, 'F', 33, 23256, [(1.0, 12.0), (0.97, 60.0), (0.97, 148.0)]),
    (15, 'O', 43, 25344, [(0.79, 10.0), (1.0, 64.0), (1.0, 160.0)]),
    (16, 'F', 75, 25344, [(0.0, 13.0), (0.0, 64.0), (0.0, 161.0)]),
    (17, 'R', 113, 19691, [(0.0, 10.0), (0.0, 49.0), (0.30, 124.0)]),
    (18, 'O', 124, 25344, [(0.0, 12.0), (1.0, 64.0), (1.0, 160.0)]),
    (19, 'O', 32, 18121, [(0.0, 9.0), (0.0, 44.0), (0.0, 113.0)]),
    (20, 'O', 49, 24604, [(0.0, 12.0), (0.0, 61.0), (0.24, 155.0)]),
    (21, 'O', 44, 17396, [(0.0, 8.0), (0.0, 44.0), (0.50, 109.0)]),
    (22, 'F', 68, 11372, [(1.0, 5.0), (1.0, 29.0), (1.0, 72.0)]),
    (23, 'F', 70, 13812, [(1.0, 8.0), (1.0, 34.0), (1.0, 88.0)]),
    (24, 'R', 59, 7235, [(0.0, 3.0), (0.22, 18.0), (0.0, 45.0)]),
    (25, 'O', 90, 20375, [(1.0, 10.0), (1.0, 51.0), (1.0, 128.0)]),
    (26, 'O', 50, 23512, [(1.0, 11.0), (1.0, 60.0), (1.0, 146.0)]),
    (27, 'F', 28, 24726, [(1.0, 13.0), (1.0, 64.0), (1.0, 160.0)]),
    (28, 'F', 35, 25342, [(1.0, 13.0), (1.0, 65.0), (1.0, 158.0)]),
    (29, 'F', 50, 25004, [(1.0, 13.0), (1.0, 65.0), (0.98, 162.0)]),
    (30, 'F', 86, 25344, [(1.0, 11.0), (1.0, 63.0), (1.0, 160.0)]),
    (31, 'F', 13, 25343, [(1.0, 10.0), (1.0, 62.0), (1.0, 158.0)]),
    (32, 'F', 233, 25343, [(1.0, 12.0), (0.0, 64.0), (0.0, 160.0)]),
    (33, 'F', 892, 25250, [(0.0, 12.0), (0.0, 64.0), (0.0, 160.0)]),
    (34, 'R', 150, 25287, [(0.0, 14.0), (0.0, 64.0), (1.0, 160.0)]),
    (35, 'R', 169, 19853, [(0.0, 10.0), (0.0, 51.0), (0.0, 128.0)]),
    (36, 'O', 728, 25344, [(0.0, 12.0), (1.0, 63.0), (1.0, 160.0)]),
    (37, 'O', 904, 22625, [(0.0, 11.0), (1.0, 57.0), (1.0, 143.0)]),
    (38, 'O', 616, 25344, [(0.0, 13.0), (1.0, 64.0), (1.0, 169.0)]),
    (39, 'F', 538, 25343, [(1.0, 13.0), (0.0, 65.0), (0.0, 163.0)]),
    (40, 'R', 548, 25202, [(0.0, 12.0), (0.0, 66.0), (0.0, 160.0)]),
    (41, 'R', 987, 25343, [(0.0, 12.0), (0.0, 61.0), (0.0, 161.0)]),
    (42, 'O', 655, 25344, [(1.0, 12.0), (1.0, 63.0), (1.0, 157.0)]),
];

/// Table 4.7's printed mean (L4197), which is the 30-row sum divided by 27.
pub(crate) const TABLE_4_7_MEAN: [(f64, f64); 3] = [(0.55, 12.0), (0.64, 63.0), (0.70, 158.0)];

/// Column sums of rate and ms divided by `divisor` (the unweighted per-scene mean for
/// `divisor = rows.len()`).
pub(crate) fn column_means(rows: &[SceneRow], divisor: f64) -> [(f64, f64); 3] {
    let mut out = [(0.0, 0.0); 3];
    for (_, _, _, _, cols) in rows {
        for (o, c) in out.iter_mut().zip(cols) {
            o.0 += c.0;
            o.1 += c.1;
        }
    }
    out.map(|(r, t)| (r / divisor, t / divisor))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_4_7_mean_is_the_sum_over_27_and_4_6_the_true_mean() {
        let over27 = column_means(&TABLE_4_7, 27.0);
        for (ours, printed) in over27.iter().zip(TABLE_4_7_MEAN) {
            assert!((ours.0 - printed.0).abs() < 0.006, "{ours:?} vs {printed:?}");
            assert!((ours.1 - printed.1).abs() < 0.6, "{ours:?} vs {printed:?}");
        }
        let true_mean = column_means(&TABLE_4_7, 30.0);
        assert!((true_mean[0].0 - 0.49).abs() < 0.006 && (true_mean[2].1 - 142.5).abs() < 0.1);
        let stereo = column_means(&TABLE_4_6, 12.0);
        for (ours, printed) in stereo.iter().zip(TABLE_4_6_MEAN) {
            assert!((ours.0 - printed.0).abs() < 0.006, "{ours:?} vs {printed:?}");
            assert!((ours.1 - printed.1).abs() < 0.6, "{ours:?} vs {printed:?}");
        }
    }
}
