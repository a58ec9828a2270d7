//! OBJ files: good ones load (polygons triangulated, groups merged), bad ones are errors that
//! name the file and the line.

use obscura_accel::{AccelError, load_obj};
use std::path::PathBuf;

/// Writes `contents` to a fresh file in the temporary directory and returns its path.
fn fixture(name: &str, contents: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("obscura-accel-obj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap();
    path
}

/// Loads a bad fixture and returns its error message, checking it names the file.
fn error_of(name: &str, contents: &[u8]) -> (AccelError, String) {
    let path = fixture(name, contents);
    let err = load_obj(&path).expect_err("a bad file must be an error");
    let message = err.to_string();
    assert!(
        message.contains(name),
        "the message must name the file: {message}"
    );
    (err, message)
}

const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

#[test]
fn polygons_are_triangulated_and_groups_merged() {
    // A square face (2 triangles) in object "a", a triangle in group "b", and a pentagon
    // (3 triangles) in object "c": 6 triangles in one mesh.
    let text = format!(
        "{SQUARE}v 2 0 0\nv 3 0 0\nv 3 1 0\nv 2.5 2 0\nv 2 1 0\n\
         o a\nf 1 2 3 4\ng b\nf 1 2 3\no c\nf 5 6 7 8 9\n"
    );
    let mesh = load_obj(&fixture("good.obj", text.as_bytes())).unwrap();
    assert_eq!(mesh.triangle_count(), 6);
    assert_eq!(mesh.skipped_degenerate(), 0);
    assert!(mesh.normals().is_none());
    assert_eq!(mesh.bounds().max.x, 3.0);
    assert_eq!(mesh.bounds().max.y, 2.0);
}

#[test]
fn normals_and_uvs_are_kept_and_degenerate_faces_counted() {
    // Two faces with normals and uvs; the second repeats vertex 1 (zero area) and is skipped.
    let text = format!(
        "{SQUARE}vn 0 0 1\nvt 0 0\nvt 1 0\nvt 1 1\n\
         f 1/1/1 2/2/1 3/3/1\nf 1/1/1 1/1/1 3/3/1\n"
    );
    let mesh = load_obj(&fixture("attributes.obj", text.as_bytes())).unwrap();
    assert_eq!(mesh.triangle_count(), 1);
    assert_eq!(mesh.skipped_degenerate(), 1);
    let normals = mesh.normals().expect("the file has normals");
    assert!(normals.iter().all(|n| *n == glam::Vec3::Z));
    assert!(mesh.uvs().is_some());
}

#[test]
fn missing_file_is_named() {
    let path = std::env::temp_dir().join("obscura-accel-no-such-file.obj");
    let message = load_obj(&path).unwrap_err().to_string();
    assert!(
        message.contains("obscura-accel-no-such-file.obj"),
        "{message}"
    );
    assert!(message.contains("cannot read"), "{message}");
}

#[test]
fn out_of_range_index_names_the_line() {
    // Line 5 is the face; the file has 4 vertices.
    let (err, message) = error_of("bad_index.obj", format!("{SQUARE}f 1 2 9\n").as_bytes());
    assert!(
        matches!(err, AccelError::Obj { line: Some(5), .. }),
        "{message}"
    );
    assert!(
        message.ends_with(
            "bad_index.obj: line 5: face index 9 out of range (the file has 4 vertices)"
        ),
        "{message}"
    );
    // Negative indices count back: -5 is before the first vertex.
    let (_, message) = error_of(
        "bad_negative.obj",
        format!("{SQUARE}f -1 -2 -5\n").as_bytes(),
    );
    assert!(message.contains("line 5"), "{message}");
}

#[test]
fn truncated_files_name_the_line() {
    // The last vertex lost its z (line 4), or the last face lost its vertices (line 5).
    let (_, message) = error_of("truncated_v.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1");
    assert!(
        message.contains("line 4") && message.contains("truncated"),
        "{message}"
    );
    let (_, message) = error_of("truncated_f.obj", format!("{SQUARE}f 1 2").as_bytes());
    assert!(
        message.contains("line 5") && message.contains("at least 3"),
        "{message}"
    );
    // A number cut in the middle of its exponent does not parse.
    let (_, message) = error_of("truncated_num.obj", b"v 0 0 0\nv 1 0 1e\n");
    assert!(
        message.contains("line 2") && message.contains("cannot parse"),
        "{message}"
    );
}

#[test]
fn faces_of_fewer_than_three_vertices_are_errors() {
    let (_, message) = error_of(
        "two_vertex_face.obj",
        format!("{SQUARE}\nf 1 2 3\nf 1 2\n").as_bytes(),
    );
    assert!(
        message.contains("line 7") && message.contains("a face of 2 vertices"),
        "{message}"
    );
}

#[test]
fn nan_and_infinite_coordinates_are_errors() {
    let (_, message) = error_of("nan.obj", b"v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    assert!(
        message.contains("line 2") && message.contains("NaN"),
        "{message}"
    );
    let (_, message) = error_of("inf.obj", b"v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n");
    assert!(
        message.contains("line 3") && message.contains("infinite"),
        "{message}"
    );
}

#[test]
fn an_empty_mesh_is_an_error() {
    let (_, message) = error_of("no_faces.obj", SQUARE.as_bytes());
    assert!(message.contains("no faces"), "{message}");
    let (_, message) = error_of("empty.obj", b"");
    assert!(message.contains("no faces"), "{message}");
    // Faces that all have zero area leave nothing either.
    let (_, message) = error_of(
        "all_degenerate.obj",
        format!("{SQUARE}f 1 1 2\n").as_bytes(),
    );
    assert!(message.contains("zero area"), "{message}");
}

#[test]
fn a_binary_file_is_refused() {
    // The start of a PNG file, renamed .obj.
    let png = [
        0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n', 0, 0, 0, 13, b'I', b'H',
    ];
    let (_, message) = error_of("image.obj", &png);
    assert!(message.contains("not a text OBJ file"), "{message}");
    // Invalid UTF-8 without a NUL byte is refused too.
    let (_, message) = error_of("latin1.obj", b"v 0 0 0\n\xff\xfe garbage\n");
    assert!(
        message.contains("line 2") && message.contains("not a text OBJ file"),
        "{message}"
    );
}

#[test]
fn garbage_statements_name_the_line() {
    let (_, message) = error_of(
        "garbage.obj",
        format!("{SQUARE}f 1 2 3\nhello world\n").as_bytes(),
    );
    assert!(
        message.contains("line 6") && message.contains("unknown statement"),
        "{message}"
    );
}
