//! `patchnav demo --quick` writes a report a browser opens without a server: the page is
//! checked as written and, opted in where Chromium is installed, as a headless browser parses
//! and draws it.

use std::io::Read as _;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The section headings of the page, in order.
const HEADINGS: [&str; 10] = patch_pipeline::report::SECTIONS;

const CHROMIUM: &str = "/usr/bin/chromium";

/// Runs `cmd`, killing it after `limit`; stdout and stderr are drained while it runs.
fn run_with_timeout(cmd: &mut Command, limit: Duration) -> Output {
    let mut child = cmd.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().expect("spawns");
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let out_reader = std::thread::spawn(move || {
        let mut buf = Vec::new();
        out.read_to_end(&mut buf).map(|_| buf).unwrap_or_default()
    });
    let err_reader = std::thread::spawn(move || {
        let mut buf = Vec::new();
        err.read_to_end(&mut buf).map(|_| buf).unwrap_or_default()
    });
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("waits") {
            break status;
        }
        if start.elapsed() > limit {
            child.kill().ok();
            child.wait().ok();
            panic!("{cmd:?} still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    Output { status, stdout: out_reader.join().unwrap(), stderr: err_reader.join().unwrap() }
}

/// Writes the quick demo into `dir` and returns the page.
fn quick_demo(dir: &Path) -> String {
    let o = run_with_timeout(
        Command::new(env!("CARGO_BIN_EXE_patchnav"))
            .args(["demo", "--quick", "--quiet", "--out"])
            .arg(dir),
        Duration::from_secs(600),
    );
    assert!(o.status.success(), "demo failed: {}", String::from_utf8_lossy(&o.stderr));
    std::fs::read_to_string(dir.join("report.html")).expect("report.html written")
}

/// Checks the page as written: headings, no external resources, every file link present.
fn check_page(page: &str, dir: &Path) {
    assert!(page.starts_with("<!doctype html>"));
    for h in HEADINGS {
        assert!(page.contains(&format!("<h2>{h}</h2>")), "heading {h} missing");
    }
    assert_eq!(page.matches("<svg").count(), page.matches("</svg>").count());
    assert_eq!(page.matches("<table>").count(), page.matches("</table>").count());
    for external in ["<script", "src=\"http", "href=\"http", "url(http", "@import", "<link"] {
        assert!(!page.contains(external), "external resource `{external}` in the page");
    }
    // Every img is inline.
    for (i, _) in page.match_indices("<img") {
        let tag = &page[i..i + page[i..].find('>').unwrap()];
        assert!(
            tag.contains("src=\"data:image/png;base64,"),
            "non-inline image: {}",
            &tag[..tag.len().min(80)]
        );
    }
    // Every file link resolves next to the page.
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("results.json")).unwrap()).unwrap();
    for f in results["files"].as_array().into_iter().flatten() {
        let path = f["path"].as_str().unwrap();
        assert!(dir.join(path).is_file(), "{path} listed but missing");
    }
    let drawings = results["drawings"].as_array().map_or(0, Vec::len);
    assert!(page.matches("<svg").count() >= 2 * drawings, "two views per map type");
}

#[test]
fn quick_demo_report_is_a_page_without_a_server() {
    let dir = tempfile::tempdir().unwrap();
    let page = quick_demo(dir.path());
    check_page(&page, dir.path());
}

/// Opt-in, as it needs Chromium (`apt-get install chromium`):
/// `cargo test -p patchnav --test it -- --ignored headless_browser`.
#[test]
#[ignore = "needs Chromium at /usr/bin/chromium; run with --ignored"]
fn quick_demo_report_opens_in_a_headless_browser() {
    assert!(Path::new(CHROMIUM).exists(), "{CHROMIUM} not found (apt-get install chromium)");
    let dir = tempfile::tempdir().unwrap();
    let page = quick_demo(dir.path());
    check_page(&page, dir.path());
    let report = dir.path().join("report.html");
    let url = format!("file://{}", report.display());
    let profile = tempfile::tempdir().unwrap();
    let chromium = |extra: &[&str]| {
        let mut cmd = Command::new(CHROMIUM);
        cmd.args(["--headless", "--disable-gpu", "--no-sandbox", "--no-first-run"])
            .arg(format!("--user-data-dir={}", profile.path().display()))
            .args(extra)
            .arg(&url);
        run_with_timeout(&mut cmd, Duration::from_secs(180))
    };

    let o = chromium(&["--dump-dom"]);
    assert!(o.status.success(), "chromium --dump-dom: {}", String::from_utf8_lossy(&o.stderr));
    let dom = String::from_utf8_lossy(&o.stdout);
    for h in HEADINGS {
        assert!(dom.contains(&format!("<h2>{h}</h2>")), "heading {h} missing from the DOM");
    }
    let svgs = page.matches("<svg").count();
    assert_eq!(dom.matches("<svg").count(), svgs, "every SVG parsed");
    assert_eq!(dom.matches("<img").count(), page.matches("<img").count(), "every image parsed");
    if svgs == 0 {
        eprintln!("note: the report has no SVG (pipeline produced no drawings or timing)");
    }

    let shot = dir.path().join("shot.png");
    let o = chromium(&[&format!("--screenshot={}", shot.display()), "--window-size=1200,3000"]);
    assert!(o.status.success(), "chromium --screenshot: {}", String::from_utf8_lossy(&o.stderr));
    let bytes = std::fs::read(&shot).expect("screenshot written");
    assert!(bytes.starts_with(&[0x89, b'P', b'N', b'G']), "screenshot is a PNG");
    let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (1200, 3000));
    // Not a blank page: many distinct colours (text, tables, pictures).
    let channels = info.color_type.samples();
    let mut colours: Vec<&[u8]> = buf[..info.buffer_size()].chunks(channels).collect();
    colours.sort_unstable();
    colours.dedup();
    assert!(colours.len() > 50, "only {} colours in the screenshot", colours.len());
}
