//! Robustness: interrupts write a partial image atomically (or nothing, on a second signal);
//! checkpoints resume to the same image bit for bit; NaN and infinite samples are counted and
//! dropped; random and mutated scene files never panic the parser or the scene builder.

use super::{obscura, root, scratch, write};
use obscura_render::{
    Checkpoint, RenderOptions, RenderScene, load_description, parse_description, read_exr, render,
    scene_fingerprint,
};
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

const SCENES: [&str; 5] = [
    "spheres-perspective.toml",
    "spheres-orthographic.toml",
    "spheres-thin-lens.toml",
    "spheres-motion-blur.toml",
    "spheres-environment.toml",
];

fn scene_path(name: &str) -> PathBuf {
    root().join("scenes").join(name)
}

/// Sends `signal` (e.g. "INT") to `child` with the system's `kill` command.
pub(super) fn send(child: &Child, signal: &str) {
    let status = Command::new("kill")
        .arg(format!("-{signal}"))
        .arg(child.id().to_string())
        .status()
        .expect("the kill command runs");
    assert!(status.success(), "kill -{signal} failed");
}

/// Polls `done` every few milliseconds. The timeout only bounds a failure; it does not
/// synchronise anything.
pub(super) fn wait_until(what: &str, mut done: impl FnMut() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "timed out waiting until {what}"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Starts a render that would take very long (a million samples per pixel), checkpointing
/// after every pass, and returns once its first checkpoint exists: the render is under way
/// and its signal handlers are installed.
fn start_long_render(dir: &Path, output: &Path) -> (Child, PathBuf) {
    let checkpoint = dir.join("long.ckpt");
    let child = obscura()
        .args([
            "render",
            scene_path("spheres-perspective.toml").to_str().unwrap(),
        ])
        .args(["-o", output.to_str().unwrap()])
        .args([
            "--resolution",
            "24x16",
            "--spp",
            "1000000",
            "--threads",
            "2",
        ])
        .args(["--checkpoint", checkpoint.to_str().unwrap()])
        .args(["--checkpoint-every", "0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_until("the first checkpoint is written", || checkpoint.exists());
    (child, checkpoint)
}

pub(super) fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn sigint_writes_the_partial_image_beside_the_older_one_and_exits_130() {
    let dir = scratch("sigint");
    let output = dir.join("out.exr");
    std::fs::write(&output, b"an older image").unwrap();
    let (child, checkpoint) = start_long_render(&dir, &output);
    send(&child, "INT");
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(
        stderr.contains("interrupted: wrote partial image") && stderr.contains("out.partial.exr"),
        "{stderr}"
    );
    // The older image is kept (SCENE_FORMAT.md: an interrupted render never destroys an older
    // one); the partial image is beside it, flagged partial in its header.
    assert_eq!(std::fs::read(&output).unwrap(), b"an older image");
    let (image, partial) = read_exr(&dir.join("out.partial.exr")).unwrap();
    assert!(partial);
    assert_eq!((image.width, image.height), (24, 16));
    // It holds exactly the passes of the checkpoint saved on the way out.
    let saved = Checkpoint::load(&checkpoint).unwrap();
    assert!(saved.passes_done >= 1 && saved.passes_done < 1_000_000);
    assert_eq!(saved.film.resolve(), image);
    assert!(
        stderr.contains(&format!("({} of 1000000 samples", saved.passes_done)),
        "{stderr}"
    );
    // Nothing else was left in the folder (no temporary files).
    assert_eq!(names_in(&dir), ["long.ckpt", "out.exr", "out.partial.exr"]);
}

#[test]
fn sigterm_writes_the_partial_image_where_nothing_was_and_exits_143() {
    let dir = scratch("sigterm");
    let output = dir.join("out.png");
    let (child, _) = start_long_render(&dir, &output);
    send(&child, "TERM");
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(143), "{stderr}");
    assert!(stderr.contains("partial image"), "{stderr}");
    // No older image was there, so the partial one takes the output's own name.
    let png = image::open(&output).unwrap();
    assert_eq!((png.width(), png.height()), (24, 16));
    assert_eq!(names_in(&dir), ["long.ckpt", "out.png"]);
}

/// Whether `/proc/PID/stat` says the process is stopped.
fn is_stopped(pid: u32) -> bool {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
    // The state follows the command name in parentheses: "PID (obscura) T ...".
    stat.rsplit_once(") ")
        .is_some_and(|(_, rest)| rest.starts_with('T'))
}

#[test]
fn a_second_signal_exits_at_once_and_keeps_the_older_output() {
    let dir = scratch("second-signal");
    let output = dir.join("out.exr");
    std::fs::write(&output, b"an older image").unwrap();
    let (child, _) = start_long_render(&dir, &output);
    // Two signals while the process is stopped are both pending when it continues, so both
    // handlers run before the render can notice the first: the second finds the flag set.
    // (Two SIGINTs would merge into one pending signal; SIGINT and SIGTERM do not.)
    send(&child, "STOP");
    wait_until("the render is stopped", || is_stopped(child.id()));
    send(&child, "INT");
    send(&child, "TERM");
    send(&child, "CONT");
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(!stderr.contains("wrote partial"), "{stderr}");
    assert_eq!(std::fs::read(&output).unwrap(), b"an older image");
}

/// Arguments shared by the straight and the resumed render.
const RESUME_SPP: u32 = 6;
const RESUME_RESOLUTION: &str = "24x16";

#[test]
fn a_resumed_render_equals_a_straight_one_bit_for_bit() {
    let dir = scratch("resume");
    let scene = scene_path("spheres-thin-lens.toml");
    let s = scene.to_str().unwrap();
    let run = |extra: &[&str], out: &Path| {
        let output = obscura()
            .args(["render", s, "-o", out.to_str().unwrap()])
            .args(["--resolution", RESUME_RESOLUTION])
            .args(["--spp", &RESUME_SPP.to_string()])
            .args(extra)
            .output()
            .unwrap();
        (
            output.status.code(),
            String::from_utf8_lossy(&output.stdout).into_owned(),
            String::from_utf8_lossy(&output.stderr).into_owned(),
        )
    };

    // The straight render.
    let straight = dir.join("straight.exr");
    let (code, _, stderr) = run(&["--threads", "2"], &straight);
    assert_eq!(code, Some(0), "{stderr}");

    // A render stopped after 2 of 6 passes through the library's cancel flag, saved the way
    // the command saves it.
    let mut description = load_description(&scene).unwrap();
    description.sampler.spp = RESUME_SPP;
    description.film.resolution = [24, 16];
    let fingerprint = scene_fingerprint(&std::fs::read(&scene).unwrap(), &description);
    let built = RenderScene::build(description).unwrap();
    let cancel = AtomicBool::new(false);
    let stop_after_two = |passes: u32, _: u32, _: &obscura_render::Film| {
        if passes == 2 {
            cancel.store(true, Ordering::SeqCst);
        }
    };
    let outcome = render(
        &built,
        RenderOptions {
            threads: Some(1),
            cancel: Some(&cancel),
            on_pass: Some(&stop_after_two),
            ..RenderOptions::default()
        },
    )
    .unwrap();
    assert_eq!(outcome.passes_done, 2);
    let checkpoint = dir.join("two.ckpt");
    Checkpoint {
        fingerprint,
        samples_per_pixel: RESUME_SPP,
        passes_done: 2,
        film: outcome.film.clone(),
    }
    .save(&checkpoint)
    .unwrap();

    // Resumed with another thread count: the same bytes.
    let resumed = dir.join("resumed.exr");
    let (code, stdout, stderr) = run(
        &["--threads", "3", "--resume", checkpoint.to_str().unwrap()],
        &resumed,
    );
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("resumed at 2"), "{stdout}");
    let straight_bytes = std::fs::read(&straight).unwrap();
    assert_eq!(std::fs::read(&resumed).unwrap(), straight_bytes);
    // Not vacuous: the two-pass image differs from the six-pass one.
    assert_ne!(outcome.film.resolve(), read_exr(&straight).unwrap().0);

    // The command's own checkpoints: saved at the end of a straight render, and resuming from
    // a complete checkpoint writes the same image again without rendering.
    let own = dir.join("own.ckpt");
    let again = dir.join("again.exr");
    let (code, _, stderr) = run(&["--checkpoint", own.to_str().unwrap()], &again);
    assert_eq!(code, Some(0), "{stderr}");
    assert_eq!(Checkpoint::load(&own).unwrap().passes_done, RESUME_SPP);
    let from_end = dir.join("from-end.exr");
    let (code, _, stderr) = run(&["--resume", own.to_str().unwrap()], &from_end);
    assert_eq!(code, Some(0), "{stderr}");
    assert_eq!(std::fs::read(&from_end).unwrap(), straight_bytes);

    // Refusals: other settings, a truncated file, garbage. Exit 2, one line naming the
    // checkpoint, nothing written.
    let ck = checkpoint.to_str().unwrap();
    let bytes = std::fs::read(&checkpoint).unwrap();
    let truncated = write(&dir, "truncated.ckpt", "");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let flipped = dir.join("flipped.ckpt");
    let mut corrupt = bytes.clone();
    corrupt[bytes.len() / 2] ^= 1;
    std::fs::write(&flipped, &corrupt).unwrap();
    let garbage = write(&dir, "garbage.ckpt", "not a checkpoint at all");
    let refused = dir.join("refused.exr");
    for (extra, name, why) in [
        (vec!["--resume", ck, "--seed", "9"], "two.ckpt", "different"),
        (
            vec!["--resume", ck, "--integrator", "depth"],
            "two.ckpt",
            "different",
        ),
        (
            vec!["--resume", ck, "--resolution", "8x8"],
            "two.ckpt",
            "resolution",
        ),
        (
            vec!["--resume", truncated.to_str().unwrap()],
            "truncated.ckpt",
            "truncated",
        ),
        (
            vec!["--resume", flipped.to_str().unwrap()],
            "flipped.ckpt",
            "checksum",
        ),
        (
            vec!["--resume", garbage.to_str().unwrap()],
            "garbage.ckpt",
            "not an obscura checkpoint",
        ),
    ] {
        let output = obscura()
            .args(["render", s, "-o", refused.to_str().unwrap()])
            .args(["--spp", &RESUME_SPP.to_string()])
            .args(if extra.contains(&"--resolution") {
                vec![]
            } else {
                vec!["--resolution", RESUME_RESOLUTION]
            })
            .args(&extra)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{extra:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{extra:?}: {stderr}");
        assert!(
            stderr.contains(name) && stderr.contains(why),
            "{extra:?}: {stderr}"
        );
        assert!(!refused.exists(), "{extra:?} wrote an image");
    }
}

/// A wall lit by a point light of intensity near `f32::MAX` just in front of it: near the
/// light, intensity x reflectance/pi x cos / d^2 overflows f32 (right under it, 3e38 x 0.25 x 1
/// / 0.2^2 = 1.9e39), so those samples are infinite or NaN; far from it (the corners of a
/// 60-degree view) the light falls off and stays finite.
const OVERFLOWING_SCENE: &str = r#"
[film]
resolution = [16, 16]
[sampler]
type = "independent"
spp = 2
[integrator]
type = "path"
max_depth = 2
[camera]
eye = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 60.0
[materials.wall]
type = "diffuse"
reflectance = [0.8, 0.8, 0.8]
[[shapes]]
type = "quad"
origin = [-10.0, -10.0, 0.0]
edge_u = [20.0, 0.0, 0.0]
edge_v = [0.0, 20.0, 0.0]
material = "wall"
[[lights]]
type = "point"
position = [0.0, 0.0, 0.2]
intensity = [3.0e38, 3.0e38, 3.0e38]
"#;

#[test]
fn non_finite_samples_are_counted_and_never_reach_the_image() {
    let dir = scratch("nonfinite");
    let scene_file = write(&dir, "overflow.toml", OVERFLOWING_SCENE);
    let description = parse_description(&scene_file, OVERFLOWING_SCENE).unwrap();
    let scene = RenderScene::build(description).unwrap();
    let outcome = render(
        &scene,
        RenderOptions {
            threads: Some(2),
            ..RenderOptions::default()
        },
    )
    .unwrap();
    let dropped = outcome.stats.dropped_nonfinite;
    // 16 x 16 pixels x 2 samples = 512 samples; some, not all, overflow.
    assert!(dropped > 0 && dropped < 512, "dropped {dropped}");
    let image = outcome.film.resolve();
    assert!(image.pixels.iter().flatten().all(|v| v.is_finite()));
    // Pixels far from the light are lit finitely, so the image is not simply black.
    assert!(image.pixel(0, 0)[0] > 0.0);

    // The command reports the count in its summary, and the file holds no NaN or infinity.
    let exr = dir.join("overflow.exr");
    let out = obscura()
        .args([
            "render",
            scene_file.to_str().unwrap(),
            "-o",
            exr.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0));
    assert!(
        stdout.contains(&format!("; {dropped} NaN/infinite samples dropped")),
        "{stdout}"
    );
    let (written, _) = read_exr(&exr).unwrap();
    assert!(written.pixels.iter().flatten().all(|v| v.is_finite()));
}

/// Parses and builds `text` as a scene file; the result may be `Ok` or `Err` but must not
/// panic.
fn parse_and_build(text: &str) -> Result<(), String> {
    let file = Path::new("/nonexistent/obscura-fuzz/mutated.toml");
    let result = std::panic::catch_unwind(|| {
        if let Ok(description) = parse_description(file, text) {
            // Big images are valid; building never allocates the film, so it stays cheap.
            let _ = RenderScene::build(description);
        }
    });
    result.map_err(|panic| {
        panic
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default()
    })
}

/// One edit of a file's bytes.
#[derive(Clone, Debug)]
enum Mutation {
    Flip {
        at: usize,
        mask: u8,
    },
    Delete {
        at: usize,
        len: usize,
    },
    Duplicate {
        at: usize,
        len: usize,
    },
    Insert {
        at: usize,
        byte: u8,
    },
    Truncate {
        at: usize,
    },
    /// Replaces the `at`-th number in the file (modulo their count) by `value`.
    Number {
        at: usize,
        value: &'static str,
    },
}

/// Values at the edges of what the scene format accepts.
const EDGE_NUMBERS: [&str; 14] = [
    "0",
    "-0.0",
    "-1",
    "1e-38",
    "3.4e38",
    "1e39",
    "nan",
    "inf",
    "-inf",
    "180",
    "4294967296",
    "65536",
    "1e-7",
    "0.5",
];

/// The byte ranges of the numbers in `bytes` (runs of digits, signs, dots and exponents that
/// start with a digit or a minus sign).
fn number_spans(bytes: &[u8]) -> Vec<(usize, usize)> {
    let numeric = |b: u8| b.is_ascii_digit() || matches!(b, b'-' | b'+' | b'.' | b'e' | b'E');
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit() || bytes[i] == b'-';
        let after_word = i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
        if starts && !after_word {
            let mut j = i;
            while j < bytes.len() && numeric(bytes[j]) {
                j += 1;
            }
            spans.push((i, j));
            i = j;
        } else {
            i += 1;
        }
    }
    spans
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 1u8..).prop_map(|(at, mask)| Mutation::Flip { at, mask }),
        (any::<usize>(), 1usize..40).prop_map(|(at, len)| Mutation::Delete { at, len }),
        (any::<usize>(), 1usize..80).prop_map(|(at, len)| Mutation::Duplicate { at, len }),
        // Bytes that matter to TOML and numbers more often than others.
        (
            any::<usize>(),
            prop_oneof![
                Just(b'-'),
                Just(b'0'),
                Just(b'9'),
                Just(b'e'),
                Just(b'.'),
                Just(b'['),
                Just(b']'),
                Just(b'"'),
                Just(b'\n'),
                any::<u8>()
            ]
        )
            .prop_map(|(at, byte)| Mutation::Insert { at, byte }),
        any::<usize>().prop_map(|at| Mutation::Truncate { at }),
        (any::<usize>(), proptest::sample::select(&EDGE_NUMBERS[..]))
            .prop_map(|(at, value)| Mutation::Number { at, value }),
        (any::<usize>(), proptest::sample::select(&EDGE_NUMBERS[..]))
            .prop_map(|(at, value)| Mutation::Number { at, value }),
    ]
}

