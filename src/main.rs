//! The `obscura` command: render a scene file, or check it.

use clap::{Parser, Subcommand};
use obscura_camera::CubeFace;
use obscura_import::Imported;
use obscura_render::{
    CameraKind, Checkpoint, Film, ImageInfo, IntegratorKind, OutputFormat, Partial, RenderError,
    RenderOptions, RenderScene, SceneDescription, Slice, SliceBy, StereoLayout, compose_stereo,
    merge_partials, render, scene_fingerprint, write_image,
};
use signal_hook::consts::{SIGINT, SIGTERM};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The most worker threads per core `--threads` gets.
const MAX_THREADS_PER_CORE: usize = 4;

/// Exit status after a second interrupt, which quits at once without writing.
const EXIT_SECOND_SIGNAL: i32 = 130;

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
    Render(RenderArgs),
    /// Parse and validate a scene, print a summary, render nothing.
    Check {
        /// The scene file (TOML, or pbrt-v4 .pbrt, or Mitsuba 3 .xml).
        scene: PathBuf,
    },
    /// Convert a pbrt-v4 (.pbrt) or Mitsuba 3 (.xml) scene to Obscura's TOML, its meshes to
    /// OBJ files in OUT-meshes/ beside it.
    Convert {
        /// The scene file (.pbrt or .xml).
        scene: PathBuf,
        /// The TOML file to write [default: the scene's name with .toml]
        #[arg(short = 'o', long = "output")]
        output: Option<PathBuf>,
    },
    /// Merge the partial films of `obscura render --slice i/N` into the image a single render
    /// makes, bit for bit.
    Merge(MergeArgs),
    /// Explore a scene's camera in the browser: a local server that renders progressively.
    Serve(ServeArgs),
}

/// The `merge` subcommand's arguments.
#[derive(clap::Args)]
struct MergeArgs {
    /// The partial files, one per slice, in any order.
    #[arg(value_name = "PARTS")]
    parts: Vec<PathBuf>,
    /// Output image, .exr or .png
    #[arg(short = 'o', long = "output", required_unless_present = "list_missing")]
    output: Option<PathBuf>,
    /// Print the indices of the slices missing from PARTS, comma-separated on one line (empty
    /// when none is), and write nothing; unreadable or corrupt parts count as missing
    #[arg(long)]
    list_missing: bool,
    /// The number of slices N [default: as the parts say]; needed by --list-missing when no
    /// part is readable
    #[arg(long, value_name = "N")]
    slices: Option<u32>,
}

