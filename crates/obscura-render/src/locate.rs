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

/// The key path a serde error at byte `at` is about, with the error's `message`:
/// - the innermost key written at `at`, or whose value holds it (a value of the wrong type,
///   an unknown key inside an inline table);
/// - else, for a key the parse could not keep (a duplicate), that key's text under the
///   table it is written in;
/// - and for `missing field` errors, the missing key under the table the error is about.
pub(crate) fn key_at(source: &str, at: usize, message: &str) -> Option<String> {
    let (root, _) = DeTable::parse_recoverable(source);
    let mut found = Found::default();
    visit(source, root.get_ref(), "", at, &mut found);
    if let Some(missing) = message
        .strip_prefix("missing field `")
        .and_then(|m| m.split('`').next())
    {
        let table = found.table.map(|(_, path)| path);
        return Some(match table {
            Some(t) => format!("{t}.{missing}"),
            None => missing.to_string(),
        });
    }
    if found.exact.is_some() {
        return found.exact;
    }
    // A key written at `at` that the parse dropped (a duplicate, or one whose value does not
    // parse): its text, under the table in force there; the key at the start of `at`'s line
    // when `at` is in its value.
    let bare = |text: &str| -> String {
        text.chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_' || *c == '-')
            .collect()
    };
    let mut word = bare(source.get(at..)?);
    if word.is_empty() {
        let line_start = source.get(..at)?.rfind('\n').map_or(0, |n| n + 1);
        let before = source.get(line_start..at)?;
        if let Some((key, _)) = before.split_once('=') {
            let key = key.trim();
            if !key.is_empty() && bare(key) == key {
                word = key.to_string();
            }
        }
    }
    let table = found.table.map(|(_, path)| path);
    match (table, word.is_empty()) {
        (Some(t), false) => Some(format!("{t}.{word}")),
        (None, false) => Some(word),
        (t, true) => t,
    }
}

/// What [`visit`] finds for an offset.
#[derive(Default)]
struct Found {
    /// The innermost key at the offset, or whose value holds it.
    exact: Option<String>,
    /// The table (by where its header or element starts) the offset lies under.
    table: Option<(usize, String)>,
}

/// Walks `table` under `prefix` for offset `at`.
fn visit(source: &str, table: &DeTable<'_>, prefix: &str, at: usize, found: &mut Found) {
    for (key, value) in table {
        let path = if prefix.is_empty() {
            key.get_ref().to_string()
        } else {
            format!("{prefix}.{}", key.get_ref())
        };
        if key.span().contains(&at) {
            found.exact = Some(path.clone());
        }
        visit_value(source, value, &path, key.span().start, at, found);
    }
}

/// [`visit`] for a value written from `start`: tables are walked, arrays' elements named by
/// index.
fn visit_value(
    source: &str,
    value: &Spanned<DeValue<'_>>,
    path: &str,
    start: usize,
    at: usize,
    found: &mut Found,
) {
    let span = value.span();
    let inside = span.start <= at && at < span.end.max(span.start + 1);
    match value.get_ref() {
        DeValue::Table(t) => {
            // A table's own span may be its header alone: the table in force at `at` is the
            // last one started before it, an inline table only up to its closing brace.
            let inline = source.get(span.start..).is_some_and(|t| t.starts_with('{'));
            let open = !inline || at < span.end;
            if start <= at && open && found.table.as_ref().is_none_or(|(s, _)| start >= *s) {
                found.table = Some((start, path.to_string()));
            }
            if inside && t.is_empty() {
                found.exact = Some(path.to_string());
            }
            visit(source, t, path, at, found);
        }
        DeValue::Array(a) => {
            if inside {
                found.exact = Some(path.to_string());
            }
            for (i, element) in a.iter().enumerate() {
                visit_value(
                    source,
                    element,
                    &format!("{path}[{i}]"),
                    element.span().start,
                    at,
                    found,
                );
            }
        }
        _ => {
            if inside {
                found.exact = Some(path.to_string());
            }
        }
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
        // Serde's errors point at a key or a value: the innermost key there.
        let key = |needle: &str| key_at(scene, scene.find(needle).unwrap(), "");
        assert_eq!(key("fov = 180").as_deref(), Some("camera.fov"));
        assert_eq!(key("180.0").as_deref(), Some("camera.fov"));
        assert_eq!(
            key("0.5, 1.0]").as_deref(),
            Some("camera.shutter_curve[1][0]"),
            "a value in a row of the array"
        );
        assert_eq!(
            key("\"up\"").as_deref(),
            Some("camera.rolling_shutter.direction")
        );
        assert_eq!(
            key("readout").as_deref(),
            Some("camera.rolling_shutter.readout")
        );
        assert_eq!(
            key("fov = 3").as_deref(),
            Some("integrator.note"),
            "inside a string"
        );
        assert_eq!(
            key("interaxial").as_deref(),
            Some("integrator.stereo.interaxial")
        );
    }

    /// The keys of errors that name no written key: a duplicate (the parse keeps the first),
    /// and a missing key, under the table the error is about.
    #[test]
    fn duplicates_and_missing_keys_are_named() {
        let scene = "[film]\nresolution = [4, 4]\n[camera]\nrolling_shutter = { readout = 1 }\n\
                     fov = 30\nfov = 40\n[[shapes]]\nradius = 1\n";
        let second = scene.rfind("fov").unwrap();
        assert_eq!(
            key_at(scene, second, "duplicate key").as_deref(),
            Some("camera.fov")
        );
        // Serde's missing-field errors point at the start of the table they are about.
        assert_eq!(
            key_at(scene, 0, "missing field `integrator`").as_deref(),
            Some("integrator")
        );
        let shape = scene.find("[[shapes]]").unwrap();
        assert_eq!(
            key_at(scene, shape, "missing field `type`").as_deref(),
            Some("shapes[0].type")
        );
    }

    #[test]
    fn offsets_give_their_keys() {
        let key = |needle: &str| key_at(SCENE, SCENE.find(needle).unwrap(), "");
        assert_eq!(key("fov").as_deref(), Some("camera.fov"));
        assert_eq!(key("origin").as_deref(), Some("shapes[1].origin"));
        assert_eq!(
            key("[1, 1, 1]").as_deref(),
            Some("materials.white.reflectance")
        );
        assert_eq!(line_of_offset(SCENE, 0), 1);
        assert_eq!(line_of_offset(SCENE, SCENE.find("fov").unwrap()), 6);
    }
}
