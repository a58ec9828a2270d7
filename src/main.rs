//! The `obscura` command: render a scene file, or check it.

use clap::{Parser, Subcommand};
use obscura_render::{
    ImageInfo, IntegratorKind, OutputFormat, RenderError, RenderOptions, RenderScene,
    load_description, render, write_image,
};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Obscura: camera models for ray tracing, and a renderer that composes them.
#[derive(Parser)]
#[command(name = "obscura", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file to an EXR or PNG image.
    Render {
        /// The scene file (TOML).
        scene: PathBuf,
        /// Output image, .exr or .png [default: the scene's name with .exr]
        #[arg(short = 'o', long = "output")]
        output: Option<PathBuf>,
        /// Samples per pixel (overrides the scene's)
        #[arg(long)]
        spp: Option<u32>,
        /// Sampler seed (overrides the scene's)
        #[arg(long)]
        seed: Option<u64>,
        /// Worker threads [default: one per core]
        #[arg(long)]
        threads: Option<usize>,
        /// Integrator: path, depth, distance, position, normal or albedo
        #[arg(long)]
        integrator: Option<String>,
        /// Image size as WIDTHxHEIGHT (overrides the scene's)
        #[arg(long)]
        resolution: Option<String>,
    },
    /// Parse and validate a scene, print a summary, render nothing.
    Check {
        /// The scene file (TOML).
        scene: PathBuf,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render {
            scene,
            output,
            spp,
            seed,
            threads,
            integrator,
            resolution,
        } => run_render(&scene, output, spp, seed, threads, integrator, resolution),
        Command::Check { scene } => run_check(&scene),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn setting(name: &'static str, message: impl Into<String>) -> RenderError {
    RenderError::Setting {
        name,
        message: message.into(),
    }
}

fn run_render(
    scene_path: &Path,
    output: Option<PathBuf>,
    spp: Option<u32>,
    seed: Option<u64>,
    threads: Option<usize>,
    integrator: Option<String>,
    resolution: Option<String>,
) -> Result<(), RenderError> {
    let output = output.unwrap_or_else(|| scene_path.with_extension("exr"));
    OutputFormat::from_path(&output)?;
    let folder = match output.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !folder.is_dir() {
        return Err(setting(
            "-o",
            format!(
                "{}: the folder {} does not exist",
                output.display(),
                folder.display()
            ),
        ));
    }
    if threads == Some(0) {
        return Err(setting("--threads", "must be >= 1, got 0"));
    }

    let mut description = load_description(scene_path)?;
    if let Some(spp) = spp {
        if spp == 0 {
            return Err(setting("--spp", "must be >= 1, got 0"));
        }
        description.sampler.spp = spp;
    }
    if let Some(seed) = seed {
        description.sampler.seed = seed;
    }
    if let Some(name) = integrator {
        description.integrator.kind = IntegratorKind::parse(&name).ok_or_else(|| {
            setting("--integrator", format!("unknown integrator `{name}`, expected path, depth, distance, position, normal or albedo"))
        })?;
    }
    if let Some(r) = resolution {
        description.film.resolution = parse_resolution(&r)?;
    }
    for note in &description.ignored {
        eprintln!("note: {note}");
    }
    let scene = RenderScene::build(description)?;
    report_skipped(&scene);

    let spp = scene.sampler.samples_per_pixel();
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = indicatif::ProgressBar::new(1);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {wide_bar} {percent:>3}% eta {eta}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar
    });
    let on_tile = |done: u64, total: u64| {
        if let Some(bar) = &bar {
            bar.set_length(total);
            bar.set_position(done);
        }
    };
    let outcome = render(
        &scene,
        RenderOptions {
            threads,
            on_tile: Some(&on_tile),
            ..RenderOptions::default()
        },
    )
    .map_err(|e| setting("--threads", format!("cannot start the worker threads: {e}")))?;
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let image = outcome.film.resolve();
    write_image(
        &output,
        &image,
        &ImageInfo {
            partial: false,
            samples_per_pixel: outcome.passes_done,
        },
    )?;

    let secs = outcome.elapsed.as_secs_f64().max(1e-9);
    let [w, h] = scene.description.film.resolution;
    let threads_used =
        threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let mut summary = format!(
        "rendered {} -> {}: {w}x{h}, {spp} spp, {} integrator, {:.2} M samples in {:.2} s ({:.2} M camera rays/s, {threads_used} threads)",
        scene_path.display(),
        output.display(),
        scene.integrator().name(),
        outcome.stats.samples as f64 / 1e6,
        secs,
        outcome.stats.samples as f64 / 1e6 / secs,
    );
    if outcome.stats.dropped_nonfinite > 0 {
        summary.push_str(&format!(
            "; {} NaN/infinite samples dropped",
            outcome.stats.dropped_nonfinite
        ));
    }
    println!("{summary}");
    Ok(())
}

fn parse_resolution(r: &str) -> Result<[u32; 2], RenderError> {
    let bad = || {
        setting(
            "--resolution",
            format!("expected WIDTHxHEIGHT with each >= 1, e.g. 640x480, got `{r}`"),
        )
    };
    let (w, h) = r.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if w == 0 || h == 0 {
        return Err(bad());
    }
    Ok([w, h])
}

fn report_skipped(scene: &RenderScene) {
    for (file, n) in &scene.skipped_triangles {
        eprintln!("note: {}: skipped {n} degenerate triangles", file.display());
    }
}

fn run_check(scene_path: &Path) -> Result<(), RenderError> {
    let description = load_description(scene_path)?;
    for note in &description.ignored {
        eprintln!("note: {note}");
    }
    let scene = RenderScene::build(description)?;
    report_skipped(&scene);
    let d = &scene.description;
    let kind = match d.camera.kind {
        obscura_render::CameraKind::Perspective => "perspective",
        obscura_render::CameraKind::Orthographic => "orthographic",
        obscura_render::CameraKind::Environment => "environment",
    };
    let lens =
        if d.camera.lens_radius > 0.0 && d.camera.kind != obscura_render::CameraKind::Environment {
            format!(
                " with a thin lens (radius {}, focused at {})",
                d.camera.lens_radius, d.camera.focal_distance
            )
        } else {
            String::new()
        };
    let moving = d
        .shapes
        .iter()
        .filter(|s| s.transform_end.is_some())
        .count();
    println!(
        "{}: ok: {}x{} {kind} camera{lens}{}, {} shapes ({moving} moving), {} materials, {} lights, {} integrator, {} sampler at {} spp, {} filter",
        scene_path.display(),
        d.film.resolution[0],
        d.film.resolution[1],
        if d.camera.end.is_some() {
            " (moving)"
        } else {
            ""
        },
        d.shapes.len(),
        d.materials.len(),
        d.lights.len() + d.shapes.iter().filter(|s| s.emission.is_some()).count(),
        d.integrator.kind.name(),
        d.sampler.kind.name(),
        d.sampler.spp,
        d.film.filter.name(),
    );
    Ok(())
}
