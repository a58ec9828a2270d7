//! Finding the line of a key in a TOML scene file, for error messages.
//!
//! Serde reports byte spans for syntax and type errors; checks made after parsing (a fov out of
//! range, an undefined material) know only the key's path. This module maps both to a line, by
//! reading the file the way a person does: table headers, then `key =` lines below them.

/// The 1-based line holding byte offset `at`.
pub(crate) fn line_of_offset(source: &str, at: usize) -> usize {
    source[..at.min(source.len())]
        .bytes()
        .filter(|&b| b == b'\n')
        .count()
        + 1
}

/// The table header in force at each line: `camera`, `shapes[2]`, `materials.white`, or "".
fn headers(source: &str) -> Vec<(usize, String)> {
    let mut counts: std::collections::HashMap<String, usize> = Default::default();
    let mut current = String::new();
    let mut out = Vec::new();
    for (i, line) in source.lines().enumerate() {
        let t = line.trim();
        if let Some(name) = t.strip_prefix("[[").and_then(|r| r.split("]]").next()) {
            let name = name.trim().to_string();
            let n = counts.entry(name.clone()).or_insert(0);
            current = format!("{name}[{n}]");
            *n += 1;
        } else if let Some(name) = t.strip_prefix('[').and_then(|r| r.split(']').next()) {
            current = name.trim().to_string();
        }
        out.push((i + 1, current.clone()));
    }
    out
}

/// The key written on a `key = value` line, if it is one.
fn key_on(line: &str) -> Option<&str> {
    let t = line.trim();
    if t.starts_with('[') || t.starts_with('#') {
        return None;
    }
    let (key, _) = t.split_once('=')?;
    Some(key.trim().trim_matches('"'))
}

/// The line where `path` (e.g. `camera.fov`, `shapes[2].transform[0]`) is written: the key's
/// own line when found, else its table's header line.
pub(crate) fn line_of_key(source: &str, path: &str) -> Option<usize> {
    let lines: Vec<&str> = source.lines().collect();
    let mut header_line = None;
    // The table's own header beats an enclosing one's (`[camera.stereo]` over `[camera]` for
    // the key `camera.stereo`).
    let mut own_header_line = None;
    for (n, header) in headers(source) {
        let rest = if header.is_empty() {
            Some(path)
        } else if path == header {
            own_header_line = own_header_line.or(Some(n));
            None
        } else {
            path.strip_prefix(header.as_str())
                .and_then(|r| r.strip_prefix('.'))
        };
        let Some(rest) = rest else { continue };
        // The innermost enclosing table's header: `[camera.stereo]` over `[camera]`.
        if !header.is_empty() && header_line.is_none_or(|(len, _)| header.len() > len) {
            header_line = Some((header.len(), n));
        }
        // The first segment of the rest, without an index: `transform[0].rotate` -> `transform`.
        let first = rest.split(['.', '[']).next().unwrap_or(rest);
        if key_on(lines[n - 1]) == Some(first) {
            return Some(n);
        }
    }
    own_header_line.or(header_line.map(|(_, n)| n))
}

/// The key path of the `key = value` line at `line`, qualified by its table: for serde errors,
/// which carry a span but no key.
pub(crate) fn key_at_line(source: &str, line: usize) -> Option<String> {
    let (_, header) = headers(source).into_iter().find(|(n, _)| *n == line)?;
    let text = source.lines().nth(line - 1)?;
    match key_on(text) {
        Some(key) if header.is_empty() => Some(key.to_string()),
        Some(key) => Some(format!("{header}.{key}")),
        None if !header.is_empty() => Some(header),
        None => None,
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

    #[test]
    fn lines_give_their_keys() {
        assert_eq!(key_at_line(SCENE, 6).as_deref(), Some("camera.fov"));
        assert_eq!(key_at_line(SCENE, 8).as_deref(), Some("shapes[0]"));
        assert_eq!(key_at_line(SCENE, 13).as_deref(), Some("shapes[1].origin"));
        assert_eq!(line_of_offset(SCENE, 0), 1);
        assert_eq!(line_of_offset(SCENE, SCENE.find("fov").unwrap()), 6);
    }
}
