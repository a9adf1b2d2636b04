//! Text helpers of the report: HTML escaping, number formatting and tables.

use std::fmt::Write as _;

/// Shown where a value is missing or not finite.
pub const DASH: &str = "–";

/// Escapes `&`, `<`, `>`, `"` and `'`, so `text` is safe in element content and in quoted
/// attribute values.
pub fn esc(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// A relative link target for `path`: characters outside the unreserved set (and `/`) are
/// percent-encoded, and a path that would read as a URL scheme (`javascript:`) gets a `./`
/// prefix. The result still needs [`esc`] only for `&`, which it never contains.
pub fn href(path: &str) -> String {
    let mut out = String::with_capacity(path.len() + 2);
    let first_segment = path.split('/').next().unwrap_or("");
    if first_segment.contains(':') {
        out.push_str("./");
    }
    for b in path.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~/".contains(&b) {
            out.push(b as char);
        } else {
            let _ = write!(out, "%{b:02X}");
        }
    }
    out
}

/// Puts commas between groups of three digits of the integer part of a formatted number
/// (`345533` → `345,533`, `-1234.5` → `-1,234.5`).
fn group(formatted: &str) -> String {
    let (sign, rest) = match formatted.strip_prefix('-') {
        Some(r) => ("-", r),
        None => ("", formatted),
    };
    let (int, frac) = match rest.find('.') {
        Some(i) => rest.split_at(i),
        None => (rest, ""),
    };
    if !int.bytes().all(|b| b.is_ascii_digit()) {
        return formatted.to_owned();
    }
    let mut out = String::from(sign);
    for (i, c) in int.chars().enumerate() {
        if i > 0 && (int.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out.push_str(frac);
    out
}

/// An integer with thousands separators.
pub fn int(n: impl Into<u128>) -> String {
    group(&n.into().to_string())
}

/// `x` to `digits` significant figures (at least 1), with thousands separators and without an
/// exponent between 1e-4 and 1e15; [`DASH`] if not finite.
pub fn sig(x: f64, digits: usize) -> String {
    if !x.is_finite() {
        return DASH.to_owned();
    }
    if x == 0.0 {
        return "0".to_owned();
    }
    let digits = digits.clamp(1, 15) as i32;
    let mag = x.abs().log10().floor() as i32;
    if !(-4..15).contains(&mag) {
        return format!("{:.*e}", (digits - 1) as usize, x);
    }
    let decimals = digits - 1 - mag;
    if decimals >= 0 {
        group(&format!("{:.*}", decimals as usize, x))
    } else {
        let unit = 10f64.powi(-decimals);
        group(&format!("{:.0}", (x / unit).round() * unit))
    }
}

/// `x` with a fixed number of decimals (for percentages and angles); [`DASH`] if not finite.
pub fn fixed(x: f64, decimals: usize) -> String {
    if x.is_finite() { group(&format!("{x:.decimals$}")) } else { DASH.to_owned() }
}

/// Seconds, three significant figures, in s or ms.
pub fn seconds(s: f64) -> String {
    if !s.is_finite() {
        DASH.to_owned()
    } else if s.abs() < 1.0 && s != 0.0 {
        format!("{} ms", sig(s * 1e3, 3))
    } else {
        format!("{} s", sig(s, 3))
    }
}

/// A byte count in B, kB, MB or GB (decimal units, as the thesis's Table 6.1).
pub fn bytes(n: u64) -> String {
    let x = n as f64;
    if n < 1000 {
        format!("{n} B")
    } else if x < 1e6 {
        format!("{:.1} kB", x / 1e3)
    } else if x < 1e9 {
        format!("{:.1} MB", x / 1e6)
    } else {
        format!("{:.2} GB", x / 1e9)
    }
}

/// `yes` or `no`.
pub fn yes_no(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

/// Does a cell read as a number (right-aligned) rather than text (left-aligned)?
fn numeric(cell: &str) -> bool {
    let body = cell.strip_prefix(['-', '+']).unwrap_or(cell);
    cell == DASH || body.starts_with(|c: char| c.is_ascii_digit())
}

/// A table: `headers` and `rows` are plain text (escaped here). Numeric cells are right-aligned
/// by the page's style sheet, text cells (class `t`) left-aligned.
pub fn table(headers: &[&str], rows: &[Vec<String>]) -> String {
    let mut out = String::from("<table>\n<thead><tr>");
    for h in headers {
        let _ = write!(out, "<th>{}</th>", esc(h));
    }
    out.push_str("</tr></thead>\n<tbody>\n");
    for row in rows {
        out.push_str("<tr>");
        for cell in row {
            let class = if numeric(cell) { "" } else { " class=\"t\"" };
            let _ = write!(out, "<td{class}>{}</td>", esc(cell));
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody>\n</table>\n");
    out
}

/// A `<p>` with escaped `text`.
pub fn para(text: &str) -> String {
    format!("<p>{}</p>\n", esc(text))
}

/// The "not computed" line of a missing section.
pub fn not_computed(what: &str) -> String {
    format!("<p class=\"missing\">{}: not computed.</p>\n", esc(what))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_markup_and_quotes() {
        assert_eq!(esc("<a href=\"x\">&'"), "&lt;a href=&quot;x&quot;&gt;&amp;&#39;");
        assert_eq!(esc("plain ρ 1.5"), "plain ρ 1.5");
    }

    #[test]
    fn links_stay_relative_and_inert() {
        assert_eq!(href("maps/hybrid map.ply"), "maps/hybrid%20map.ply");
        assert_eq!(href("javascript:alert(1)"), "./javascript%3Aalert%281%29");
        assert_eq!(href("a\"><b"), "a%22%3E%3Cb");
    }

    #[test]
    fn significant_figures() {
        assert_eq!(sig(9714.015, 4), "9,714");
        assert_eq!(sig(0.5571, 3), "0.557");
        assert_eq!(sig(345_533.0, 3), "346,000");
        assert_eq!(sig(-1.26, 2), "-1.3");
        assert_eq!(sig(0.0, 3), "0");
        assert_eq!(sig(f64::NAN, 3), DASH);
        assert_eq!(sig(1.5e-7, 2), "1.5e-7");
        assert_eq!(int(5_600_612u64), "5,600,612");
        assert_eq!(int(12u64), "12");
        assert_eq!(seconds(0.0123), "12.3 ms");
        assert_eq!(seconds(61.26), "61.3 s");
        assert_eq!(bytes(8_700_000), "8.7 MB");
        assert_eq!(bytes(999), "999 B");
        assert_eq!(fixed(1.2345, 2), "1.23");
    }

    #[test]
    fn table_escapes_cells() {
        let t = table(&["a<b"], &[vec!["<x>".to_owned()]]);
        assert!(
            t.contains("<th>a&lt;b</th>") && t.contains("<td class=\"t\">&lt;x&gt;</td>"),
            "{t}"
        );
        let t = table(
            &["n"],
            &[vec!["-1.5 m".to_owned()], vec![DASH.to_owned()], vec!["yes".to_owned()]],
        );
        assert!(t.contains("<td>-1.5 m</td>") && t.contains("<td>–</td>"), "{t}");
        assert!(t.contains("<td class=\"t\">yes</td>"), "{t}");
    }
}
