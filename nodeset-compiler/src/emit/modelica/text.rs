//! Text building blocks: Modelica string literals, HTML documentation, number literals, file headers.

use crate::load::ModelInfo;

/// A Modelica string literal (with its quotes). Control characters that Modelica cannot escape are dropped;
/// the others use the escapes of MLS 2.4.6.
pub fn string_literal(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if c.is_control() => {}
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// One line of text for a description string: whitespace runs (line breaks included) become one space.
pub fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The description string of an element: the original BrowseName first (so the one-to-one mapping stays
/// visible), then the Description of the nodeset.
pub fn description(original: &str, doc: Option<&str>) -> String {
    // Some nodesets start a Description with the separator themselves (": The ...").
    let doc = doc.map(|d| d.trim_start_matches(|c: char| c == ':' || c.is_whitespace()));
    match doc.map(one_line).filter(|d| !d.is_empty()) {
        Some(d) => string_literal(&format!("{original}: {d}")),
        None => string_literal(original),
    }
}

/// Escapes text for HTML.
pub fn html_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            c => out.push(c),
        }
    }
    out
}

/// HTML paragraphs from plain text (paragraphs separated by blank lines).
pub fn html_paragraphs(text: &str) -> String {
    let mut out = String::new();
    for para in text.split("\n\n").map(one_line).filter(|p| !p.is_empty()) {
        out.push_str("<p>");
        out.push_str(&html_escape(&para));
        out.push_str("</p>");
    }
    out
}

/// The icon of a model: a white box with a blue frame, its name above it. Connectors sit on its left (inputs)
/// and right (outputs) edges.
pub const MODEL_ICON: &str = "Icon(graphics={Rectangle(extent={{-100,100},{100,-100}}, lineColor={0,0,127}, \
fillColor={255,255,255}, fillPattern=FillPattern.Solid, radius=10), Text(extent={{-150,150},{150,110}}, \
textString=\"%name\", textColor={0,0,255})})";

/// The icon of an example, as the Modelica Standard Library draws `Modelica.Icons.Example`: a play button.
pub const EXAMPLE_ICON: &str = "Icon(graphics={Ellipse(extent={{-100,100},{100,-100}}, lineColor={75,138,73}, \
fillColor={255,255,255}, fillPattern=FillPattern.Solid), Polygon(points={{-36,60},{64,0},{-36,-60},{-36,60}}, \
lineColor={0,0,255}, fillColor={75,138,73}, fillPattern=FillPattern.Solid)})";

/// The icon of a block, as the Modelica Standard Library draws `Modelica.Blocks.Icons.Block`.
pub const BLOCK_ICON: &str = "Icon(graphics={Rectangle(extent={{-100,100},{100,-100}}, lineColor={0,0,127}, \
fillColor={255,255,255}, fillPattern=FillPattern.Solid), Text(extent={{-150,150},{150,110}}, \
textString=\"%name\", textColor={0,0,255})})";

/// The icon of a record: a box with a grey header that holds its name.
pub const RECORD_ICON: &str = "Icon(graphics={Rectangle(extent={{-100,100},{100,-100}}, lineColor={64,64,64}, \
fillColor={255,255,255}, fillPattern=FillPattern.Solid), Rectangle(extent={{-100,100},{100,50}}, \
lineColor={64,64,64}, fillColor={200,200,200}, fillPattern=FillPattern.Solid), Text(extent={{-100,100},{100,50}}, \
textString=\"%name\", textColor={0,0,0})})";

/// The icon of a package: a grey rounded box marked UA.
pub const PACKAGE_ICON: &str = "Icon(graphics={Rectangle(extent={{-100,100},{100,-100}}, lineColor={128,128,128}, \
fillColor={240,240,240}, fillPattern=FillPattern.Solid, radius=25), Text(extent={{-80,40},{80,-40}}, \
textString=\"UA\", textColor={128,128,128})})";

/// The icon of a package of documentation (the support package's UsersGuide): an i in a circle.
pub const INFO_ICON: &str = "Icon(graphics={Ellipse(extent={{-100,100},{100,-100}}, lineColor={0,0,127}, \
fillColor={255,255,255}, fillPattern=FillPattern.Solid), Text(extent={{-60,70},{60,-70}}, textString=\"i\", \
textColor={0,0,127})})";

/// A `Documentation(info=...)` annotation item for an HTML body.
pub fn documentation(html_body: &str) -> String {
    format!("Documentation(info={})", string_literal(&format!("<html>{html_body}</html>")))
}

/// A Modelica Real literal for a finite number (`1.0`, `1e-05`, `1450.0`); `None` for NaN and infinities,
/// which Modelica has no literal for.
pub fn real_literal(x: f64) -> Option<String> {
    if !x.is_finite() {
        return None;
    }
    let s = format!("{x:?}");
    // Rust writes `1e-5` and `1e20`; both are valid Modelica UNSIGNED_NUMBERs (with the sign in front).
    Some(s)
}

