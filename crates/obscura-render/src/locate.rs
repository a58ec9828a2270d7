//! Finding the line of a key in a TOML scene file, for error messages.
//!
//! Serde reports byte spans for syntax and type errors; checks made after parsing (a fov out of
//! range, an undefined material) know only the key's path. This module maps both to a line
//! through toml's own parse of the file with spans (recovering what it can of a file with a
//! syntax error), so multi-line arrays, inline tables and dotted keys are read as the parser
//! reads them.

use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// The 1-based line holding byte offset `at`.
pub(crate) fn line_of_offset(source: &str, at: usize) -> usize {
    // Bytes, not a `str` slice: a span from a recovered parse need not fall on a character.
    source.as_bytes()[..at.min(source.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// One step of a key path: a table's key, or an array's index.
enum Step<'a> {
    Key(&'a str),
    Index(usize),
}

/// The steps of a path such as `shapes[2].transform[0]`.
fn steps(path: &str) -> Vec<Step<'_>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (name, mut rest) = part.split_once('[').map_or((part, ""), |(n, r)| (n, r));
        out.push(Step::Key(name));
        while let Some((index, after)) = rest.split_once(']') {
            if let Ok(i) = index.parse() {
                out.push(Step::Index(i));
            }
            rest = after.strip_prefix('[').unwrap_or("");
        }
    }
    out
}

/// The line where `path` (e.g. `camera.fov`, `shapes[2].transform[0]`) is written: the key's
/// own line when found, else the line of the nearest enclosing key or table that is (a
/// table's header for a key missing from it).
pub(crate) fn line_of_key(source: &str, path: &str) -> Option<usize> {
    let (root, _) = DeTable::parse_recoverable(source);
    let mut table = Some(root.get_ref());
    let mut value: Option<&Spanned<DeValue<'_>>> = None;
    let mut line = None;
    for step in steps(path) {
        // Where the step is written (a key's own span, an element's start) and its value.
        let found = match step {
            Step::Key(key) => table
                .and_then(|t| t.iter().find(|(k, _)| k.get_ref() == key))
                .map(|(k, v)| (k.span().start, v)),
            Step::Index(i) => match value.map(Spanned::get_ref) {
                Some(DeValue::Array(a)) => a.get(i).map(|v| (v.span().start, v)),
                _ => None,
            },
        };
        let Some((at, v)) = found else { break };
        line = Some(line_of_offset(source, at));
        table = match v.get_ref() {
            DeValue::Table(t) => Some(t),
            _ => None,
        };
        value = Some(v);
    }
    line
}

/// The key path written on line `line` (the key of a `key = value` line, qualified by its
/// table, or a table's header), or else the innermost key whose value spans that line: for
/// serde errors, which carry a span but no key.
pub(crate) fn key_at_line(source: &str, line: usize) -> Option<String> {
    let (root, _) = DeTable::parse_recoverable(source);
    let mut on_line = None;
    let mut around = None;
    visit(source, root.get_ref(), "", line, &mut on_line, &mut around);
    on_line.or(around)
}

/// Walks `table` under `prefix`, keeping the last key written on `line` and the last (so the
/// innermost) whose value's lines hold it.
fn visit(
    source: &str,
    table: &DeTable<'_>,
    prefix: &str,
    line: usize,
    on_line: &mut Option<String>,
    around: &mut Option<String>,
) {
    for (key, value) in table {
        let path = if prefix.is_empty() {
            key.get_ref().to_string()
        } else {
            format!("{prefix}.{}", key.get_ref())
        };
        if line_of_offset(source, key.span().start) == line {
            *on_line = Some(path.clone());
        }
        visit_value(source, value, &path, line, on_line, around);
    }
}

/// [`visit`] for a value: tables are walked, arrays' elements named by index.
fn visit_value(
    source: &str,
    value: &Spanned<DeValue<'_>>,
    path: &str,
    line: usize,
    on_line: &mut Option<String>,
    around: &mut Option<String>,
) {
    let span = value.span();
    let (first, last) = (
        line_of_offset(source, span.start),
        line_of_offset(source, span.end.saturating_sub(1).max(span.start)),
    );
    if (first..=last).contains(&line) {
        *around = Some(path.to_string());
    }
    match value.get_ref() {
        DeValue::Table(t) => visit(source, t, path, line, on_line, around),
        DeValue::Array(a) => {
            for (i, element) in a.iter().enumerate() {
                let path = format!("{path}[{i}]");
                if let DeValue::Table(_) = element.get_ref()
                    && line_of_offset(source, element.span().start) == line
                {
                    *on_line = Some(path.clone());
                }
                visit_value(source, element, &path, line, on_line, around);
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = "[film]\nresolution = [4, 4]\n\n[camera]\ntype = \"perspective\"\nfov = 200\n\n[[shapes]]\ntype = \"sphere\"\n\n[[shapes]]\ntype = \"quad\"\norigin = [0, 0, 0]\n[materials.white]\nreflectance = [1, 1, 1]\n";

    #[test]
    fn keys_are_found_below_their_headers() {
        assert_eq!(line_of_key(SCENE, "camera.fov"), Some(6));
        assert_eq!(line_of_key(SCENE, "film.resolution"), Some(2));
        assert_eq!(line_of_key(SCENE, "shapes[1].origin"), Some(13));
        assert_eq!(
            line_of_key(SCENE, "shapes[1].transform[0]"),
            Some(11),
            "falls back to the header"
        );
        assert_eq!(line_of_key(SCENE, "shapes[0].type"), Some(9));
        assert_eq!(line_of_key(SCENE, "materials.white.reflectance"), Some(15));
        assert_eq!(line_of_key(SCENE, "lights[0]"), None);
        let nested = "[camera]\nfov = 1.0\n[camera.stereo]\ninteraxial = 0.1\n";
        assert_eq!(line_of_key(nested, "camera.stereo"), Some(3));
        assert_eq!(line_of_key(nested, "camera.stereo.interaxial"), Some(4));
        assert_eq!(line_of_key(nested, "camera.stereo.layout"), Some(3));
    }

    /// Rows of a multi-line array that begin with `[` are not table headers, a `[camera]` inside
    /// a multi-line string is text, and a dotted key or an inline table is found where the
    /// parser finds it. (A line-by-line reading took the array's rows for headers: `fov` was
    /// reported at the `[camera]` line, and its key as `1.0, 1.0.fov`.)
    #[test]
    fn arrays_strings_and_inline_tables_are_read_as_toml() {
        let scene = "[camera]\nshutter_curve = [\n  [0.0, 0.0],\n  [0.5, 1.0],\n  [1.0, 1.0],\n]\n\
                     fov = 180.0\nrolling_shutter = { readout = 2.0, direction = \"up\" }\n\
                     [integrator]\nnote = \"\"\"\n[camera]\nfov = 3\n\"\"\"\nstereo.interaxial = 1\n";
        assert_eq!(line_of_key(scene, "camera.fov"), Some(7));
        assert_eq!(line_of_key(scene, "camera.shutter_curve[1]"), Some(4));
        assert_eq!(
            line_of_key(scene, "camera.rolling_shutter.direction"),
            Some(8)
        );
        assert_eq!(line_of_key(scene, "integrator.stereo.interaxial"), Some(14));
        assert_eq!(key_at_line(scene, 7).as_deref(), Some("camera.fov"));
        assert_eq!(
            key_at_line(scene, 4).as_deref(),
            Some("camera.shutter_curve[1][1]"),
            "the innermost value on a row of the array"
        );
        assert_eq!(
            key_at_line(scene, 11).as_deref(),
            Some("integrator.note"),
            "inside a string"
        );
        assert_eq!(key_at_line(scene, 9).as_deref(), Some("integrator"));
    }

    #[test]
    fn lines_give_their_keys() {
        assert_eq!(key_at_line(SCENE, 6).as_deref(), Some("camera.fov"));
        assert_eq!(key_at_line(SCENE, 8).as_deref(), Some("shapes[0]"));
        assert_eq!(key_at_line(SCENE, 13).as_deref(), Some("shapes[1].origin"));
        assert_eq!(line_of_offset(SCENE, 0), 1);
        assert_eq!(line_of_offset(SCENE, SCENE.find("fov").unwrap()), 6);
    }
}
