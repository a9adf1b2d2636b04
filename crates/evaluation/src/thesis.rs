//! The thesis's published planning figures (§5.5.3 Tables 5.3–5.11, §6.1–6.2 Tables 6.1,
//! 6.2, 6.4), with their line references, so every program that prints our results beside
//! the thesis's reads them from one place.
//!
//! Line numbers (`L…`) refer to the plain-text thesis (Poppinga 2010). The figures are copied
//! as printed, digit for digit: "–" (a framework that cannot run a planner, a map compared with
//! itself) is `None`, and nothing is rounded or recomputed, even where the prose disagrees
//! with a table (the "factor 2.35" of L6202 is 2.90 by Table 5.3).
//!
//! ```
//! use roadmap::PlannerKind;
//! use evaluation::thesis::{TABLE_5_3, TABLE_5_7};
//!
//! // The thesis's median RRT time on Bullet (the fourth column), s.
//! assert_eq!(TABLE_5_3.cell(PlannerKind::Rrt, 3), Some(0.004721));
//! // OPCODE cannot run the MA RRT (no closest-patch queries).
//! assert_eq!(TABLE_5_3.cell(PlannerKind::MaRrt, 2), None);
//! assert_eq!(TABLE_5_7.cell(PlannerKind::Prm, 0).map(|t| t.steep), Some(7));
//! ```

use roadmap::PlannerKind;

// ---------------------------------------------------------------------------------------------
// §5.5.3: the office benchmark (Tables 5.3–5.11).

/// The thesis's four collision frameworks, the columns of Tables 5.3–5.11 in its order
/// (L6154): the naive CGAL implementation, CGAL on 6D bounding boxes, OPCODE and Bullet.
pub const OFFICE_COLUMNS: [&str; 4] = ["Simple", "BB6D", "OPCODE", "Bullet"];

/// One planner's row of an office table: the thesis's figure per column of
/// [`OFFICE_COLUMNS`], `None` where the framework cannot run the planner (the thesis's "–":
/// OPCODE answers neither which patch a step hits nor the closest patch, L6099–6103).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct OfficeRow<T> {
    /// The planner.
    pub planner: PlannerKind,
    /// The thesis's label of the row ("RRT", "MA RRT", "Ev. RRT", "PRM", "MA PRM").
    pub label: &'static str,
    /// The figure per column.
    pub cells: [Option<T>; 4],
}

/// One of the thesis's Tables 5.3–5.11: five planners (its row order: RRT, MA RRT, Evasion
/// RRT, PRM, MA PRM) × four frameworks, over the successful runs of 50 seeds (L6119–6121).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct OfficeTable<T> {
    /// The table's number ("5.3").
    pub number: &'static str,
    /// What it measures, in the words of its caption.
    pub caption: &'static str,
    /// The thesis lines holding the table and its caption, first and last.
    pub lines: [u32; 2],
    /// The rows, in the thesis's order.
    pub rows: [OfficeRow<T>; 5],
}

impl<T: Copy> OfficeTable<T> {
    /// The figure of `planner` in column `column` (an index into [`OFFICE_COLUMNS`]); `None`
    /// for "–", a planner the thesis did not run or a column past the fourth.
    pub fn cell(&self, planner: PlannerKind, column: usize) -> Option<T> {
        self.rows.iter().find(|r| r.planner == planner)?.cells.get(column).copied().flatten()
    }
}

/// The lower and upper quartile as ratios to the median, as Tables 5.4, 5.6 and 5.11 print
/// them ("lower/upper").
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct QuartileRatios {
    /// Lower quartile / median.
    pub lower: f64,
    /// Upper quartile / median.
    pub upper: f64,
}

/// A cell of Tables 5.7–5.9, "steep/total/ratio": one quantile of the number of steep turns
/// (> 90°) on the paths to the ROIs, the same quantile of all turns, and the ratio the thesis
/// prints (the first over the second, to three decimals).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Turns {
    /// Steep turns.
    pub steep: u32,
    /// All turns.
    pub total: u32,
    /// The printed ratio.
    pub ratio: f64,
}

