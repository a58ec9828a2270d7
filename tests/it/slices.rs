//! Slices and the exact merge (issue 23): `obscura render --slice i/N` on several "machines"
//! (processes with different thread counts), `obscura merge` in any order, compared bit for bit
//! with a one-process render; every bad set of parts refused with exit 2 and nothing written.

use super::{obscura, root, scratch, shipped};
use obscura_render::{Film, RenderOptions, RenderScene, render, tiles};
use proptest::prelude::*;
use std::path::{Path, PathBuf};

/// Runs `obscura ARGS`, returning (status code, stdout, stderr).
fn run<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> (i32, String, String) {
    let out = obscura().args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The small render every test here splits: the Cornell box at 40x30 (3x2 tiles of 16
/// pixels, the Gaussian filter reaching across tile edges), 7 samples per pixel.
fn scene_args(scene: &Path, integrator: &str) -> Vec<String> {
    [
        "render",
        scene.to_str().unwrap(),
        "--resolution",
        "40x30",
        "--spp",
        "7",
        "--seed",
        "11",
        "--integrator",
        integrator,
    ]
    .map(String::from)
    .to_vec()
}

fn cornell() -> PathBuf {
    root().join("scenes").join("cornell-box.toml")
}

/// Renders slice `i` of `n` by `by` with `threads` workers to `dir/name`; panics on failure.
fn render_slice(
    base: &[String],
    dir: &Path,
    name: &str,
    (i, n): (u32, u32),
    by: &str,
    threads: usize,
) -> PathBuf {
    let part = dir.join(name);
    let mut args = base.to_vec();
    args.extend(
        [
            "--slice",
            &format!("{i}/{n}"),
            "--slice-by",
            by,
            "--threads",
            &threads.to_string(),
            "-o",
            part.to_str().unwrap(),
        ]
        .map(String::from),
    );
    let (code, stdout, stderr) = run(&args);
    assert_eq!(code, 0, "slice {i}/{n} by {by}: {stderr}");
    assert!(
        stdout.contains(&format!("slice {i}/{n} by {by}")),
        "{stdout}"
    );
    part
}

/// Renders the whole image in one process to `out`.
fn render_whole(base: &[String], out: &Path, threads: usize) {
    let mut args = base.to_vec();
    args.extend(
        [
            "--threads",
            &threads.to_string(),
            "-o",
            out.to_str().unwrap(),
        ]
        .map(String::from),
    );
    let (code, _, stderr) = run(&args);
    assert_eq!(code, 0, "{stderr}");
}

/// Merges `parts` (in the order given) into `out`, returning (status, stderr).
fn merge(parts: &[PathBuf], out: &Path) -> (i32, String) {
    let mut args: Vec<String> = vec!["merge".into()];
    args.extend(parts.iter().map(|p| p.to_string_lossy().into_owned()));
    args.extend(["-o".into(), out.to_string_lossy().into_owned()]);
    let (code, _, stderr) = run(&args);
    (code, stderr)
}

/// Slices of N in {1, 2, 3, 7} by passes and by tiles (7 tile slices of 6 tiles: one slice is
/// empty), each slice with its own thread count, merged in a shuffled order: the same file,
/// byte for byte, as the one-process render.
#[test]
fn merged_slices_equal_the_one_process_render_bit_for_bit() {
    let dir = scratch("slices-exact");
    let base = scene_args(&cornell(), "path");
    let whole = dir.join("whole.exr");
    render_whole(&base, &whole, 2);
    let whole_bytes = std::fs::read(&whole).unwrap();
    for by in ["passes", "tiles"] {
        for n in [1u32, 2, 3, 7] {
            let mut parts: Vec<PathBuf> = (0..n)
                .map(|i| {
                    let threads = 1 + (i as usize * 2) % 3;
                    render_slice(
                        &base,
                        &dir,
                        &format!("{by}-{n}-{i}.part"),
                        (i, n),
                        by,
                        threads,
                    )
                })
                .collect();
            // Any order: reversed, then the first moved to the middle.
            parts.reverse();
            let first = parts.remove(0);
            parts.insert(parts.len() / 2, first);
            let merged = dir.join(format!("merged-{by}-{n}.exr"));
            let (code, stderr) = merge(&parts, &merged);
            assert_eq!(code, 0, "{by} {n}: {stderr}");
            assert!(
                std::fs::read(&merged).unwrap() == whole_bytes,
                "{n} slices by {by} merged to another image"
            );
        }
    }
}

/// An AOV (the depth integrator) and PNG output merge exactly too.
#[test]
fn an_aov_render_merges_exactly_to_png() {
    let dir = scratch("slices-aov");
    let scene = root().join("scenes").join("spheres-perspective.toml");
    let base = scene_args(&scene, "depth");
    let whole = dir.join("whole.png");
    render_whole(&base, &whole, 1);
    for by in ["passes", "tiles"] {
        let parts: Vec<PathBuf> = (0..3)
            .map(|i| render_slice(&base, &dir, &format!("{by}-{i}.part"), (i, 3), by, 2))
            .collect();
        let merged = dir.join(format!("merged-{by}.png"));
        assert_eq!(merge(&parts, &merged).0, 0);
        assert!(
            std::fs::read(&merged).unwrap() == std::fs::read(&whole).unwrap(),
            "{by}"
        );
    }
}

/// Every bad set of parts: exit 2, one message naming the fault, no image written and an
/// older one left as it was.
#[test]
fn merge_refuses_bad_sets_and_writes_nothing() {
    let dir = scratch("slices-refuse");
    let base = scene_args(&cornell(), "path");
    let part = |name: &str, i: u32, n: u32, by: &str, base: &[String]| {
        render_slice(base, &dir, name, (i, n), by, 1)
    };
    let p0 = part("p0.part", 0, 3, "passes", &base);
    let p1 = part("p1.part", 1, 3, "passes", &base);
    let p2 = part("p2.part", 2, 3, "passes", &base);

    // The same scene with a changed comment: another file, so another fingerprint.
    let edited = dir.join("edited.toml");
    let text = std::fs::read_to_string(cornell()).unwrap();
    std::fs::write(&edited, format!("# edited\n{text}")).unwrap();
    let other_scene = part("scene.part", 2, 3, "passes", &scene_args(&edited, "path"));
    let with = |flag: &str, value: &str| {
        let mut b = base.clone();
        let at = b.iter().position(|a| a == flag).unwrap();
        b[at + 1] = value.into();
        b
    };
    let other_seed = part("seed.part", 2, 3, "passes", &with("--seed", "12"));
    let other_spp = part("spp.part", 2, 3, "passes", &with("--spp", "8"));
    let other_integrator = part("integ.part", 2, 3, "passes", &with("--integrator", "depth"));
    let other_resolution = part("res.part", 2, 3, "passes", &with("--resolution", "40x31"));
    let by_tiles = part("tiles.part", 2, 3, "tiles", &base);
    let of_four = part("four.part", 2, 4, "passes", &base);

    let bytes = std::fs::read(&p2).unwrap();
    let truncated = dir.join("truncated.part");
    std::fs::write(&truncated, &bytes[..bytes.len() - 1]).unwrap();
    let flipped = dir.join("flipped.part");
    let mut f = bytes.clone();
    f[bytes.len() / 2] ^= 0x04;
    std::fs::write(&flipped, &f).unwrap();
    let header_flipped = dir.join("header-flipped.part");
    let mut h = bytes.clone();
    h[76] ^= 0x01; // the slice index: 2 becomes 3
    std::fs::write(&header_flipped, &h).unwrap();
    let not_a_part = dir.join("image.part");
    std::fs::write(&not_a_part, b"\x89PNG not a partial").unwrap();

    let cases: Vec<(&str, PathBuf, &str)> = vec![
        ("duplicate", p1.clone(), "duplicate"),
        ("scene", other_scene, "another scene"),
        ("seed", other_seed, "another seed"),
        ("spp", other_spp, "another sample count"),
        ("integrator", other_integrator, "another integrator"),
        ("resolution", other_resolution, "another resolution"),
        ("slicing", by_tiles, "sliced differently"),
        ("count", of_four, "sliced differently"),
        ("truncated", truncated, "truncated"),
        ("flipped", flipped, "checksum"),
        ("header", header_flipped, "checksum"),
        ("foreign", not_a_part, "not an obscura partial"),
    ];
    let out = dir.join("out.exr");
    let mut sets: Vec<(&str, Vec<PathBuf>, &str)> = vec![(
        "missing",
        vec![p1.clone(), p0.clone()],
        "missing 1 of 3 slices: 2",
    )];
    sets.extend(
        cases
            .into_iter()
            .map(|(what, third, expect)| (what, vec![p0.clone(), p1.clone(), third], expect)),
    );
    for (what, set, expect) in sets {
        std::fs::write(&out, b"an older image").unwrap();
        let (code, stderr) = merge(&set, &out);
        assert_eq!(code, 2, "{what}: {stderr}");
        assert!(stderr.contains(expect), "{what}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{what}: {stderr}");
        assert_eq!(std::fs::read(&out).unwrap(), b"an older image", "{what}");
        let strays: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().starts_with(".out.exr"))
            .collect();
        assert!(strays.is_empty(), "{what}: a temporary file was left");
    }
    // Into a folder that does not exist: the message names it, not a temporary file.
    let nowhere = dir.join("no-such-folder").join("out.exr");
    let (code, stderr) = merge(&[p0.clone(), p1.clone(), p2.clone()], &nowhere);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("no-such-folder does not exist") && !stderr.contains("partial"),
        "{stderr}"
    );
    // The good set merges.
    assert_eq!(merge(&[p2, p0, p1], &out).0, 0);
    assert_ne!(std::fs::read(&out).unwrap(), b"an older image");
}