fn apply(bytes: &mut Vec<u8>, m: &Mutation) {
    let n = bytes.len();
    if n == 0 {
        return;
    }
    match *m {
        Mutation::Flip { at, mask } => bytes[at % n] ^= mask,
        Mutation::Delete { at, len } => {
            let at = at % n;
            bytes.drain(at..(at + len).min(n));
        }
        Mutation::Duplicate { at, len } => {
            let at = at % n;
            let piece = bytes[at..(at + len).min(n)].to_vec();
            bytes.splice(at..at, piece);
        }
        Mutation::Insert { at, byte } => bytes.insert(at % (n + 1), byte),
        Mutation::Truncate { at } => bytes.truncate(at % n),
        Mutation::Number { at, value } => {
            let spans = number_spans(bytes);
            if let Some(&(a, b)) = spans.get(at % spans.len().max(1)) {
                bytes.splice(a..b, value.bytes());
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn mutated_shipped_scenes_never_panic(
        which in 0..SCENES.len(),
        mutations in proptest::collection::vec(mutation(), 1..6),
    ) {
        let mut bytes = std::fs::read(scene_path(SCENES[which])).unwrap();
        for m in &mutations {
            apply(&mut bytes, m);
        }
        let text = String::from_utf8_lossy(&bytes);
        prop_assert!(parse_and_build(&text).is_ok(), "panicked on {text:?}");
    }

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let text = String::from_utf8_lossy(&bytes);
        prop_assert!(parse_and_build(&text).is_ok());
    }

    #[test]
    fn random_toml_shaped_text_never_panics(
        lines in proptest::collection::vec(
            "(\\[[a-z]{1,10}\\]|\\[\\[[a-z]{1,8}\\]\\]|[a-z_]{1,12} = (-?[0-9]{1,3}(\\.[0-9]{0,3})?(e[0-9]{1,2})?|\"[a-z]{0,8}\"|\\[-?[0-9.]{1,4}, -?[0-9.]{1,4}(, -?[0-9.]{1,4})?\\]|true|nan|inf))",
            0..30,
        ),
    ) {
        let text = lines.join("\n");
        prop_assert!(parse_and_build(&text).is_ok(), "panicked on {text:?}");
    }
}

#[test]
fn overflowing_camera_arithmetic_gives_no_ray_not_a_nan_ray() {
    // Found by the camera fuzz target: an orthographic thin lens with a screen window up to
    // 1.9e34 and a film position of 4.5e30 overflowed to a NaN origin and a zero direction.
    use obscura_camera::{Camera, CameraSample};
    use obscura_space::Point2;
    let text = r#"[film]
resolution = [110, 110]
[camera]
type = "orthographic"
screen_window = [-5.148387e-17, 4.5925147e27, 4.5925147e27, 1.8588872e34]
lens_radius = 7.2064745e31
focal_distance = 1.1561e-41
eye = [-7.943588e-11, -7.943633e-11, -7.943633e-11]
target = [-7.943633e-11, -7.943633e-11, -7.943633e-11]
shutter = [4.597445e27, 4.669886e27]
near = 4.5925147e27
"#;
    let d = obscura_render::parse_description(Path::new("fuzz.toml"), text).unwrap();
    let camera = obscura_render::camera_of(&d).unwrap();
    let traceable = |o: [f32; 3], d: [f32; 3]| {
        o.iter().chain(&d).all(|v| v.is_finite()) && d.iter().any(|&v| v != 0.0)
    };
    let coords = [0.5f32, 55.0, 109.5, 1e6, 1.3417982e28, 4.5238512e30, -1e30];
    for &x in &coords {
        for &y in &coords {
            let mut sample = CameraSample::at(Point2::new(x, y));
            sample.p_lens = glam::Vec2::new(0.3, 0.8);
            if let Some(r) = camera.generate_ray(&sample) {
                let (o, dir) = (r.ray.origin, r.ray.direction);
                assert!(
                    traceable([o.x, o.y, o.z], [dir.x, dir.y, dir.z]),
                    "({x}, {y}): {r:?}"
                );
            }
            if let Some(r) = camera.generate_ray_differential(&sample) {
                for (o, dir) in [
                    (r.ray.origin, r.ray.direction),
                    (r.rx_origin, r.rx_direction),
                    (r.ry_origin, r.ry_direction),
                ] {
                    assert!(
                        traceable([o.x, o.y, o.z], [dir.x, dir.y, dir.z]),
                        "({x}, {y}): {r:?}"
                    );
                }
            }
        }
    }
    // The fuzzer's own sample gives no ray now.
    let mut sample = CameraSample::at(Point2::new(4.5238512e30, 1.3417982e28));
    sample.p_lens = glam::Vec2::ZERO;
    assert!(camera.generate_ray(&sample).is_none());

    // The second find: a thin lens at the scale of 1e-22, where squaring a direction's
    // components underflows and its normalisation came out 1.0075 long.
    let text = r#"[film]
resolution = [1, 66]
[camera]
type = "perspective"
fov = 1.2830058e-22
lens_radius = 1.2830058e-22
focal_distance = 1.2830058e-22
lens_shift = [1.2830058e-22, 1.2830058e-22]
eye = [2.3509887e-38, 0e0, 1.0753431e-22]
target = [1.2830058e-22, 1.2830058e-22, 1.2830058e-22]
near = 1.2830058e-22
"#;
    let d = obscura_render::parse_description(Path::new("fuzz.toml"), text).unwrap();
    let camera = obscura_render::camera_of(&d).unwrap();
    for y in [0.5f32, 33.0, 65.5] {
        for lens in [glam::Vec2::new(0.1, 0.9), glam::Vec2::new(0.7, 0.2)] {
            let mut sample = CameraSample::at(Point2::new(0.5, y));
            sample.p_lens = lens;
            if let Some(r) = camera.generate_ray(&sample) {
                let dir = r.ray.direction;
                let len = (dir.x * dir.x + dir.y * dir.y + dir.z * dir.z).sqrt();
                assert!((len - 1.0).abs() < 1e-3, "({y}, {lens}): length {len}");
            }
        }
    }

    // The third: a cylindrical camera of fov 1e-45 degrees projected a point to (1, inf).
    let text = r#"[film]
resolution = [1, 1]
[camera]
type = "cylindrical"
fov = 1e-45
eye = [-3.0517578e-5, -3.5424324e-4, -3.5424324e-4]
target = [2.1540213e8, 2.153771e8, 2.4712324e-33]
near = 1.6495023e-33
"#;
    let d = obscura_render::parse_description(Path::new("fuzz.toml"), text).unwrap();
    let camera = obscura_render::camera_of(&d).unwrap();
    for x in [0.1f32, 0.5, 0.9] {
        for y in [0.1f32, 0.5, 0.9] {
            let Some(r) = camera.generate_ray(&CameraSample::at(Point2::new(x, y))) else {
                continue;
            };
            for t in [1e-3f32, 1.0, 1e3] {
                let p = r.ray.origin + r.ray.direction * t;
                if let Some(q) = camera.project(p, 0.0) {
                    assert!(
                        q.x.is_finite() && q.y.is_finite(),
                        "({x}, {y}) at {t}: {q:?}"
                    );
                }
            }
            let off = r.ray.origin + obscura_space::Vector3::new(1.0, 1.0, 1.0);
            if let Some(q) = camera.project(off, 0.0) {
                assert!(q.x.is_finite() && q.y.is_finite(), "off the ray: {q:?}");
            }
        }
    }
}