const fn row<T: Copy>(
    planner: PlannerKind,
    label: &'static str,
    cells: [Option<T>; 4],
) -> OfficeRow<T> {
    OfficeRow { planner, label, cells }
}

const fn q(lower: f64, upper: f64) -> Option<QuartileRatios> {
    Some(QuartileRatios { lower, upper })
}

const fn t(steep: u32, total: u32, ratio: f64) -> Option<Turns> {
    Some(Turns { steep, total, ratio })
}

use PlannerKind::{EvasionRrt, MaPrm, MaRrt, Prm, Rrt};

/// Table 5.3 (L6154–6166): median wall time \[s\] to reach the four ROIs from the start.
pub const TABLE_5_3: OfficeTable<f64> = OfficeTable {
    number: "5.3",
    caption: "median wall time taken to reach the ROIs from the starting point [s]",
    lines: [6154, 6166],
    rows: [
        row(Rrt, "RRT", [Some(0.010057), Some(0.006137), Some(0.002435), Some(0.004721)]),
        row(MaRrt, "MA RRT", [Some(0.124055), Some(0.060409), None, Some(0.055298)]),
        row(EvasionRrt, "Ev. RRT", [Some(0.18627), Some(0.156209), None, Some(0.099351)]),
        row(Prm, "PRM", [Some(0.013578), Some(0.010544), Some(0.001309), Some(0.008801)]),
        row(MaPrm, "MA PRM", [Some(1.96683), Some(1.20087), None, Some(0.678831)]),
    ],
};

/// Table 5.4 (L6168–6182): lower and upper quartile of the wall time, as ratios to the
/// median.
pub const TABLE_5_4: OfficeTable<QuartileRatios> = OfficeTable {
    number: "5.4",
    caption: "lower and upper quartile of the wall time taken to reach the ROIs, as ratios to \
              the median",
    lines: [6168, 6182],
    rows: [
        row(Rrt, "RRT", [q(0.547, 1.874), q(0.570, 1.837), q(0.716, 1.544), q(0.570, 1.730)]),
        row(MaRrt, "MA RRT", [q(0.513, 1.484), q(0.550, 1.643), None, q(0.520, 1.545)]),
        row(EvasionRrt, "Ev. RRT", [q(0.339, 2.141), q(0.305, 1.909), None, q(0.337, 2.124)]),
        row(Prm, "PRM", [q(0.525, 2.621), q(0.520, 2.830), q(0.770, 1.388), q(0.452, 3.123)]),
        row(MaPrm, "MA PRM", [q(0.253, 1.307), q(0.239, 1.243), None, q(0.354, 1.558)]),
    ],
};

/// Table 5.5 (L6220–6232): median added length \[m\] of the paths from the start to all ROIs
/// (the sum of the four paths' lengths).
pub const TABLE_5_5: OfficeTable<f64> = OfficeTable {
    number: "5.5",
    caption: "median added length of the paths from the starting point to all ROIs [m]",
    lines: [6220, 6232],
    rows: [
        row(Rrt, "RRT", [Some(23.1608), Some(23.1608), Some(21.5803), Some(23.1608)]),
        row(MaRrt, "MA RRT", [Some(22.166), Some(22.3942), None, Some(22.1411)]),
        row(EvasionRrt, "Ev. RRT", [Some(25.7439), Some(26.621), None, Some(26.621)]),
        row(Prm, "PRM", [Some(41.3277), Some(41.3277), Some(40.2935), Some(41.3277)]),
        row(MaPrm, "MA PRM", [Some(66.0655), Some(64.6227), None, Some(68.2961)]),
    ],
};