#[test]
fn list_missing_prints_what_to_render_again() {
    let dir = scratch("slices-missing");
    let base = scene_args(&cornell(), "depth");
    let p1 = render_slice(&base, &dir, "p1.part", (1, 5), "tiles", 1);
    let p3 = render_slice(&base, &dir, "p3.part", (3, 5), "tiles", 1);
    // A corrupt part counts as missing: its slice has to be rendered again.
    let mut bytes = std::fs::read(&p3).unwrap();
    bytes.truncate(100);
    let broken = dir.join("p4.part");
    std::fs::write(&broken, &bytes).unwrap();
    let list = |args: &[&str]| {
        let mut all = vec!["merge", "--list-missing"];
        all.extend_from_slice(args);
        run(&all)
    };
    let (p1s, p3s, bs) = (
        p1.to_str().unwrap(),
        p3.to_str().unwrap(),
        broken.to_str().unwrap(),
    );
    let (code, stdout, stderr) = list(&[p3s, bs, p1s]);
    assert_eq!((code, stdout.as_str()), (0, "0,2,4\n"), "{stderr}");
    assert!(stderr.contains("p4.part"), "{stderr}");
    let (code, stdout, _) = list(&["--slices", "3", "nowhere.part"]);
    assert_eq!((code, stdout.as_str()), (0, "0,1,2\n"));
    // Parts of 5 slices while 3 are expected.
    assert_eq!(list(&["--slices", "3", p1s]).0, 2);
    // Without parts or --slices nobody knows N.
    assert_eq!(list(&["nowhere.part"]).0, 2);
    let mut all: Vec<PathBuf> = [0, 2, 4]
        .into_iter()
        .map(|i| render_slice(&base, &dir, &format!("q{i}.part"), (i, 5), "tiles", 2))
        .collect();
    all.extend([p1.clone(), p3.clone()]);
    let names: Vec<&str> = all.iter().map(|p| p.to_str().unwrap()).collect();
    assert_eq!(list(&names).1, "\n");
}

