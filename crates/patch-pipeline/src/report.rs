//! The demo's self-contained HTML report: one page that opens in a browser without a server.
//! Pictures are inline SVG (map views, the Fig 6.4 plot) or PNG `data:` URIs (the Hough space,
//! the ToF outcomes, the explored-volume slice); there are no scripts, fonts or external
//! resources. Each section compares what the thesis shows (Ch. 2, 4, 5 and 6) with what this
//! run measured. A section whose data is missing renders as a "not computed" line.

mod encode;
mod html;
mod raster;
mod svg;

use crate::results::{
    DemoResults, MapDrawing, MapRow, PlanRun, TerrainSection, TofSection, VolumeSection,
};
use anyhow::Result;
use evaluation::stats::median;
use html::{DASH, bytes, esc, fixed, int, not_computed, para, seconds, sig, table, yes_no};
use roadmap::PlannerKind;
use std::fmt::Write as _;
use std::path::Path;

/// The section headings, in page order.
pub const SECTIONS: [&str; 10] = [
    "1. The run",
    "2. Map sizes",
    "3. Is the map safe?",
    "4. Planning",
    "5. The maps",
    "6. Explored volume",
    "7. Time against iterations",
    "8. Terrain",
    "9. Time-of-flight frame",
    "10. Files",
];

/// Width pictures are shown at, pixels.
const PICTURE_WIDTH: u32 = 800;

const STYLE: &str = "\
body{font-family:system-ui,sans-serif;margin:0;background:#fafafa;color:#222}\
main{max-width:1000px;margin:0 auto;padding:1em 1.5em 3em;background:#fff}\
h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:2em}\
p.caption{color:#333;max-width:60em}p.missing{color:#a33;font-style:italic}\
table{border-collapse:collapse;margin:.6em 0;font-size:.9em}\
th,td{border:1px solid #ccc;padding:.2em .5em}th{background:#f0f0f0}\
td{text-align:right}td.t{text-align:left}\
.pair{display:flex;flex-wrap:wrap;gap:2em;align-items:flex-start}\
.pair h3{font-size:1em;margin:.5em 0 0}\
figure{margin:1em 0}figcaption{font-size:.9em;color:#444}\
svg,img{max-width:100%;height:auto;border:1px solid #ddd}\
img.pixels{image-rendering:pixelated}\
ul.legend{list-style:none;padding:0;display:flex;flex-wrap:wrap;gap:.4em 1.4em;font-size:.9em}\
.sw{display:inline-block;width:1.1em;height:1.1em;vertical-align:-.2em;margin-right:.35em;border:1px solid #888}\
nav ol{columns:3;font-size:.9em}";

/// Writes `report.html` for `results` to `path`; errors name the file.
pub fn write(results: &DemoResults, path: &Path) -> Result<()> {
    pointcloud::io::write_bytes_atomically(path, render(results))?;
    Ok(())
}

/// The whole page for `results`.
pub fn render(results: &DemoResults) -> String {
    let scene = if results.scene.name.is_empty() {
        "no scene".to_owned()
    } else {
        results.scene.name.clone()
    };
    let mut page = String::with_capacity(1 << 16);
    let _ = write!(
        page,
        "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>patchnav {1}: {0}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<main>\n\
         <h1>patchnav {1}: {0}</h1>\n<nav><ol>",
        esc(&scene),
        esc(if results.command.is_empty() { "demo" } else { &results.command })
    );
    for (i, title) in SECTIONS.iter().enumerate() {
        let name = title.split_once(". ").map_or(*title, |(_, name)| name);
        let _ = write!(page, "<li><a href=\"#s{}\">{}</a></li>", i + 1, esc(name));
    }
    page.push_str("</ol></nav>\n");
    let bodies = [
        section_run(results),
        section_maps(results),
        section_safety(results),
        section_plans(results),
        section_pictures(results),
        section_volume(results.volume.as_ref()),
        section_timing(results),
        section_terrain(results.terrain.as_ref()),
        section_tof(results.tof.as_ref()),
        section_files(results),
    ];
    for (i, (title, body)) in SECTIONS.iter().zip(bodies).enumerate() {
        let _ = write!(
            page,
            "<section id=\"s{}\">\n<h2>{}</h2>\n{body}</section>\n",
            i + 1,
            esc(title)
        );
    }
    page.push_str("</main>\n</body>\n</html>\n");
    page
}

/// A `<p class="caption">` from plain text.
fn caption(text: &str) -> String {
    format!("<p class=\"caption\">{}</p>\n", esc(text))
}

/// A legend entry: a swatch of `colour` (CSS) and `label`.
fn legend_item(colour: &str, label: &str, round: bool) -> String {
    let radius = if round { "border-radius:50%;" } else { "" };
    format!(
        "<li><span class=\"sw\" style=\"background:{};{radius}\"></span>{}</li>",
        esc(colour),
        esc(label)
    )
}

/// An `<img>` of a PNG as a `data:` URI, shown `width` pixels wide.
fn png_img(png: &[u8], alt: &str, width: u32, pixelated: bool) -> String {
    let class = if pixelated { " class=\"pixels\"" } else { "" };
    format!(
        "<img{class} src=\"{}\" alt=\"{}\" width=\"{width}\">\n",
        encode::png_data_uri(png),
        esc(alt)
    )
}