/// Table 5.6 (L6239–6253): lower and upper quartile of the added length, as ratios to the
/// median.
pub const TABLE_5_6: OfficeTable<QuartileRatios> = OfficeTable {
    number: "5.6",
    caption: "lower and upper quartile of the added length of the paths to all ROIs, as \
              ratios to the median",
    lines: [6239, 6253],
    rows: [
        row(Rrt, "RRT", [q(0.904, 1.060), q(0.904, 1.060), q(0.926, 1.158), q(0.904, 1.060)]),
        row(MaRrt, "MA RRT", [q(0.947, 1.042), q(0.935, 1.034), None, q(0.943, 1.047)]),
        row(EvasionRrt, "Ev. RRT", [q(0.923, 1.104), q(0.932, 1.066), None, q(0.924, 1.066)]),
        row(Prm, "PRM", [q(0.838, 1.212), q(0.838, 1.212), q(0.843, 1.291), q(0.838, 1.212)]),
        row(MaPrm, "MA PRM", [q(0.797, 1.094), q(0.815, 1.167), None, q(0.771, 1.158)]),
    ],
};

/// Table 5.7 (L6255–6271): median number of steep (> 90°) turns / median number of turns /
/// ratio on the paths from the start to the ROIs.
pub const TABLE_5_7: OfficeTable<Turns> = OfficeTable {
    number: "5.7",
    caption: "median steep (> 90°) turns / median total turns / ratio on the paths from the \
              starting point to the ROIs",
    lines: [6255, 6271],
    rows: [
        row(Rrt, "RRT", [t(3, 20, 0.150), t(3, 20, 0.150), t(2, 18, 0.111), t(3, 20, 0.150)]),
        row(MaRrt, "MA RRT", [t(3, 18, 0.167), t(3, 18, 0.167), None, t(2, 18, 0.111)]),
        row(EvasionRrt, "Ev. RRT", [t(3, 23, 0.130), t(3, 24, 0.125), None, t(3, 24, 0.125)]),
        row(Prm, "PRM", [t(7, 14, 0.500), t(7, 14, 0.500), t(4, 8, 0.500), t(7, 14, 0.500)]),
        row(MaPrm, "MA PRM", [t(36, 160, 0.225), t(36, 167, 0.216), None, t(38, 189, 0.201)]),
    ],
};

/// Table 5.8 (L6303–6319): the lower quartiles of Table 5.7's counts, and their ratio.
pub const TABLE_5_8: OfficeTable<Turns> = OfficeTable {
    number: "5.8",
    caption: "lower quartile of steep (> 90°) turns / lower quartile of total turns / ratio on \
              the paths from the starting point to the ROIs",
    lines: [6303, 6319],
    rows: [
        row(Rrt, "RRT", [t(2, 17, 0.118), t(2, 17, 0.118), t(1, 16, 0.062), t(2, 17, 0.118)]),
        row(MaRrt, "MA RRT", [t(2, 17, 0.118), t(1, 17, 0.059), None, t(2, 17, 0.118)]),
        row(EvasionRrt, "Ev. RRT", [t(2, 21, 0.095), t(2, 22, 0.091), None, t(2, 22, 0.091)]),
        row(Prm, "PRM", [t(4, 9, 0.444), t(4, 9, 0.444), t(3, 5, 0.600), t(4, 9, 0.444)]),
        row(MaPrm, "MA PRM", [t(22, 91, 0.242), t(22, 95, 0.232), None, t(24, 95, 0.253)]),
    ],
};