/// The header comment every generated Modelica file starts with.
pub fn header(model: Option<&ModelInfo>) -> String {
    let from = match model {
        Some(m) => {
            let mut s = m.uri.clone();
            match (&m.version, &m.publication_date) {
                (Some(v), Some(d)) => s.push_str(&format!(" (version {v}, published {d})")),
                (Some(v), None) => s.push_str(&format!(" (version {v})")),
                (None, Some(d)) => s.push_str(&format!(" (published {d})")),
                (None, None) => {}
            }
            s
        }
        None => "no information model (the support package of the generated Modelica packages)".into(),
    };
    format!(
        "// Generated by nodeset-compiler {} from {from}.\n// Do not edit: regenerate with `cargo xtask generate`.\n",
        env!("CARGO_PKG_VERSION")
    )
}

/// Indents every non-empty line of `s` by `n` spaces.
pub fn indent(s: &str, n: usize) -> String {
    let pad = " ".repeat(n);
    let mut out = String::with_capacity(s.len() + 16);
    for line in s.lines() {
        if !line.is_empty() {
            out.push_str(&pad);
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// Days since 1970-01-01 of a proleptic Gregorian date (Howard Hinnant's `days_from_civil`).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = if y >= 0 { y } else { y - 399 } / 400;
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// Seconds since 1970-01-01T00:00:00Z of an `xs:dateTime` (`2020-08-01T00:00:00Z`, fractions and offsets
/// allowed); `None` when the text is not one.
pub fn unix_seconds(text: &str) -> Option<f64> {
    let t = text.trim();
    let (date, rest) = t.split_once('T').unwrap_or((t, "00:00:00Z"));
    let mut dp = date.splitn(3, '-');
    let (y, m, d): (i64, i64, i64) = (dp.next()?.parse().ok()?, dp.next()?.parse().ok()?, dp.next()?.parse().ok()?);
    if !(1..=12).contains(&m) || !(1..=31).contains(&d) {
        return None;
    }
    // Split the time from a zone designator.
    let (time, offset) = if let Some(p) = rest.strip_suffix('Z') {
        (p, 0i64)
    } else if let Some(i) = rest.rfind(['+', '-']).filter(|&i| i >= 8) {
        let (tm, zone) = rest.split_at(i);
        let sign = if zone.starts_with('-') { -1 } else { 1 };
        let (zh, zm) = zone[1..].split_once(':')?;
        (tm, sign * (zh.parse::<i64>().ok()? * 3600 + zm.parse::<i64>().ok()? * 60))
    } else {
        (rest, 0)
    };
    let mut tp = time.splitn(3, ':');
    let h: i64 = tp.next()?.parse().ok()?;
    let mi: i64 = tp.next()?.parse().ok()?;
    let s: f64 = tp.next().unwrap_or("0").parse().ok()?;
    let days = days_from_civil(y, m, d);
    Some((days * 86_400 + h * 3600 + mi * 60 - offset) as f64 + s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strings_escape_quotes_backslashes_and_line_breaks() {
        assert_eq!(string_literal("a \"b\" \\ c\nd\u{7}"), "\"a \\\"b\\\" \\\\ c\\nd\"");
        assert_eq!(description("Model", Some("The\n  model  name.")), "\"Model: The model name.\"");
        assert_eq!(description("X", Some("  ")), "\"X\"");
    }

    #[test]
    fn html_is_escaped_then_quoted() {
        assert_eq!(html_paragraphs("a < b & c\n\nsecond"), "<p>a &lt; b &amp; c</p><p>second</p>");
        assert_eq!(documentation("<p>\"x\"</p>"), "Documentation(info=\"<html><p>\\\"x\\\"</p></html>\")");
    }

    #[test]
    fn reals_are_modelica_literals() {
        assert_eq!(real_literal(1450.0).unwrap(), "1450.0");
        assert_eq!(real_literal(-1e-5).unwrap(), "-1e-5");
        assert_eq!(real_literal(0.1).unwrap(), "0.1");
        assert!(real_literal(f64::NAN).is_none());
    }

    #[test]
    fn date_times_become_unix_seconds() {
        assert_eq!(unix_seconds("1970-01-01T00:00:00Z"), Some(0.0));
        assert_eq!(unix_seconds("2020-08-01T00:00:00Z"), Some(1_596_240_000.0));
        assert_eq!(unix_seconds("2020-08-01T02:00:00+02:00"), Some(1_596_240_000.0));
        assert_eq!(unix_seconds("1601-01-01T00:00:00Z"), Some(-11_644_473_600.0));
        assert_eq!(unix_seconds("2020-08-01T00:00:00.5Z"), Some(1_596_240_000.5));
        assert_eq!(unix_seconds("garbage"), None);
    }
}