/// Section 1: what ran.
fn section_run(r: &DemoResults) -> String {
    let mut out = String::new();
    let scale = match r.scale {
        Some(s) => format!("{s:?}").to_lowercase(),
        None => "unknown".to_owned(),
    };
    let s = &r.scene;
    let box_text = if s.min.iter().chain(&s.max).all(|v| v.is_finite()) && s.min != s.max {
        format!(
            "{} × {} × {} m",
            sig(s.max[0] - s.min[0], 3),
            sig(s.max[1] - s.min[1], 3),
            sig(s.max[2] - s.min[2], 3)
        )
    } else {
        DASH.to_owned()
    };
    out.push_str(&caption(&format!(
        "The thesis's Ch. 6 experiments run on the Lab dataset, 29 registered 3D scans of a room \
         (§6.1.3), turned into four map types and planned on with RRT and PRM (§6.1). This run \
         simulates the {} scene ({box_text}) scanned from {} sensor position(s), {} points in all, \
         and repeats the chain: ToF filtering (Ch. 2), terrain classification (Ch. 4), patch \
         extraction and maps (Ch. 3, 5), planning and explored volume (Ch. 6).",
        if s.name.is_empty() { "(unnamed)" } else { &s.name },
        s.scan_positions.len(),
        int(s.points as u64),
    )));
    out.push_str(&table(
        &["scale", "seed", "scene", "scene box", "scans", "points"],
        &[vec![
            scale,
            r.seed.to_string(),
            s.name.clone(),
            box_text,
            s.scan_positions.len().to_string(),
            int(s.points as u64),
        ]],
    ));
    if r.stages.is_empty() {
        out.push_str(&not_computed("Stage times"));
    } else {
        let mut rows: Vec<Vec<String>> =
            r.stages.iter().map(|st| vec![st.stage.clone(), seconds(st.seconds)]).collect();
        let total: f64 = r.stages.iter().map(|st| st.seconds).filter(|v| v.is_finite()).sum();
        rows.push(vec!["total".to_owned(), seconds(total)]);
        out.push_str(&table(&["stage", "wall time"], &rows));
    }
    out
}

/// The first row of `kind` with `value(row) > 0`.
fn first_positive(maps: &[MapRow], kind: &str, value: impl Fn(&MapRow) -> f64) -> Option<f64> {
    maps.iter().filter(|m| m.kind == kind).map(value).find(|v| *v > 0.0 && v.is_finite())
}

/// Section 2: map sizes (Table 6.1).
fn section_maps(r: &DemoResults) -> String {
    let mut out = String::new();
    let file = |m: &MapRow| m.file_bytes as f64;
    let memory = |m: &MapRow| m.memory_bytes as f64;
    let ratio = match (first_positive(&r.maps, "pc", file), first_positive(&r.maps, "planes", file))
    {
        (Some(pc), Some(planes)) => Some(("file", pc / planes)),
        _ => {
            match (first_positive(&r.maps, "pc", memory), first_positive(&r.maps, "planes", memory))
            {
                (Some(pc), Some(planes)) => Some(("in-memory", pc / planes)),
                _ => None,
            }
        }
    };
    let ours = match ratio {
        Some((what, k)) if k >= 1.0 => format!(
            "Here the planes map's {what} size is {}× smaller than the pc map's.",
            sig(k, 2)
        ),
        Some((what, k)) => format!(
            "Here the planes map's {what} size is {}× larger than the pc map's.",
            sig(1.0 / k, 2)
        ),
        None => "Here the pc/planes ratio is not available (a map is missing or empty).".to_owned(),
    };
    out.push_str(&caption(&format!(
        "Thesis Table 6.1 lists the file sizes and contents of the four Lab maps: the planes map \
         (3.0 MB) is 18× smaller than the point-cloud map (54.0 MB) and 35× smaller than the \
         trimesh map (106.4 MB); the hybrid map adds trimeshes of the non-planar remainder. {ours} \
         Our table also gives the memory each backend holds and the build time; the pc column \
         counts points, where the thesis counts point clouds."
    )));
    out.push_str("<div class=\"pair\">\n<div><h3>This run</h3>\n");
    if r.maps.is_empty() {
        out.push_str(&not_computed("Maps"));
    } else {
        let rows: Vec<Vec<String>> = r
            .maps
            .iter()
            .map(|m| {
                vec![
                    m.kind.clone(),
                    m.backend.clone(),
                    if m.file_bytes > 0 { bytes(m.file_bytes) } else { DASH.to_owned() },
                    int(m.planar_patches as u64),
                    int(m.trimesh_patches as u64),
                    int(m.points as u64),
                    int(m.triangles as u64),
                    bytes(m.memory_bytes as u64),
                    seconds(m.build_seconds),
                ]
            })
            .collect();
        out.push_str(&table(
            &[
                "map",
                "backend",
                "file size",
                "planar patches",
                "trimesh patches",
                "points (pc)",
                "triangles",
                "memory",
                "build time",
            ],
            &rows,
        ));
    }
    out.push_str("</div>\n<div><h3>Thesis Table 6.1 (Lab)</h3>\n");
    let count = |n: Option<u32>| n.map_or(DASH.to_owned(), int);
    let rows: Vec<Vec<String>> = evaluation::thesis::TABLE_6_1
        .iter()
        .map(|r| {
            vec![
                r.map.to_owned(),
                format!("{:.1} MB", r.file_size_mb),
                count(r.planar_patches),
                count(r.trimesh_patches),
                count(r.point_clouds),
                count(r.triangles),
            ]
        })
        .collect();
    out.push_str(&table(
        &["map", "file size", "planar patches", "trimesh patches", "point clouds", "triangles"],
        &rows,
    ));
    out.push_str("</div>\n</div>\n");
    out
}

/// Distinct values of `key` over `plans`, in first-seen order.
fn distinct<'a>(plans: &'a [PlanRun], key: impl Fn(&'a PlanRun) -> &'a str) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for p in plans {
        let k = key(p);
        if !out.contains(&k) {
            out.push(k);
        }
    }
    out
}