/// Table 5.9 (L6326–6342): the upper quartiles of Table 5.7's counts, and their ratio.
pub const TABLE_5_9: OfficeTable<Turns> = OfficeTable {
    number: "5.9",
    caption: "upper quartile of steep (> 90°) turns / upper quartile of total turns / ratio on \
              the paths from the starting point to the ROIs",
    lines: [6326, 6342],
    rows: [
        row(Rrt, "RRT", [t(4, 22, 0.182), t(4, 22, 0.182), t(3, 21, 0.143), t(4, 22, 0.182)]),
        row(MaRrt, "MA RRT", [t(4, 20, 0.200), t(4, 20, 0.200), None, t(4, 20, 0.200)]),
        row(EvasionRrt, "Ev. RRT", [t(5, 25, 0.200), t(5, 25, 0.200), None, t(5, 25, 0.200)]),
        row(Prm, "PRM", [t(9, 18, 0.500), t(9, 18, 0.500), t(7, 11, 0.636), t(9, 18, 0.500)]),
        row(MaPrm, "MA PRM", [t(46, 242, 0.190), t(48, 242, 0.198), None, t(52, 238, 0.218)]),
    ],
};

/// Table 5.10 (L6344–6358): median curviness [°], the upper quartile of the turn angles on
/// the paths from the start to the ROIs (L6364–6366).
pub const TABLE_5_10: OfficeTable<f64> = OfficeTable {
    number: "5.10",
    caption: "median curviness (upper quartile of the turn angles) of the paths from the \
              starting point to the ROIs [°]",
    lines: [6344, 6358],
    rows: [
        row(Rrt, "RRT", [Some(78.0185), Some(78.0185), Some(71.383), Some(78.0185)]),
        row(MaRrt, "MA RRT", [Some(78.5776), Some(77.6607), None, Some(78.8892)]),
        row(EvasionRrt, "Ev. RRT", [Some(80.0567), Some(78.5778), None, Some(77.8766)]),
        row(Prm, "PRM", [Some(119.903), Some(119.903), Some(135.332), Some(119.903)]),
        row(MaPrm, "MA PRM", [Some(86.8547), Some(86.8317), None, Some(86.5707)]),
    ],
};

/// Table 5.11 (L6386–6402): lower and upper quartile of the curviness, as ratios to the
/// median.
pub const TABLE_5_11: OfficeTable<QuartileRatios> = OfficeTable {
    number: "5.11",
    caption: "lower and upper quartile of the curviness of the paths to the ROIs, as ratios to \
              the median",
    lines: [6386, 6402],
    rows: [
        row(Rrt, "RRT", [q(0.850, 1.093), q(0.850, 1.093), q(0.858, 1.153), q(0.850, 1.093)]),
        row(MaRrt, "MA RRT", [q(0.791, 1.048), q(0.838, 1.060), None, q(0.832, 1.065)]),
        row(EvasionRrt, "Ev. RRT", [q(0.913, 1.042), q(0.937, 1.060), None, q(0.946, 1.063)]),
        row(Prm, "PRM", [q(0.876, 1.080), q(0.876, 1.080), q(0.905, 1.158), q(0.876, 1.080)]),
        row(MaPrm, "MA PRM", [q(0.973, 1.028), q(0.968, 1.029), None, q(0.960, 1.042)]),
    ],
};

/// How many of the 50 MA PRM runs reached all four ROIs, per column of [`OFFICE_COLUMNS`]
/// (L6141–6145: 28 for "OPCODE, simple and 6D bounding box", 30 for Bullet; OPCODE cannot run
/// the MA PRM, L6099–6103, so its 28 is kept as printed).
pub const MA_PRM_SOLVED_OF_50: [u32; 4] = [28, 28, 28, 30];

// ---------------------------------------------------------------------------------------------
// §6.1–6.2: the lab (Tables 6.1, 6.2, 6.4; Fig 6.4).

/// The thesis's four map types of the lab in the column order of Tables 6.2 and 6.4
/// (L6762): planar patches only, planes plus trimeshes, trimeshes only, point clouds.
pub const LAB_MAPS: [&str; 4] = ["planes", "hybrid", "trimesh", "pc"];

/// A row of Table 6.1: what one map of the lab holds. `None` is the thesis's "–".
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MapContents {
    /// The map type (one of [`LAB_MAPS`]).
    pub map: &'static str,
    /// The map file's size, MB.
    pub file_size_mb: f64,
    /// Planar patches.
    pub planar_patches: Option<u32>,
    /// Trimesh patches.
    pub trimesh_patches: Option<u32>,
    /// Point clouds.
    pub point_clouds: Option<u32>,
    /// Triangles (of the trimesh patches and of the planar patches' triangulations).
    pub triangles: Option<u32>,
}

