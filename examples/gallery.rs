//! Makes the illustrated guide's pictures: every scene in `docs/gallery/` rendered and laid out
//! as a PNG beside it (see `docs/gallery.md`).
//!
//! ```text
//! cargo run --release --example gallery -- [--quick] [OUT_DIR]     # OUT_DIR: docs/gallery
//! ```
//!
//! `--quick` makes tiny, noisy pictures in seconds (what the tests run); `--only NAME` (repeatable)
//! makes just the named figures.

use camera_obscura::gallery::{Quality, generate_only};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    let mut quality = Quality::Full;
    let mut out_dir = None;
    let mut only: Vec<String> = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--quick" => quality = Quality::Quick,
            "--only" => match args.next() {
                Some(name) => only.push(name),
                None => {
                    eprintln!("error: --only needs a figure name");
                    return ExitCode::from(2);
                }
            },
            "-h" | "--help" => {
                println!("usage: gallery [--quick] [OUT_DIR]   (OUT_DIR defaults to docs/gallery)");
                return ExitCode::SUCCESS;
            }
            _ if arg.starts_with('-') => {
                eprintln!("error: unknown option {arg} (usage: gallery [--quick] [OUT_DIR])");
                return ExitCode::from(2);
            }
            _ if out_dir.is_none() => out_dir = Some(PathBuf::from(arg)),
            _ => {
                eprintln!("error: more than one OUT_DIR (usage: gallery [--quick] [OUT_DIR])");
                return ExitCode::from(2);
            }
        }
    }
    let out_dir = out_dir.unwrap_or_else(|| PathBuf::from("docs/gallery"));
    let start = Instant::now();
    let mut last = Instant::now();
    let only: Vec<&str> = only.iter().map(String::as_str).collect();
    let result = generate_only(&out_dir, quality, &only, |made| {
        println!(
            "{} ({}x{}, {:.1} s)",
            made.png.display(),
            made.size[0],
            made.size[1],
            last.elapsed().as_secs_f64()
        );
        for (column, row, mean) in made.hot_cells.iter().take(3) {
            println!(
                "  largest difference: grid cell column {column}, row {row} (of 4x3): mean {mean:.3}"
            );
        }
        last = Instant::now();
    });
    match result {
        Ok(made) => {
            println!(
                "{} pictures in {:.1} s",
                made.len(),
                start.elapsed().as_secs_f64()
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