/// Section 4: planning runs.
fn section_plans(r: &DemoResults) -> String {
    let mut out = String::new();
    let solved = r.plans.iter().filter(|p| p.solved).count();
    let mut medians = Vec::new();
    for planner in distinct(&r.plans, |p| &p.planner) {
        for map in distinct(&r.plans, |p| &p.map) {
            let times =
                r.plans.iter().filter(|p| p.planner == planner && p.map == map).map(|p| p.seconds);
            if let Some(m) = median(times) {
                medians.push(format!("{planner} on {map} {}", seconds(m)));
            }
        }
    }
    let ours = if r.plans.is_empty() {
        String::new()
    } else {
        format!(
            " Here {solved} of {} runs reached every goal; median wall time per planner and map: {}.",
            r.plans.len(),
            medians.join(", ")
        )
    };
    out.push_str(&caption(&format!(
        "The thesis compares planners and collision backends by path quality (Ch. 5, Tables 5.7–5.11: \
         steep turns over 90° and curviness, the upper quartile of turn angles, on paths to the regions \
         of interest) and map types by time and explored volume (Ch. 6). Each row is one run: \
         iterations are samples drawn, vertices the roadmap size, collision checks the step tests \
         asked of the map.{ours}"
    )));
    if r.plans.is_empty() {
        out.push_str(&not_computed("Planning runs"));
        return out;
    }
    let rows: Vec<Vec<String>> = r
        .plans
        .iter()
        .map(|p| {
            vec![
                p.map.clone(),
                p.backend.clone(),
                p.planner.clone(),
                p.seed.to_string(),
                yes_no(p.solved).to_owned(),
                seconds(p.seconds),
                int(p.iterations),
                int(p.vertices as u64),
                int(p.collision_checks),
                format!("{} m", sig(p.path_length, 3)),
                int(p.turns as u64),
                int(p.steep_turns as u64),
                format!("{}°", fixed(p.curviness_deg, 1)),
            ]
        })
        .collect();
    out.push_str(&table(
        &[
            "map",
            "backend",
            "planner",
            "seed",
            "solved",
            "time",
            "iterations",
            "vertices",
            "collision checks",
            "path length",
            "turns",
            "steep turns",
            "curviness",
        ],
        &rows,
    ));
    out
}

/// Section 5: top and perspective views of each map type.
fn section_pictures(r: &DemoResults) -> String {
    let mut out = String::new();
    out.push_str(&caption(
        "Thesis Fig 6.3 shows the Lab planes map in perspective wire-frame, surface, top and inside \
         views, with the robot location marked; Fig 6.6 draws an RRT of 100 iterations in the hybrid \
         map. Here each map type is drawn from above (orthographic, x to the right, y up) and in \
         perspective from a fixed camera above the scene's (min x, min y) corner looking at its \
         centre, faces shaded by orientation and painted far to near. Over the map: the roadmap \
         edges (faint) and paths (bold) of the first run of each planner on that map, the start, \
         the goals and the scan positions. Geometry is decimated for drawing; the 3D files hold all of it.",
    ));
    if r.drawings.is_empty() {
        out.push_str(&not_computed("Map pictures"));
        return out;
    }
    out.push_str("<ul class=\"legend\">");
    out.push_str(&legend_item(&raster::hex(svg::colours::POLYGON), "planar patch", false));
    out.push_str(&legend_item(&raster::hex(svg::colours::TRIANGLE), "triangle", false));
    out.push_str(&legend_item(svg::colours::POINT, "point", true));
    out.push_str(&legend_item(svg::colours::SCAN, "scan position", true));
    out.push_str(&legend_item(svg::colours::START, "start", true));
    out.push_str(&legend_item(svg::colours::GOAL, "goal", false));
    for planner in distinct(&r.plans, |p| &p.planner) {
        out.push_str(&legend_item(
            svg::planner_colour(planner),
            &format!("{planner} roadmap and path"),
            false,
        ));
    }
    out.push_str("</ul>\n");
    for d in &r.drawings {
        out.push_str(&map_pictures(r, d));
    }
    out
}

/// The two views of one map type.
fn map_pictures(r: &DemoResults, d: &MapDrawing) -> String {
    let mut out = String::new();
    let mut shown: Vec<&PlanRun> = Vec::new();
    for p in r.plans.iter().filter(|p| p.map == d.kind) {
        if !shown.iter().any(|s| s.planner == p.planner) {
            shown.push(p);
        }
    }
    let overlay = svg::Overlay { scan_positions: &r.scene.scan_positions, plans: &shown };
    let bounds = svg::view_bounds(d, (&r.scene.min, &r.scene.max), &overlay);
    let _ = writeln!(
        out,
        "<h3>{} map</h3>\n<p>{} polygons, {} triangles, {} points drawn; {} run(s) overlaid.</p>",
        esc(&d.kind),
        int(d.polygons.len() as u64),
        int(d.triangles.len() as u64),
        int(d.points.len() as u64),
        shown.len()
    );
    let _ = write!(
        out,
        "<figure>\n{}<figcaption>Top view of the {} map.</figcaption>\n</figure>\n",
        svg::top_view(d, &overlay),
        esc(&d.kind)
    );
    let _ = write!(
        out,
        "<figure>\n{}<figcaption>Perspective view of the {} map.</figcaption>\n</figure>\n",
        svg::perspective_view(d, &overlay, &bounds),
        esc(&d.kind)
    );
    out
}