/// Table 6.1 (L6721–6739): the lab's map types (29 ALRF scans), in the thesis's row order.
/// Its caption adds a median of 11 points per polygon and 163,439 per cloud.
pub const TABLE_6_1: [MapContents; 4] = [
    MapContents {
        map: "hybrid",
        file_size_mb: 8.7,
        planar_patches: Some(5906),
        trimesh_patches: Some(4142),
        point_clouds: None,
        triangles: Some(345_533),
    },
    MapContents {
        map: "pc",
        file_size_mb: 54.0,
        planar_patches: None,
        trimesh_patches: None,
        point_clouds: Some(29),
        triangles: None,
    },
    MapContents {
        map: "planes",
        file_size_mb: 3.0,
        planar_patches: Some(5906),
        trimesh_patches: Some(0),
        point_clouds: None,
        triangles: Some(86_174),
    },
    MapContents {
        map: "trimesh",
        file_size_mb: 106.4,
        planar_patches: Some(0),
        trimesh_patches: Some(17_273),
        point_clouds: None,
        triangles: Some(5_600_612),
    },
];

/// A row of Tables 6.2 and 6.4: the volume explored on one map and the share of it that
/// another map's roadmaps did not explore.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct VolumeRow {
    /// The map of the row (one of [`LAB_MAPS`]).
    pub map: &'static str,
    /// The volume explored on it, m³.
    pub volume_m3: f64,
    /// Per column of [`LAB_MAPS`]: % of this row's volume not explored on the column's map;
    /// `None` on the diagonal.
    pub not_in_percent: [Option<f64>; 4],
}

/// Table 6.2 (L6760–6778): explored volume of the RRT on the lab (480 RRTs per map, K =
/// 10,000, a 1024³ grid of 38.684 mm cells).
pub const TABLE_6_2_RRT: [VolumeRow; 4] = [
    VolumeRow {
        map: "planes",
        volume_m3: 9714.015,
        not_in_percent: [None, Some(0.557), Some(1.739), Some(0.986)],
    },
    VolumeRow {
        map: "hybrid",
        volume_m3: 9693.171,
        not_in_percent: [Some(0.343), None, Some(1.551), Some(0.803)],
    },
    VolumeRow {
        map: "trimesh",
        volume_m3: 9564.215,
        not_in_percent: [Some(0.200), Some(0.223), None, Some(0.347)],
    },
    VolumeRow {
        map: "pc",
        volume_m3: 9651.058,
        not_in_percent: [Some(0.340), Some(0.370), Some(1.244), None],
    },
];

/// Table 6.4 (L7068–7086): explored volume of the PRM on the lab.
pub const TABLE_6_4_PRM: [VolumeRow; 4] = [
    VolumeRow {
        map: "planes",
        volume_m3: 11859.6544,
        not_in_percent: [None, Some(0.160), Some(0.737), Some(0.387)],
    },
    VolumeRow {
        map: "hybrid",
        volume_m3: 11841.7095,
        not_in_percent: [Some(0.008), None, Some(0.593), Some(0.251)],
    },
    VolumeRow {
        map: "trimesh",
        volume_m3: 11776.3023,
        not_in_percent: [Some(0.035), Some(0.041), None, Some(0.056)],
    },
    VolumeRow {
        map: "pc",
        volume_m3: 11818.7659,
        not_in_percent: [Some(0.042), Some(0.057), Some(0.416), None],
    },
];

/// Fig 6.4 (L6813–6818), RRT on the lab at K = 500: "less then \[sic\] 0.4 seconds" on the
/// planes and hybrid maps, s (an upper bound; the figure's values are not printed).
pub const FIG_6_4_PATCH_MAPS_BELOW_S: f64 = 0.4;