/// The `serve` subcommand's arguments.
#[derive(clap::Args)]
struct ServeArgs {
    /// The scene file (TOML).
    #[arg(value_name = "SCENE")]
    scene: PathBuf,
    /// Port to listen on; 0 picks a free one (the URL printed says which)
    #[arg(long, default_value_t = 8080)]
    port: u16,
    /// Address to listen on; anything but loopback exposes the explorer to the network
    #[arg(long, default_value = "127.0.0.1")]
    host: std::net::IpAddr,
    /// Render threads per page [default: one per core]
    #[arg(long)]
    threads: Option<usize>,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => run_render(args),
        Command::Check { scene } => run_check(&scene).map(|()| ExitCode::SUCCESS),
        Command::Convert { scene, output } => {
            run_convert(&scene, output).map(|()| ExitCode::SUCCESS)
        }
        Command::Merge(args) => run_merge(args),
        Command::Serve(args) => {
            if args.threads == Some(0) {
                eprintln!("error: --threads: must be >= 1, got 0");
                return ExitCode::from(2);
            }
            let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
            let threads = args.threads.map(|n| n.min(MAX_THREADS_PER_CORE * cores));
            // The explorer's errors are its own; print them here with the same exit status.
            if let Err(e) = obscura_explore::run(obscura_explore::ServeOptions {
                scene: args.scene,
                host: args.host,
                port: args.port,
                threads,
            }) {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
            Ok(ExitCode::SUCCESS)
        }
    };
    match result {
        Ok(code) => code,
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

/// The `render` subcommand's arguments.
#[derive(clap::Args)]
struct RenderArgs {
    /// The scene file (TOML, or pbrt-v4 .pbrt, or Mitsuba 3 .xml).
    #[arg(value_name = "SCENE")]
    scene_path: PathBuf,
    /// Output image, .exr or .png [default: the scene's name with .exr]
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Samples per pixel (overrides the scene's)
    #[arg(long)]
    spp: Option<u32>,
    /// Sampler seed (overrides the scene's)
    #[arg(long)]
    seed: Option<u64>,
    /// Worker threads, for the BVH build and the render [default: one per core]
    #[arg(long)]
    threads: Option<usize>,
    /// Integrator: path, depth, distance, position, normal or albedo
    #[arg(long)]
    integrator: Option<String>,
    /// Image size as WIDTHxHEIGHT (overrides the scene's)
    #[arg(long)]
    resolution: Option<String>,
    /// Save the film's sums to this file now and then, on interrupt and at the end
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints (0: after every pass)
    #[arg(long, value_name = "SECONDS", default_value_t = 60.0)]
    checkpoint_every: f64,
    /// Continue a render from a checkpoint made with the same scene and flags
    #[arg(long, value_name = "FILE")]
    resume: Option<PathBuf>,
    /// Render the six 90-degree faces of a cube map from the scene's camera position, to
    /// OUT-px, OUT-nx, OUT-py, OUT-ny, OUT-pz, OUT-nz (OpenGL order; the film must be square)
    #[arg(long)]
    cube_map: bool,
    /// Render only slice i of N (0 <= i < N) and write its partial film to -o PART, for
    /// `obscura merge`
    #[arg(long, value_name = "i/N")]
    slice: Option<String>,
    /// What --slice splits: passes (sample indices; each slice covers the whole image) or
    /// tiles (each slice takes every sample of its share of the image)
    #[arg(long, value_name = "KIND", default_value = "passes", value_parser = ["passes", "tiles"])]
    slice_by: String,
}

/// SIGINT and SIGTERM handling: the first sets `cancel` (the render stops at the next pass
/// boundary and the partial image is written) and records which signal; a second one exits at
/// once with status 130, writing nothing.
struct Interrupts {
    cancel: Arc<AtomicBool>,
    signal: Arc<AtomicUsize>,
}

impl Interrupts {
    fn install() -> Result<Self, RenderError> {
        let cancel = Arc::new(AtomicBool::new(false));
        let signal = Arc::new(AtomicUsize::new(0));
        let failed = |e: std::io::Error| {
            setting("render", format!("cannot install the signal handlers: {e}"))
        };
        let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM]).map_err(failed)?;
        let (first, which) = (Arc::clone(&cancel), Arc::clone(&signal));
        // One thread takes the signals one at a time, so two that arrive together (say, both
        // pending while the process was stopped) are still a first and a second. Handlers
        // running on two threads at once could both see the flag unset.
        std::thread::Builder::new()
            .name("signals".into())
            .spawn(move || {
                for sig in signals.forever() {
                    if first.load(Ordering::SeqCst) {
                        std::process::exit(EXIT_SECOND_SIGNAL);
                    }
                    // The signal first, then the flag: whoever sees the flag sees the signal.
                    which.store(sig as usize, Ordering::SeqCst);
                    first.store(true, Ordering::SeqCst);
                }
            })
            .map_err(failed)?;
        Ok(Self { cancel, signal })
    }

    /// The signal that interrupted the render, if one did.
    fn received(&self) -> Option<i32> {
        if !self.cancel.load(Ordering::SeqCst) {
            return None;
        }
        match self.signal.load(Ordering::SeqCst) {
            0 => Some(SIGINT),
            s => Some(s as i32),
        }
    }
}

fn run_render(args: RenderArgs) -> Result<ExitCode, RenderError> {
    let started = Instant::now();
    let scene_path = args.scene_path.as_path();
    let slice = match &args.slice {
        Some(text) => Some(Slice::parse(
            text,
            SliceBy::parse(&args.slice_by).unwrap_or(SliceBy::Passes),
        )?),
        None => None,
    };
    if slice.is_some() && args.output.is_none() {
        return Err(setting(
            "--slice",
            "needs -o PART, the partial file to write",
        ));
    }
    let output = args
        .output
        .unwrap_or_else(|| scene_path.with_extension("exr"));
    if slice.is_none() {
        OutputFormat::from_path(&output)?;
    }
    folder_exists("-o", &output)?;
    let mut threads = args.threads;
    if threads == Some(0) {
        return Err(setting("--threads", "must be >= 1, got 0"));
    }
    // More workers than a few per core only cost time to start (10000 took 20 s for a 1-spp
    // render); the image is the same for any count, so cap and say so.
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if let Some(n) = threads.filter(|&n| n > MAX_THREADS_PER_CORE * cores) {
        let cap = MAX_THREADS_PER_CORE * cores;
        eprintln!("note: --threads {n} capped at {cap} ({MAX_THREADS_PER_CORE} per core)");
        threads = Some(cap);
    }
    // The scene's BVH build runs its large subtrees on rayon's global pool: give it the
    // render's thread count (the pool is made once; a second call changes nothing).
    if let Some(n) = threads {
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global();
    }
    if !(args.checkpoint_every.is_finite() && args.checkpoint_every >= 0.0) {
        return Err(setting(
            "--checkpoint-every",
            format!(
                "must be a number of seconds >= 0, got {}",
                args.checkpoint_every
            ),
        ));
    }
    if let Some(path) = &args.checkpoint {
        folder_exists("--checkpoint", path)?;
    }

    let (mut description, imported) = load_scene(scene_path)?;
    if let Some(spp) = args.spp {
        if spp == 0 {
            return Err(setting("--spp", "must be >= 1, got 0"));
        }
        description.sampler.spp = spp;
    }
    if let Some(seed) = args.seed {
        description.sampler.seed = seed;
    }
    if let Some(name) = args.integrator {
        description.integrator.kind = IntegratorKind::parse(&name).ok_or_else(|| {
            setting("--integrator", format!("unknown integrator `{name}`, expected path, depth, distance, position, normal or albedo"))
        })?;
    }
    if let Some(r) = args.resolution {
        description.film.resolution = parse_resolution(&r)?;
    }
    for note in &description.ignored {
        eprintln!("note: {note}");
    }
    if let Some(slice) = slice {
        let refused = if args.checkpoint.is_some() {
            Some("--checkpoint")
        } else if args.resume.is_some() {
            Some("--resume")
        } else if args.cube_map {
            Some("--cube-map")
        } else {
            None
        };
        if let Some(name) = refused {
            return Err(setting(
                name,
                "cannot be combined with --slice (a slice is re-rendered whole if it fails)",
            ));
        }
        if description.camera.stereo.is_some() {
            return Err(setting(
                "--slice",
                "a stereo camera renders two views; slice a single view",
            ));
        }
        return render_slice(scene_path, description, slice, &output, threads, started);
    }
    if let Some(views) = plan_views(&description, args.cube_map, &output) {
        if args.checkpoint.is_some() || args.resume.is_some() {
            return Err(setting(
                if args.checkpoint.is_some() {
                    "--checkpoint"
                } else {
                    "--resume"
                },
                "checkpoints hold one image; a cube map or a stereo pair renders several",
            ));
        }
        return render_views(views, &output, threads, imported.as_ref());
    }
    // The checkpoint's fingerprint: the scene file's bytes and the settings after overrides.
    let fingerprint = if args.checkpoint.is_some() || args.resume.is_some() {
        scene_fingerprint(&scene_source(scene_path)?, &description)
    } else {
        0
    };
    let scene = RenderScene::build(description).map_err(|e| locate(imported.as_ref(), e))?;
    report_skipped(&scene);
    let spp = scene.sampler.samples_per_pixel();

    let resume = match &args.resume {
        Some(path) => {
            let checkpoint = Checkpoint::load(path)?;
            checkpoint.check_matches(fingerprint, spp, scene.pixel_bounds, path)?;
            Some((checkpoint.film, checkpoint.passes_done))
        }
        None => None,
    };
    let first_pass = resume.as_ref().map_or(0, |r| r.1);

    let interrupts = Interrupts::install()?;
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
    // Checkpoints from the pass callback, when the interval has elapsed. A failed save warns
    // and the render goes on: losing the checkpoint is better than losing the render.
    let interval = Duration::from_secs_f64(args.checkpoint_every);
    let last_save = Mutex::new(Instant::now());
    let save = |passes_done: u32, film: &Film| {
        let Some(path) = &args.checkpoint else {
            return;
        };
        let checkpoint = Checkpoint {
            fingerprint,
            samples_per_pixel: spp,
            passes_done,
            film: film.clone(),
        };
        if let Err(e) = checkpoint.save(path) {
            let message = format!("warning: {e}");
            match &bar {
                Some(bar) => bar.println(message),
                None => eprintln!("{message}"),
            }
        }
    };
    let on_pass = |passes_done: u32, _spp: u32, film: &Film| {
        if args.checkpoint.is_none() || passes_done >= spp {
            return;
        }
        let mut last = last_save.lock().unwrap_or_else(|e| e.into_inner());
        if last.elapsed() >= interval {
            save(passes_done, film);
            *last = Instant::now();
        }
    };
    let outcome = render(
        &scene,
        RenderOptions {
            threads,
            cancel: Some(&interrupts.cancel),
            on_pass: Some(&on_pass),
            on_tile: Some(&on_tile),
            resume,
            ..Default::default()
        },
    )
    .map_err(|e| setting("--threads", format!("cannot start the worker threads: {e}")))?;
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let complete = outcome.is_complete(&scene);
    // The final or interrupted state, before the image: a second signal from here on loses
    // at most the image, never the samples.
    save(outcome.passes_done, &outcome.film);

    if !complete {
        let signal = interrupts.received().unwrap_or(SIGINT);
        let status = 128 + signal as u8;
        if outcome.passes_done == 0 {
            eprintln!(
                "interrupted before the first pass finished: wrote nothing ({} left as it was)",
                output.display()
            );
            return Ok(ExitCode::from(status));
        }
        let partial_path = partial_image_path(&output);
        write_image(
            &partial_path,
            &outcome.film.resolve(),
            &ImageInfo {
                partial: true,
                samples_per_pixel: outcome.passes_done,
            },
        )?;
        let kept = if partial_path == output {
            String::new()
        } else {
            format!(", beside the older {}, left as it was", output.display())
        };
        eprintln!(
            "interrupted: wrote partial image {}{kept} ({} of {spp} samples per pixel){}",
            partial_path.display(),
            outcome.passes_done,
            args.checkpoint
                .as_ref()
                .map(|c| format!("; resume with --resume {}", c.display()))
                .unwrap_or_default()
        );
        return Ok(ExitCode::from(status));
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
        "rendered {} -> {}: {w}x{h}, {spp} spp{}, {} integrator, {:.2} M samples in {:.3} s ({:.2} M camera rays/s, {threads_used} threads)",
        scene_path.display(),
        output.display(),
        if first_pass > 0 {
            format!(" (resumed at {first_pass})")
        } else {
            String::new()
        },
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
    Ok(ExitCode::SUCCESS)
}

/// Where an interrupted render writes its partial image: the output path when nothing is there,
/// else `NAME.partial.EXT` beside it, so that an older image is never replaced by a partial one.
fn partial_image_path(output: &Path) -> PathBuf {
    if std::fs::symlink_metadata(output).is_err() {
        return output.to_path_buf();
    }
    let stem = output.file_stem().unwrap_or_default().to_string_lossy();
    let name = match output.extension() {
        Some(ext) => format!("{stem}.partial.{}", ext.to_string_lossy()),
        None => format!("{stem}.partial"),
    };
    output.with_file_name(name)
}

/// Reads the scene file's bytes, for the fingerprint of checkpoints and partials.
fn scene_source(scene_path: &Path) -> Result<Vec<u8>, RenderError> {
    std::fs::read(scene_path).map_err(|source| RenderError::Io {
        file: scene_path.to_path_buf(),
        action: "cannot read the scene file",
        source,
    })
}

/// Renders one slice of the scene and writes its partial film to `output`, whole or not at
/// all. An interrupt writes nothing. `started`: when the command started, for the set-up time
/// (parse, build) it reports.
fn render_slice(
    scene_path: &Path,
    description: SceneDescription,
    slice: Slice,
    output: &Path,
    threads: Option<usize>,
    started: Instant,
) -> Result<ExitCode, RenderError> {
    let fingerprint = scene_fingerprint(&scene_source(scene_path)?, &description);
    let scene = RenderScene::build(description)?;
    report_skipped(&scene);
    let setup = started.elapsed();
    let spp = scene.sampler.samples_per_pixel();
    let tile_count = obscura_render::tiles(scene.pixel_bounds).len();
    let (passes, tiles, what) = match slice.by {
        SliceBy::Passes => {
            let r = slice.range(u64::from(spp));
            let r = r.start as u32..r.end as u32;
            let what = format!("passes {}..{} of {spp}", r.start, r.end);
            (r, None, what)
        }
        SliceBy::Tiles => {
            let r = slice.range(tile_count as u64);
            let r = r.start as usize..r.end as usize;
            let what = format!("tiles {}..{} of {tile_count}", r.start, r.end);
            (0..spp, Some(r), what)
        }
    };
    let end = passes.end;
    let interrupts = Interrupts::install()?;
    let outcome = render(
        &scene,
        RenderOptions {
            threads,
            cancel: Some(&interrupts.cancel),
            passes: Some(passes),
            tiles,
            ..Default::default()
        },
    )
    .map_err(|e| setting("--threads", format!("cannot start the worker threads: {e}")))?;
    if outcome.passes_done < end {
        let signal = interrupts.received().unwrap_or(SIGINT);
        eprintln!(
            "interrupted: slice {slice} not written ({} left as it was)",
            output.display()
        );
        return Ok(ExitCode::from(128 + signal as u8));
    }
    let d = &scene.description;
    let partial = Partial {
        fingerprint,
        seed: d.sampler.seed,
        samples_per_pixel: spp,
        integrator: scene.integrator(),
        resolution: d.film.resolution,
        slice,
        film: outcome.film,
    };
    let written = Instant::now();
    partial.save(output)?;
    println!(
        "rendered slice {slice} of {} -> {}: {what}, {} integrator, {:.2} M samples; set-up (parse, build) {:.3} s, render {:.3} s, write {:.3} s",
        scene_path.display(),
        output.display(),
        scene.integrator().name(),
        outcome.stats.samples as f64 / 1e6,
        setup.as_secs_f64(),
        outcome.elapsed.as_secs_f64(),
        written.elapsed().as_secs_f64(),
    );
    Ok(ExitCode::SUCCESS)
}

/// `obscura merge`: checks that the parts are one render's slices, each once, and writes the
/// image; or, with --list-missing, prints the slices still to render.
/// An error naming `flag` when the folder `path` would be written into does not exist (checked
/// before any work, so the message names the user's path, not a temporary file beside it).
fn folder_exists(flag: &'static str, path: &Path) -> Result<(), RenderError> {
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if folder.is_dir() {
        Ok(())
    } else {
        Err(setting(
            flag,
            format!(
                "{}: the folder {} does not exist",
                path.display(),
                folder.display()
            ),
        ))
    }
}

fn run_merge(args: MergeArgs) -> Result<ExitCode, RenderError> {
    if args.slices == Some(0) {
        return Err(setting("--slices", "must be >= 1, got 0"));
    }
    if args.list_missing {
        // A part that cannot be read is as good as missing: its slice must be rendered again.
        let readable: Vec<PathBuf> = args
            .parts
            .iter()
            .filter(|p| match Partial::load(p) {
                Ok(_) => true,
                Err(e) => {
                    eprintln!("note: counted as missing: {e}");
                    false
                }
            })
            .cloned()
            .collect();
        if readable.is_empty() && args.slices.is_none() {
            return Err(setting(
                "--list-missing",
                "no readable part says how many slices there are; give --slices N",
            ));
        }
        let set = merge_partials(&readable, args.slices)?;
        let list: Vec<String> = set.missing.iter().map(u32::to_string).collect();
        println!("{}", list.join(","));
        return Ok(ExitCode::SUCCESS);
    }
    let Some(output) = args.output else {
        return Err(setting("-o", "merge needs -o OUT.exr or OUT.png"));
    };
    OutputFormat::from_path(&output)?;
    folder_exists("-o", &output)?;
    if args.parts.is_empty() {
        return Err(setting("merge", "no parts given"));
    }
    let start = Instant::now();
    let set = merge_partials(&args.parts, args.slices)?;
    let Some(merged) = set.merged else {
        return Err(setting("merge", "no parts given"));
    };
    let first = &merged;
    if !set.missing.is_empty() {
        let missing = &set.missing;
        let list: Vec<String> = missing.iter().map(u32::to_string).collect();
        return Err(setting(
            "merge",
            format!(
                "missing {} of {} slices: {} (render them with --slice i/{} --slice-by {}); wrote nothing",
                missing.len(),
                first.slice.count,
                list.join(", "),
                first.slice.count,
                first.slice.by.name()
            ),
        ));
    }
    let read = start.elapsed();
    write_image(
        &output,
        &merged.film.resolve(),
        &ImageInfo {
            partial: false,
            samples_per_pixel: first.samples_per_pixel,
        },
    )?;
    println!(
        "merged {} slices by {} -> {}: {}x{}, {} spp, {} integrator; read and add {:.3} s, write {:.3} s",
        set.present.len(),
        first.slice.by.name(),
        output.display(),
        first.resolution[0],
        first.resolution[1],
        first.samples_per_pixel,
        first.integrator.name(),
        read.as_secs_f64(),
        (start.elapsed() - read).as_secs_f64(),
    );
    Ok(ExitCode::SUCCESS)
}

/// A render of several views of one scene: a cube map's faces or a stereo pair's eyes.
enum Views {
    /// Each view to its own file.
    Files(Vec<(SceneDescription, PathBuf)>),
    /// The two eyes, composed into the one output.
    Pair(Box<[SceneDescription; 2]>, StereoLayout),
}

/// The views `obscura render` makes of a scene: None for the usual single image.
fn plan_views(d: &SceneDescription, cube_map: bool, output: &Path) -> Option<Views> {
    if cube_map {
        const SUFFIXES: [&str; 6] = ["px", "nx", "py", "ny", "pz", "nz"];
        let faces = CubeFace::ALL
            .into_iter()
            .zip(SUFFIXES)
            .map(|(face, suffix)| {
                let mut view = d.clone();
                view.camera.kind = CameraKind::CubeFace;
                view.camera.face = face;
                view.camera.stereo = None;
                (view, suffixed(output, suffix))
            })
            .collect();
        return Some(Views::Files(faces));
    }
    let [left, right] = d.stereo_eyes()?;
    let layout = d.camera.stereo?.layout;
    Some(match layout {
        StereoLayout::Separate => Views::Files(vec![
            (left, suffixed(output, "left")),
            (right, suffixed(output, "right")),
        ]),
        layout => Views::Pair(Box::new([left, right]), layout),
    })
}

/// `dir/name.ext` -> `dir/name-suffix.ext`.
fn suffixed(output: &Path, suffix: &str) -> PathBuf {
    let stem = output
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let ext = output
        .extension()
        .map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
    output.with_file_name(format!("{stem}-{suffix}{ext}"))
}

/// Renders several views one after the other. Each file is written whole when its view is
/// done; an interrupt stops at once and writes nothing more (a pair is written only whole).
fn render_views(
    views: Views,
    output: &Path,
    threads: Option<usize>,
    imported: Option<&Imported>,
) -> Result<ExitCode, RenderError> {
    let interrupts = Interrupts::install()?;
    let shoot = |d: SceneDescription| -> Result<Option<obscura_render::Image>, RenderError> {
        let scene = RenderScene::build(d).map_err(|e| locate(imported, e))?;
        report_skipped(&scene);
        let outcome = render(
            &scene,
            RenderOptions {
                threads,
                cancel: Some(&interrupts.cancel),
                ..Default::default()
            },
        )
        .map_err(|e| setting("--threads", format!("cannot start the worker threads: {e}")))?;
        Ok(outcome.is_complete(&scene).then(|| outcome.film.resolve()))
    };
    let info = |d: &SceneDescription| ImageInfo {
        partial: false,
        samples_per_pixel: d.sampler.spp,
    };
    let interrupted = || {
        let signal = interrupts.received().unwrap_or(SIGINT);
        eprintln!("interrupted: the view in progress was not written");
        Ok(ExitCode::from(128 + signal as u8))
    };
    match views {
        Views::Files(files) => {
            for (d, path) in files {
                let spp = info(&d);
                let Some(image) = shoot(d)? else {
                    return interrupted();
                };
                write_image(&path, &image, &spp)?;
                println!("wrote {}", path.display());
            }
        }
        Views::Pair(eyes, layout) => {
            let [left, right] = *eyes;
            let spp = info(&left);
            let Some(l) = shoot(left)? else {
                return interrupted();
            };
            let Some(r) = shoot(right)? else {
                return interrupted();
            };
            if let Some(image) = compose_stereo(&l, &r, layout) {
                write_image(output, &image, &spp)?;
                println!("wrote {}", output.display());
            }
        }
    }
    Ok(ExitCode::SUCCESS)
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

/// Reads a scene: TOML as it is, a .pbrt or .xml through obscura-import (whose warnings go to
/// stderr); the import is kept to place later errors on its lines.
fn load_scene(path: &Path) -> Result<(SceneDescription, Option<Imported>), RenderError> {
    let (description, imported) = obscura_import::load(path)?;
    for w in imported.iter().flat_map(|i| &i.warnings) {
        eprintln!("warning: {w}");
    }
    Ok((description, imported))
}

/// A renderer error moved onto the imported file's line, for imported scenes.
fn locate(imported: Option<&Imported>, e: RenderError) -> RenderError {
    match imported {
        Some(i) => i.locate(e),
        None => e,
    }
}

fn run_convert(scene_path: &Path, output: Option<PathBuf>) -> Result<(), RenderError> {
    if !obscura_import::is_importable(scene_path) {
        return Err(setting(
            "convert",
            format!(
                "{}: expected a pbrt-v4 (.pbrt) or Mitsuba 3 (.xml) scene",
                scene_path.display()
            ),
        ));
    }
    let output = output.unwrap_or_else(|| scene_path.with_extension("toml"));
    if output.extension().and_then(|e| e.to_str()) != Some("toml") {
        return Err(setting(
            "-o",
            format!("{}: the output must be a .toml file", output.display()),
        ));
    }
    let imported = obscura_import::import(scene_path)?;
    for w in &imported.warnings {
        eprintln!("warning: {w}");
    }
    let description = imported.description()?;
    // Everything the renderer would refuse is refused before anything is written.
    RenderScene::build(description).map_err(|e| imported.locate(e))?;
    let written = imported.write(&output)?;
    println!(
        "converted {} -> {} ({} files)",
        scene_path.display(),
        output.display(),
        written.len()
    );
    Ok(())
}

fn run_check(scene_path: &Path) -> Result<(), RenderError> {
    let (description, imported) = load_scene(scene_path)?;
    for note in &description.ignored {
        eprintln!("note: {note}");
    }
    let scene = RenderScene::build(description).map_err(|e| locate(imported.as_ref(), e))?;
    report_skipped(&scene);
    let d = &scene.description;
    let kind = d.camera.kind.name();
    let lens = if d.camera.lens.radius > 0.0
        && matches!(
            d.camera.kind,
            CameraKind::Perspective | CameraKind::Orthographic
        ) {
        format!(
            " with a thin lens (radius {}, focused at {})",
            d.camera.lens.radius, d.camera.lens.focal_distance
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