/// Section 3: each map against the exact scene, with where the unsafe steps hit.
fn section_safety(r: &DemoResults) -> String {
    let mut out = String::new();
    let Some(s) = &r.safety else {
        out.push_str(&not_computed("Map safety"));
        return out;
    };
    out.push_str(&caption(&format!(
        "The thesis judges its maps by planning on them (Tables 6.2, 6.4). A robot needs more:          a map must not call a colliding step free. Each map is compared with the scene's exact          surfaces over {} random steps of a sphere of radius {} m moved up to {} m in the room.          Unsafe: colliding steps the map calls free, of all truly colliding steps; overcautious:          free steps the map blocks, of all truly free steps; each with its 95 % Wilson interval.          The pc map's unsafe rate is the occlusion floor: what no scan saw. `patchnav experiment          map-safety` runs the same check on more scenes, noise levels and scan counts.",
        int(s.samples),
        fixed(s.radius, 2),
        fixed(s.max_length, 1)
    )));
    let pct = |v: &[f64; 3]| format!("{} [{}, {}]", fixed(v[0], 2), fixed(v[1], 2), fixed(v[2], 2));
    let rows: Vec<Vec<String>> = s
        .rows
        .iter()
        .map(|m| {
            vec![
                m.map.clone(),
                pct(&m.unsafe_pct),
                format!("{} of {}", int(m.unsafe_steps[0]), int(m.unsafe_steps[1])),
                pct(&m.overcautious_pct),
            ]
        })
        .collect();
    out.push_str(&table(&["map", "unsafe %", "unsafe steps", "overcautious %"], &rows));
    let none: [&PlanRun; 0] = [];
    let overlay = svg::Overlay { scan_positions: &r.scene.scan_positions, plans: &none };
    for m in s.rows.iter().filter(|m| !m.unsafe_hits.is_empty()) {
        let d = MapDrawing {
            kind: format!("exact scene with the {} map's unsafe steps", m.map),
            polygons: s.truth.polygons.clone(),
            triangles: Vec::new(),
            points: m.unsafe_hits.clone(),
        };
        let _ = write!(
            out,
            "<figure>\n{}<figcaption>The {} map: where its unsafe steps first touch the exact \
             scene (dots, {} drawn), over the scene's planar surfaces seen from above.</figcaption>\n</figure>\n",
            svg::top_view(&d, &overlay),
            esc(&m.map),
            int(m.unsafe_hits.len() as u64)
        );
    }
    out
}

/// Section 6: explored volume (Table 6.2, Fig 6.1).
fn section_volume(vol: Option<&VolumeSection>) -> String {
    let mut out = String::new();
    let largest = vol.and_then(VolumeSection::largest_difference);
    let ours = match (vol, largest) {
        (Some(v), Some((x, a, b))) => format!(
            " Here{}, on cells of {} m, the largest difference is {} % of the {a} map's explored \
             volume not explored on the {b} map.",
            runs_text(v),
            sig(v.cell, 3),
            sig(x, 3)
        ),
        _ => String::new(),
    };
    out.push_str(&caption(&format!(
        "Thesis §6.1.1 measures how much of the space a planner explored (its roadmap entered as \
         spheres and cylinders into an octree of 38.684 mm cells) and compares map types by the \
         volume explored on one but not the other; Table 6.2 gives, for the RRT on the Lab map, \
         the % of the row map's volume that the column map's runs did not reach: at most 1.739 % \
         (planes not in trimesh), so all four maps let the planner explore nearly the same space, \
         the trimesh map the least. Fig 6.1 shows a cross-section near the floor.{ours}"
    )));
    let Some(v) = vol else {
        out.push_str(&not_computed("Explored volume"));
        return out;
    };
    out.push_str(
        "<div class=\"pair\">\n<div><h3>This run: % of the row's volume not in the column's</h3>\n",
    );
    if v.maps.is_empty() {
        out.push_str(&not_computed("Volume table"));
    } else {
        let mut headers = vec!["map".to_owned(), "volume [m³]".to_owned()];
        headers.extend(v.maps.iter().map(|m| format!("not in {m} [%]")));
        let rows: Vec<Vec<String>> = v
            .maps
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let mut row =
                    vec![m.clone(), v.volumes_m3.get(i).map_or(DASH.to_owned(), |x| fixed(*x, 3))];
                for j in 0..v.maps.len() {
                    let cell = v.table.get(i).and_then(|r| r.get(j)).copied().flatten();
                    row.push(cell.map_or(DASH.to_owned(), |x| fixed(x, 3)));
                }
                row
            })
            .collect();
        let header_refs: Vec<&str> = headers.iter().map(String::as_str).collect();
        out.push_str(&table(&header_refs, &rows));
    }
    let (thesis, title) = if matches!(v.planner.parse(), Ok(PlannerKind::Prm)) {
        (&evaluation::thesis::TABLE_6_4_PRM, "Thesis Table 6.4 (PRM, Lab)")
    } else {
        (&evaluation::thesis::TABLE_6_2_RRT, "Thesis Table 6.2 (RRT, Lab)")
    };
    let _ = write!(out, "</div>\n<div><h3>{title}</h3>\n");
    let rows: Vec<Vec<String>> = thesis
        .iter()
        .map(|r| {
            let mut row = vec![r.map.to_owned(), fixed(r.volume_m3, 3)];
            row.extend(r.not_in_percent.iter().map(|c| c.map_or(DASH.to_owned(), |p| fixed(p, 3))));
            row
        })
        .collect();
    out.push_str(&table(
        &["map", "volume [m³]", "not in planes", "not in hybrid", "not in trimesh", "not in pc"],
        &rows,
    ));
    out.push_str("</div>\n</div>\n");
    match raster::slice_image(v) {
        Err(raster::Unusable(why)) => {
            out.push_str(&para(&format!("Slice picture not drawn: {why}.")))
        }
        Ok((img, keys)) => {
            let [w, h] = v.slice_size;
            let factor = (PICTURE_WIDTH / w.max(h)).clamp(1, 16);
            match img.scaled(factor).to_png() {
                Err(e) => out.push_str(&para(&format!("Slice picture not encoded: {e}."))),
                Ok(png) => {
                    let shown = (w * factor).min(PICTURE_WIDTH);
                    let x1 = v.slice_origin[0] + f64::from(w) * v.cell;
                    let y1 = v.slice_origin[1] + f64::from(h) * v.cell;
                    let _ = write!(
                        out,
                        "<figure>\n{}<figcaption>Cross-section at z = {} m, x from {} to {} m (left to right), \
                         y from {} to {} m (bottom to top), {} × {} cells of {} m.</figcaption>\n</figure>\n",
                        png_img(&png, "explored-volume slice", shown, true),
                        sig(v.slice_z, 3),
                        sig(v.slice_origin[0], 3),
                        sig(x1, 3),
                        sig(v.slice_origin[1], 3),
                        sig(y1, 3),
                        w,
                        h,
                        sig(v.cell, 3)
                    );
                    out.push_str("<ul class=\"legend\">");
                    for k in &keys {
                        let names: Vec<&str> = (0..v.maps.len().min(8))
                            .filter(|i| k.bits & (1 << i) != 0)
                            .map(|i| v.maps[i].as_str())
                            .collect();
                        let label = match names.len() {
                            0 => "not explored".to_owned(),
                            n if n == v.maps.len() => "explored on every map".to_owned(),
                            1 => format!("only on {}", names[0]),
                            _ => format!("on {} only", names.join(" + ")),
                        };
                        let label = format!("{label} ({} cells)", int(k.cells as u64));
                        out.push_str(&legend_item(&raster::hex(k.colour), &label, false));
                    }
                    out.push_str("</ul>\n");
                }
            }
        }
    }
    out
}