#[test]
fn bad_slice_flags_are_refused() {
    let dir = scratch("slices-flags");
    let base = scene_args(&cornell(), "depth");
    let part = dir.join("x.part");
    let p = part.to_str().unwrap();
    let ckpt = dir.join("x.ckpt");
    for (extra, expect) in [
        (vec!["--slice", "3/3", "-o", p], "numbered from 0"),
        (vec!["--slice", "0/0", "-o", p], "N must be >= 1"),
        (vec!["--slice", "1of2", "-o", p], "expected i/N"),
        (vec!["--slice", "0/2"], "needs -o PART"),
        (
            vec![
                "--slice",
                "0/2",
                "-o",
                p,
                "--checkpoint",
                ckpt.to_str().unwrap(),
            ],
            "--checkpoint",
        ),
        (vec!["--slice", "0/2", "-o", p, "--cube-map"], "--cube-map"),
        (
            vec!["--slice", "0/2", "--slice-by", "rows", "-o", p],
            "rows",
        ),
    ] {
        let mut args = base.clone();
        args.extend(extra.iter().map(|s| s.to_string()));
        let (code, _, stderr) = run(&args);
        assert_eq!(code, 2, "{extra:?}: {stderr}");
        assert!(stderr.contains(expect), "{extra:?}: {stderr}");
        assert!(!part.exists(), "{extra:?}");
    }
}

/// The film of a render split at arbitrary pass boundaries (and with the tiles split too),
/// each piece with its own thread count, adds up to the one-process film's exact sums.
fn split_film(cuts: &[u32], tile_cut: usize, threads: &[usize]) -> (Film, Film) {
    let mut d = shipped("cornell-box.toml");
    d.film.resolution = [24, 20];
    d.sampler.spp = 9;
    let scene = RenderScene::build(d).unwrap();
    let whole = render(
        &scene,
        RenderOptions {
            threads: Some(2),
            ..Default::default()
        },
    )
    .unwrap()
    .film;
    let tile_count = tiles(scene.pixel_bounds).len();
    let tile_cut = tile_cut % (tile_count + 1);
    let mut bounds: Vec<u32> = cuts.iter().map(|c| c % 10).collect();
    bounds.extend([0, 9]);
    bounds.sort_unstable();
    bounds.dedup();
    let mut merged = Film::new(scene.pixel_bounds);
    for (k, r) in bounds.windows(2).enumerate().rev() {
        for (j, t) in [0..tile_cut, tile_cut..tile_count].into_iter().enumerate() {
            let piece = render(
                &scene,
                RenderOptions {
                    threads: Some(threads[(k + j) % threads.len()]),
                    passes: Some(r[0]..r[1]),
                    tiles: Some(t),
                    ..Default::default()
                },
            )
            .unwrap();
            assert_eq!(piece.passes_done, r[1]);
            merged.add(&piece.film);
        }
    }
    (whole, merged)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]

    #[test]
    fn any_split_of_passes_and_tiles_merges_to_the_whole_film(
        cuts in proptest::collection::vec(0u32..10, 0..5),
        tile_cut in 0usize..10,
        threads in proptest::collection::vec(1usize..4, 1..4),
    ) {
        let (whole, merged) = split_film(&cuts, tile_cut, &threads);
        prop_assert!(whole.sums() == merged.sums());
    }
}
