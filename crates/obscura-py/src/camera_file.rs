//! The camera's part of a scene file, for `Camera.from_toml`: the `[camera]` and `[film]`
//! tables and `[sampler] type` (which `pixel_rays` draws from); every other table is ignored,
//! so a scene whose materials, shapes or integrator the renderer would refuse still gives its
//! camera.
//!
//! The renderer's parser checks a whole scene, and its errors find their line by reading the
//! text. So the other statements are blanked out of the text, each kept line staying where it
//! was, and the renderer parses what is left: its errors name the file's own lines.

use std::ops::Range;
use toml_edit::{Document, Item, Table};

/// `source` with every statement (table header or `key = value`, with all the lines its value
/// spans) outside the camera's tables replaced by empty lines. None when `source` is not TOML:
/// the renderer's parser then reports the error, with its line.
pub(crate) fn camera_tables(source: &str) -> Option<String> {
    let doc = Document::parse(source).ok()?;
    let mut dropped = Vec::new();
    statements(
        doc.as_table(),
        &mut Vec::new(),
        &mut |path, span, header| {
            if !kept(path, header) {
                dropped.push(span);
            }
        },
    )?;

    // Blank every line a dropped statement touches (TOML puts one statement on a line, so no
    // kept statement shares one).
    let line_of = |at: usize| {
        source.as_bytes()[..at]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
    };
    let mut blank = vec![false; source.split_inclusive('\n').count()];
    for span in dropped {
        let last = span.end.saturating_sub(1).max(span.start);
        blank[line_of(span.start)..=line_of(last)].fill(true);
    }
    Some(
        source
            .split_inclusive('\n')
            .zip(blank)
            .map(|(line, blank)| match blank {
                true => &line[line.trim_end_matches(['\r', '\n']).len()..],
                false => line,
            })
            .collect(),
    )
}

/// Whether a statement at `path` belongs to the camera: anything under `camera` or `film`,
/// and of the sampler its header and `type` only.
fn kept(path: &[String], header: bool) -> bool {
    match path {
        [first, ..] if first == "camera" || first == "film" => true,
        [sampler] if sampler == "sampler" => header,
        [sampler, key] => sampler == "sampler" && key == "type",
        _ => false,
    }
}

/// Calls `f(path, span, is_header)` for every statement under `table` (at `path`): its header,
/// when written, then each `key = value` written under it (dotted keys included), then those
/// of its sub-tables. None when a statement has no position (never for a parsed document).
fn statements(
    table: &Table,
    path: &mut Vec<String>,
    f: &mut impl FnMut(&[String], Range<usize>, bool),
) -> Option<()> {
    // The root has no header, nor has a table made by dotted keys or only implied by a
    // deeper header; a dotted table's values are written under its parent's.
    let written = !path.is_empty() && !table.is_implicit() && !table.is_dotted();
    if written {
        f(path, table.span()?, true);
    }
    if !table.is_dotted() {
        for (keys, value) in table.get_values() {
            let key = keys.last()?.span()?;
            let full: Vec<String> = path
                .iter()
                .cloned()
                .chain(keys.iter().map(|k| k.get().to_string()))
                .collect();
            f(&full, key.start..value.span()?.end, false);
        }
    }
    for (key, item) in table.iter() {
        path.push(key.to_string());
        match item {
            Item::Table(t) => statements(t, path, f)?,
            Item::ArrayOfTables(a) => {
                for t in a.iter() {
                    statements(t, path, f)?;
                }
            }
            _ => {}
        }
        path.pop();
    }
    Some(())
}