/// What the volume's roadmaps were (` (RRT, 8 runs per map of 3,000 iterations)`), empty
/// when the results do not say.
fn runs_text(v: &VolumeSection) -> String {
    if v.planner.is_empty() || v.runs == 0 {
        return String::new();
    }
    format!(
        " ({}, {} run{} per map of {} iterations)",
        esc(&v.planner.to_uppercase()),
        int(v.runs as u64),
        if v.runs == 1 { "" } else { "s" },
        int(v.iterations)
    )
}

/// Section 7: time against iterations (Fig 6.4).
fn section_timing(r: &DemoResults) -> String {
    let mut out = String::new();
    let mut last: Vec<(f64, String)> = r
        .timing
        .iter()
        .filter_map(|c| {
            let n = c.iterations.len().min(c.median_ms.len());
            (n > 0).then(|| {
                (
                    c.median_ms[n - 1],
                    format!(
                        "{} {} ms at {} iterations",
                        c.map,
                        sig(c.median_ms[n - 1], 3),
                        int(c.iterations[n - 1])
                    ),
                )
            })
        })
        .collect();
    last.sort_by(|a, b| a.0.total_cmp(&b.0));
    let ours = if last.is_empty() {
        String::new()
    } else {
        format!(
            " Here the median at the last checkpoint, fastest first: {}.",
            last.iter().map(|l| l.1.as_str()).collect::<Vec<_>>().join(", ")
        )
    };
    out.push_str(&caption(&format!(
        "Thesis Fig 6.4 plots the time of one RRT run against the number of iterations on the four \
         Lab maps (median line, quartile error bars, log time axis; 4 starts × 24 seeds): the trimesh \
         and point-cloud maps are more than an order of magnitude slower than the planes and hybrid \
         maps, and the trimesh map varies most.{ours}"
    )));
    match svg::time_plot(&r.timing) {
        Some(plot) => {
            let _ = write!(
                out,
                "<figure>\n{plot}<figcaption>Median time per run (line) and quartiles (band and bars) \
                 against iterations, per map type.</figcaption>\n</figure>\n"
            );
        }
        None => out.push_str(&not_computed("Time against iterations")),
    }
    out
}

/// Section 8: terrain classification (Ch. 4).
fn section_terrain(t: Option<&TerrainSection>) -> String {
    let mut out = String::new();
    let ours = t.map_or(String::new(), |t| {
        let verdict = if t.class == t.truth { "matching" } else { "not matching" };
        format!(
            " Here the {} snapshot ({} points) is classified by the ground-ahead rule (what stands on \
             the ground, the surface ahead, where the ground drops away; Algorithm 3 stays available \
             as `--method thesis`) as {}, {verdict} the truth ({}), in {} ms.",
            t.scene,
            int(t.points as u64),
            t.class,
            t.truth,
            sig(t.millis, 3)
        )
    });
    out.push_str(&caption(&format!(
        "Thesis Ch. 4 classifies a range snapshot by the strongest planes of a 3D Hough transform \
         over (ρx, ρy, d). Fig 4.3 shows the parameter space flattened: distances on the y-axis, \
         angles on the x-axis with ρy iterating once and ρx repeatedly, darker bins with fewer \
         hits; Table 4.3 reports drivability success rates of 0.83–1.0 in 4–53 ms.{ours}"
    )));
    let Some(t) = t else {
        out.push_str(&not_computed("Terrain"));
        return out;
    };
    if encode::is_png(&t.hough_png) {
        let _ = write!(
            out,
            "<figure>\n{}<figcaption>Hough space of the {} snapshot (Fig 4.3 layout).</figcaption>\n</figure>\n",
            png_img(&t.hough_png, "Hough space", PICTURE_WIDTH, true),
            esc(&t.scene)
        );
    } else {
        out.push_str(&not_computed("Hough-space picture"));
    }
    out.push_str(&table(
        &["scene", "truth", "class", "drivable", "ρx", "ρy", "d", "resolution", "points", "time"],
        &[vec![
            t.scene.clone(),
            t.truth.clone(),
            t.class.clone(),
            yes_no(t.drivable).to_owned(),
            format!("{}°", fixed(t.plane[0], 1)),
            format!("{}°", fixed(t.plane[1], 1)),
            format!("{} m", sig(t.plane[2], 3)),
            format!("{}°", sig(t.resolution_deg, 3)),
            int(t.points as u64),
            format!("{} ms", sig(t.millis, 3)),
        ]],
    ));
    if t.sectors.is_empty() {
        out.push_str(&not_computed("Sectors"));
    } else {
        let names = ["left", "centre", "right"];
        let rows: Vec<Vec<String>> = t
            .sectors
            .iter()
            .enumerate()
            .map(|(i, (class, drivable))| {
                let name =
                    names.get(i).map_or_else(|| format!("sector {}", i + 1), |n| (*n).to_owned());
                vec![name, class.clone(), yes_no(*drivable).to_owned()]
            })
            .collect();
        out.push_str(&table(&["sector", "class", "drivable"], &rows));
    }
    if let Some(g) = &t.ground {
        out.push_str(&caption(
            "Per-point ground (not in the thesis): every point labelled drivable ground or not,              from local ground planes within Rugbot's 0.2 m step and 35° slope limits; scored              against the scene's drivable surfaces.",
        ));
        out.push_str(&table(
            &["ground share", "precision", "recall", "F1", "time"],
            &[vec![
                format!("{} %", fixed(100.0 * g.share, 1)),
                fixed(g.precision, 3),
                fixed(g.recall, 3),
                fixed(g.f1, 3),
                format!("{} ms", sig(g.millis, 3)),
            ]],
        ));
    }
    out
}