/// Fig 6.4 (L6813–6818), RRT on the lab at K = 500: "well over 4 seconds" on the trimesh and
/// point-cloud maps, s (a lower bound).
pub const FIG_6_4_SLOW_MAPS_ABOVE_S: f64 = 4.0;

/// A count as the thesis prints it: thousands separated by commas from 10,000 on ("5906",
/// "86,174", "5,600,612").
pub fn count_text(n: u64) -> String {
    let digits = n.to_string();
    if digits.len() < 5 {
        return digits;
    }
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Tables 6.2 and 6.4 as Markdown, in the layout of `roadmap::volume::CongruenceTable`'s
/// display: map, volume, then % not explored per column of [`LAB_MAPS`] ("–" on the diagonal).
pub fn volume_table_markdown(rows: &[VolumeRow]) -> String {
    let mut out = format!("| Map | Volume [m³] | {} |\n", LAB_MAPS.join(" | "));
    out.push_str(&format!("|---|---|{}\n", "---|".repeat(LAB_MAPS.len())));
    for r in rows {
        let cells: Vec<String> = r
            .not_in_percent
            .iter()
            .map(|c| c.map_or("–".to_owned(), |p| format!("{p:.3}")))
            .collect();
        out.push_str(&format!("| {} | {} | {} |\n", r.map, r.volume_m3, cells.join(" | ")));
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn counts_and_volume_tables_print_as_the_thesis_prints_them() {
        assert_eq!(count_text(5906), "5906");
        assert_eq!(count_text(17_273), "17,273");
        assert_eq!(count_text(5_600_612), "5,600,612");
        let t = volume_table_markdown(&TABLE_6_2_RRT);
        assert_eq!(t.lines().count(), 2 + TABLE_6_2_RRT.len());
        assert!(t.contains("| planes | 9714.015 | – | 0.557 | 1.739 | 0.986 |"), "{t}");
    }

    use super::*;

    const MEDIANS: [OfficeTable<f64>; 3] = [TABLE_5_3, TABLE_5_5, TABLE_5_10];
    const QUARTILES: [OfficeTable<QuartileRatios>; 3] = [TABLE_5_4, TABLE_5_6, TABLE_5_11];
    const TURNS: [OfficeTable<Turns>; 3] = [TABLE_5_7, TABLE_5_8, TABLE_5_9];

    fn dashes<T>(t: &OfficeTable<T>) -> Vec<(PlannerKind, usize)> {
        t.rows
            .iter()
            .flat_map(|r| (0..4).filter(|&c| r.cells[c].is_none()).map(move |c| (r.planner, c)))
            .collect()
    }

    #[test]
    fn office_tables_have_the_five_planners_and_opcodes_gaps() {
        // OPCODE (column 2) cannot run MA RRT, Evasion RRT or MA PRM (L6099–6103): exactly
        // those cells are "–" in every table.
        let expected = vec![(MaRrt, 2), (EvasionRrt, 2), (MaPrm, 2)];
        let first_five: Vec<PlannerKind> = PlannerKind::ALL[..5].to_vec();
        let mut numbers = Vec::new();
        let mut check =
            |number: &'static str, planners: Vec<PlannerKind>, gaps, lines: [u32; 2]| {
                assert_eq!(planners, first_five, "Table {number}");
                assert_eq!(gaps, expected, "Table {number}");
                assert!((6068..=6410).contains(&lines[0]) && lines[0] < lines[1], "Table {number}");
                numbers.push(number);
            };
        for t in &MEDIANS {
            check(t.number, t.rows.map(|r| r.planner).to_vec(), dashes(t), t.lines);
        }
        for t in &QUARTILES {
            check(t.number, t.rows.map(|r| r.planner).to_vec(), dashes(t), t.lines);
        }
        for t in &TURNS {
            check(t.number, t.rows.map(|r| r.planner).to_vec(), dashes(t), t.lines);
        }
        numbers.sort_by_key(|n| n[2..].parse::<u32>().unwrap());
        assert_eq!(numbers, ["5.3", "5.4", "5.5", "5.6", "5.7", "5.8", "5.9", "5.10", "5.11"]);
    }

    #[test]
    fn quartile_ratios_straddle_the_median_and_turn_ratios_match_their_counts() {
        for t in &QUARTILES {
            for r in &t.rows {
                for q in r.cells.iter().flatten() {
                    assert!(q.lower < 1.0 && q.upper > 1.0, "Table {} {}", t.number, r.label);
                }
            }
        }
        // The printed ratio is steep / total to the printed three decimals.
        for t in &TURNS {
            for r in &t.rows {
                for c in r.cells.iter().flatten() {
                    let quotient = f64::from(c.steep) / f64::from(c.total);
                    assert!(
                        (quotient - c.ratio).abs() <= 0.0015,
                        "Table {} {}: {}/{} = {quotient:.3}, printed {}",
                        t.number,
                        r.label,
                        c.steep,
                        c.total,
                        c.ratio
                    );
                }
            }
        }
        // The lower quartile is at most the median, the median at most the upper quartile.
        let rows = TABLE_5_8.rows.iter().zip(TABLE_5_7.rows.iter().zip(&TABLE_5_9.rows));
        for (lower, (median, upper)) in rows {
            for c in 0..4 {
                if let (Some(lo), Some(med), Some(up)) =
                    (lower.cells[c], median.cells[c], upper.cells[c])
                {
                    assert!(lo.total <= med.total && med.total <= up.total, "{}", median.label);
                    assert!(lo.steep <= med.steep && med.steep <= up.steep, "{}", median.label);
                }
            }
        }
    }

    #[test]
    fn cells_are_found_by_planner_and_column() {
        assert_eq!(TABLE_5_5.cell(Rrt, 2), Some(21.5803));
        assert_eq!(TABLE_5_5.cell(MaPrm, 3), Some(68.2961));
        assert_eq!(TABLE_5_5.cell(MaPrm, 2), None);
        assert_eq!(TABLE_5_5.cell(Rrt, 4), None, "no fifth column");
        assert_eq!(TABLE_5_5.cell(PlannerKind::RrtStar, 0), None, "not in the thesis");
        assert_eq!(TABLE_5_11.cell(MaRrt, 0), Some(QuartileRatios { lower: 0.791, upper: 1.048 }));
        // §7.15: the worst naive/Bullet time factor is Simple/MA PRM = 2.90, not the prose's 2.35.
        let f = TABLE_5_3.cell(MaPrm, 0).unwrap() / TABLE_5_3.cell(MaPrm, 3).unwrap();
        assert!((f - 2.897).abs() < 1e-3, "{f}");
    }

    #[test]
    fn lab_tables_are_consistent() {
        let mut maps: Vec<&str> = TABLE_6_1.iter().map(|r| r.map).collect();
        maps.sort_unstable();
        let mut expected = LAB_MAPS.to_vec();
        expected.sort_unstable();
        assert_eq!(maps, expected);
        // "18× smaller" (L108, L7643) = the pc file over the planes file.
        let size = |m: &str| TABLE_6_1.iter().find(|r| r.map == m).unwrap().file_size_mb;
        assert!((size("pc") / size("planes") - 18.0).abs() < 1e-9);
        for table in [TABLE_6_2_RRT, TABLE_6_4_PRM] {
            for (i, r) in table.iter().enumerate() {
                assert_eq!(r.map, LAB_MAPS[i]);
                assert!(r.volume_m3 > 9000.0);
                for (j, c) in r.not_in_percent.iter().enumerate() {
                    assert_eq!(c.is_none(), i == j, "{} column {j}", r.map);
                    assert!(c.is_none_or(|p| (0.0..2.0).contains(&p)));
                }
            }
        }
    }
}