/// Section 9: the ToF frame (§2.5).
fn section_tof(t: Option<&TofSection>) -> String {
    let mut out = String::new();
    let ours = t.map_or(String::new(), |t| {
        if !t.wrapped_percent.is_finite() {
            // A real frame: no truth to score against.
            return format!(
                " Here {} on the frame {} discards {} % of the pixels (no ground truth to tell \
                 right from wrong).",
                t.method,
                t.scene,
                fixed(t.discarded_percent, 1)
            );
        }
        format!(
            " Here {} on the simulated {} scene discards {} % of the pixels; {} % of the pixels were \
             wrapped, {} % of those are put back within 5 cm, {} % of the output is wrong, and the \
             yield (correct output pixels per measured pixel) is {} %.",
            t.method,
            t.scene,
            fixed(t.discarded_percent, 1),
            fixed(t.wrapped_percent, 1),
            fixed(t.unwrapped_correct_percent, 1),
            fixed(t.wrong_percent, 2),
            fixed(t.yield_percent, 1)
        )
    });
    out.push_str(&caption(&format!(
        "Thesis §2.5 filters SwissRanger frames with an adaptive amplitude threshold and unwraps \
         pixels beyond the 7.5 m non-ambiguity range instead of discarding them; Table 2.4 reports \
         the discarded pixels on six scenes: 31.8 % on average with the proposed method against \
         53.1 % and 68.5 % for the camera's fixed thresholds AT 160 and AT 240 (Fig 2.17 shows the \
         images).{ours}"
    )));
    let Some(t) = t else {
        out.push_str(&not_computed("Time-of-flight frame"));
        return out;
    };
    match raster::tof_image(t) {
        Err(raster::Unusable(why)) => {
            out.push_str(&para(&format!("Outcome picture not drawn: {why}.")))
        }
        Ok((img, max_range)) => match img.scaled(3).to_png() {
            Err(e) => out.push_str(&para(&format!("Outcome picture not encoded: {e}."))),
            Ok(png) => {
                let _ = write!(
                    out,
                    "<figure>\n{}<figcaption>Pixel outcomes of the {} × {} frame, 3× enlarged.</figcaption>\n</figure>\n",
                    png_img(&png, "ToF pixel outcomes", img.width * 3, true),
                    t.width,
                    t.height
                );
                let count = |code: u8| t.outcomes.iter().filter(|&&o| o == code).count() as u64;
                let grey = raster::tof_colour(raster::TOF_KEPT, 0.3 * max_range, max_range);
                let blue = raster::tof_colour(raster::TOF_UNWRAPPED, 0.3 * max_range, max_range);
                out.push_str("<ul class=\"legend\">");
                out.push_str(&legend_item(
                    &raster::hex(grey),
                    &format!(
                        "kept, grey by range: light near, dark at {} m ({})",
                        sig(f64::from(max_range), 3),
                        int(count(raster::TOF_KEPT))
                    ),
                    false,
                ));
                out.push_str(&legend_item(
                    &raster::hex(blue),
                    &format!("unwrapped, blue by range ({})", int(count(raster::TOF_UNWRAPPED))),
                    false,
                ));
                out.push_str(&legend_item(
                    &raster::hex(raster::TOF_DROPPED_RGB),
                    &format!("dropped ({})", int(count(raster::TOF_DROPPED))),
                    false,
                ));
                let other = t.outcomes.len() as u64
                    - count(raster::TOF_KEPT)
                    - count(raster::TOF_UNWRAPPED)
                    - count(raster::TOF_DROPPED);
                out.push_str(&legend_item(
                    &raster::hex(raster::TOF_NONE_RGB),
                    &format!("no measurement ({})", int(other)),
                    false,
                ));
                out.push_str("</ul>\n");
            }
        },
    }
    out.push_str(&table(
        &[
            "scene",
            "method",
            "discarded",
            "wrapped",
            "unwrapped correctly",
            "wrong",
            "yield",
            "time",
        ],
        &[vec![
            t.scene.clone(),
            t.method.clone(),
            format!("{} %", fixed(t.discarded_percent, 1)),
            format!("{} %", fixed(t.wrapped_percent, 1)),
            format!("{} %", fixed(t.unwrapped_correct_percent, 1)),
            format!("{} %", fixed(t.wrong_percent, 2)),
            format!("{} %", fixed(t.yield_percent, 1)),
            format!("{} ms", sig(t.millis, 3)),
        ]],
    ));
    out
}

/// Section 10: the files written.
fn section_files(r: &DemoResults) -> String {
    let mut out = String::new();
    out.push_str(&caption(
        "The 3D files hold the full geometry the pictures above decimate. Open PLY, OBJ and PCD \
         files in MeshLab or CloudCompare (File → Open; several at once overlay in one scene) or \
         import PLY and OBJ into Blender (File → Import). Links are relative to this page, so keep \
         the folder together.",
    ));
    if r.files.is_empty() {
        out.push_str(&not_computed("Files"));
        return out;
    }
    out.push_str("<ul>\n");
    for f in &r.files {
        let _ = writeln!(
            out,
            "<li><a href=\"{}\">{}</a>: {} ({})</li>",
            esc(&html::href(&f.path)),
            esc(&f.path),
            esc(&f.label),
            bytes(f.bytes)
        );
    }
    out.push_str("</ul>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::*;
    use crate::results::{MapSafety, SafetySection};

    fn plan(map: &str, planner: &str, solved: bool) -> PlanRun {
        PlanRun {
            map: map.into(),
            backend: "polygon".into(),
            planner: planner.into(),
            seed: 3,
            solved,
            seconds: 0.042,
            iterations: 1200,
            vertices: 340,
            collision_checks: 5600,
            path_length: 12.345,
            turns: 7,
            steep_turns: 1,
            curviness_deg: 33.3,
            start: [1.0, 1.0, 1.0],
            goals: vec![[8.0, 5.0, 1.2], [2.0, 6.0, 1.0]],
            paths: vec![vec![[1.0, 1.0, 1.0], [4.0, 2.0, 1.1], [8.0, 5.0, 1.2]]],
            edges: vec![[[1.0, 1.0, 1.0], [4.0, 2.0, 1.1]], [[4.0, 2.0, 1.1], [8.0, 5.0, 1.2]]],
        }
    }

    fn tiny_png() -> Vec<u8> {
        encode::Rgb::filled(2, 2, [9, 9, 9]).to_png().unwrap()
    }

    /// A results set touching every section.
    fn synthetic() -> DemoResults {
        let maps = ["planes", "hybrid", "trimesh", "pc"];
        DemoResults {
            command: "demo".into(),
            scale: Some(Scale::Quick),
            seed: 7,
            stages: vec![
                StageTime { stage: "simulate".into(), seconds: 0.5 },
                StageTime { stage: "plan".into(), seconds: 1.25 },
            ],
            scene: SceneInfo {
                name: "lab<script>".into(),
                min: [0.0, 0.0, 0.0],
                max: [10.0, 7.0, 3.0],
                scan_positions: vec![[5.0, 3.5, 1.0], [2.0, 2.0, 1.0]],
                points: 123_456,
            },
            tof: Some(TofSection {
                scene: "Rack and door".into(),
                width: 16,
                height: 8,
                outcomes: (0..128).map(|i| (i % 4) as u8).collect(),
                radial: (0..128).map(|i| i as f32 * 0.1).collect(),
                method: "AAT+unwrap".into(),
                discarded_percent: 16.7,
                wrapped_percent: 12.0,
                unwrapped_correct_percent: 97.5,
                wrong_percent: 0.31,
                yield_percent: 80.5,
                millis: 1.9,
            }),
            terrain: Some(TerrainSection {
                scene: "terrain-ramp".into(),
                truth: "ramp".into(),
                class: "ramp".into(),
                drivable: true,
                plane: [12.0, -3.0, 0.4],
                resolution_deg: 3.0,
                millis: 4.2,
                points: 20_000,
                hough_png: tiny_png(),
                sectors: vec![
                    ("ramp".into(), true),
                    ("floor".into(), true),
                    ("step".into(), false),
                ],
                ground: Some(crate::results::GroundScore {
                    share: 0.6,
                    precision: 0.99,
                    recall: 0.98,
                    f1: 0.985,
                    millis: 0.4,
                }),
            }),
            maps: maps
                .iter()
                .enumerate()
                .map(|(i, k)| MapRow {
                    kind: (*k).into(),
                    backend: "bbox_kd".into(),
                    planar_patches: 100 * i,
                    trimesh_patches: 10 * i,
                    triangles: 1000 * i,
                    points: if *k == "pc" { 50_000 } else { 0 },
                    memory_bytes: 1_000_000 * (i + 1),
                    file_bytes: if *k == "pc" { 5_400_000 } else { 300_000 * (i as u64 + 1) },
                    build_seconds: 0.2,
                })
                .collect(),
            drawings: maps
                .iter()
                .map(|k| MapDrawing {
                    kind: (*k).into(),
                    polygons: vec![vec![
                        [0.0, 0.0, 0.0],
                        [10.0, 0.0, 0.0],
                        [10.0, 7.0, 0.0],
                        [0.0, 7.0, 0.0],
                    ]],
                    triangles: vec![[[0.0, 0.0, 0.0], [0.0, 7.0, 0.0], [0.0, 7.0, 3.0]]],
                    points: vec![[5.0, 5.0, 1.5], [6.0, 1.0, 2.0]],
                })
                .collect(),
            plans: vec![plan("hybrid", "rrt", true), plan("hybrid", "prm", false)],
            timing: maps
                .iter()
                .enumerate()
                .map(|(i, k)| TimingCurve {
                    map: (*k).into(),
                    iterations: vec![100, 500, 1000],
                    median_ms: vec![
                        0.1 * (i + 1) as f64,
                        0.5 * (i + 1) as f64,
                        1.0 * (i + 1) as f64,
                    ],
                    q1_ms: vec![0.08, 0.4, 0.8],
                    q3_ms: vec![0.2 * (i + 1) as f64, 0.9 * (i + 1) as f64, 2.0 * (i + 1) as f64],
                })
                .collect(),
            volume: Some(VolumeSection {
                planner: "rrt".into(),
                runs: 8,
                iterations: 1000,
                cell: 0.1,
                maps: maps.iter().map(|s| (*s).into()).collect(),
                volumes_m3: vec![400.0, 399.0, 395.5, 401.2],
                table: (0..4)
                    .map(|i| (0..4).map(|j| (i != j).then_some(0.1 * (i + j) as f64)).collect())
                    .collect(),
                slice_z: 0.3,
                slice_origin: [0.0, 0.0],
                slice_size: [10, 7],
                slice_bits: (0..70).map(|i| (i % 16) as u8).collect(),
            }),
            safety: Some(SafetySection {
                samples: 1000,
                radius: 0.3,
                max_length: 1.0,
                truth: MapDrawing {
                    kind: "planes".into(),
                    polygons: vec![vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [4.0, 3.0, 0.0]]],
                    triangles: Vec::new(),
                    points: Vec::new(),
                },
                rows: maps
                    .iter()
                    .map(|m| MapSafety {
                        map: (*m).into(),
                        unsafe_pct: [1.0, 0.5, 1.5],
                        overcautious_pct: [2.0, 1.5, 2.5],
                        unsafe_steps: [4, 400],
                        unsafe_hits: vec![[1.0, 1.0, 0.7], [2.0, 1.0, 0.0]],
                    })
                    .collect(),
            }),
            files: vec![
                FileEntry {
                    label: "hybrid map".into(),
                    path: "maps/hybrid.ply".into(),
                    bytes: 12_345,
                },
                FileEntry { label: "odd".into(), path: "a b&c.obj".into(), bytes: 10 },
            ],
        }
    }

    /// Every `data:image/png;base64,` payload.
    fn png_payloads(page: &str) -> Vec<Vec<u8>> {
        let marker = "data:image/png;base64,";
        page.match_indices(marker)
            .map(|(i, _)| {
                let rest = &page[i + marker.len()..];
                let end = rest.find('"').expect("payload ends at a quote");
                encode::tests::decode_base64(&rest[..end]).expect("payload is base64")
            })
            .collect()
    }

    fn assert_balanced(page: &str) {
        for tag in ["svg", "table", "section", "figure", "ul", "tr", "p"] {
            let open = page.matches(&format!("<{tag}>")).count()
                + page.matches(&format!("<{tag} ")).count();
            let close = page.matches(&format!("</{tag}>")).count();
            assert_eq!(open, close, "<{tag}> opened {open} times, closed {close} times");
        }
    }

    #[test]
    fn full_report_has_every_section_and_valid_images() {
        let page = render(&synthetic());
        assert!(page.starts_with("<!doctype html>") && page.ends_with("</html>\n"));
        assert_balanced(&page);
        for title in SECTIONS {
            assert!(page.contains(&format!("<h2>{}</h2>", esc(title))), "{title} missing");
        }
        assert!(!page.contains("not computed"), "every section has data");
        // Four map types × two views + the time plot + four safety pictures.
        assert_eq!(page.matches("<svg").count(), 13);
        let pngs = png_payloads(&page);
        // Hough, slice, ToF.
        assert_eq!(pngs.len(), 3);
        for png in &pngs {
            assert!(encode::is_png(png));
        }
        // The ToF picture is the 16×8 frame scaled 3×.
        let tof = pngs.iter().find(|p| {
            p.len() > 8 && {
                let info =
                    png::Decoder::new(std::io::Cursor::new(p.as_slice())).read_info().unwrap();
                (info.info().width, info.info().height) == (48, 24)
            }
        });
        assert!(tof.is_some(), "48 × 24 ToF picture");
        assert!(page.contains("18×") && page.contains("9,714.015"), "thesis tables");
        assert!(page.contains("<a href=\"a%20b%26c.obj\">a b&amp;c.obj</a>"), "escaped link");
        assert!(!page.contains("NaN") && !page.contains("<script"));
    }

    #[test]
    fn scene_names_are_escaped() {
        let page = render(&synthetic());
        assert!(page.contains("lab&lt;script&gt;"));
        assert!(!page.contains("lab<script>"));
    }

    #[test]
    fn empty_results_render_not_computed_lines() {
        let page = render(&DemoResults::default());
        assert_balanced(&page);
        for title in SECTIONS {
            assert!(page.contains(&format!("<h2>{}</h2>", esc(title))), "{title} missing");
        }
        for what in
            ["Maps", "Planning runs", "Map pictures", "Explored volume", "Time against iterations"]
        {
            assert!(page.contains(&format!("{what}: not computed.")), "{what}");
        }
        for what in ["Terrain", "Time-of-flight frame", "Files", "Stage times"] {
            assert!(page.contains(&format!("{what}: not computed.")), "{what}");
        }
        assert!(png_payloads(&page).is_empty());
        assert_eq!(page.matches("<svg").count(), 0);
    }

    #[test]
    fn broken_sections_degrade_to_notes() {
        let mut r = synthetic();
        if let Some(t) = r.tof.as_mut() {
            t.outcomes.truncate(5);
        }
        if let Some(v) = r.volume.as_mut() {
            v.slice_size = [u32::MAX, 3];
            v.table = vec![vec![Some(f64::NAN)]];
        }
        if let Some(t) = r.terrain.as_mut() {
            t.hough_png = b"not a png".to_vec();
            t.sectors.push(("extra".into(), false));
        }
        r.timing[0].median_ms = vec![f64::NAN, -1.0];
        r.stages[0].seconds = f64::INFINITY;
        r.drawings[0].points.push([f64::NAN, 1.0, f64::INFINITY]);
        if let Some(s) = r.safety.as_mut() {
            s.rows[0].unsafe_pct = [f64::NAN; 3];
            s.rows[0].unsafe_hits.push([f64::INFINITY, 0.0, 0.0]);
        }
        let page = render(&r);
        assert_balanced(&page);
        assert!(page.contains("Outcome picture not drawn"));
        assert!(page.contains("Slice picture not drawn"));
        assert!(page.contains("Hough-space picture: not computed."));
        assert!(page.contains("sector 4"));
        assert!(!page.contains("NaN") && !page.contains("inf"));
        for png in png_payloads(&page) {
            assert!(encode::is_png(&png));
        }
    }

    #[test]
    fn write_creates_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("report.html");
        write(&synthetic(), &path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text, render(&synthetic()));
        assert!(write(&synthetic(), &dir.path().join("missing/report.html")).is_err());
    }
}
