//! `luxon`: the command-line shell over the library.

mod cli;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "luxon",
    version,
    about = "A parallel ray tracer with dynamic plugins"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to its outputs (or to the files given with -o).
    Render {
        scene: PathBuf,
        /// Output file(s); the writer is chosen by extension. Replaces the scene's outputs.
        #[arg(short, long = "output")]
        output: Vec<PathBuf>,
        /// Resolution as WIDTHxHEIGHT.
        #[arg(long, value_parser = parse_res)]
        res: Option<(u32, u32)>,
        /// Samples per pixel.
        #[arg(long)]
        samples: Option<u32>,
        /// Adaptive supersampling: split the pixel cells whose samples differ by more than
        /// THRESHOLD (colour, 0..1), at most DEPTH times (default 3); `off` turns a scene's off.
        #[arg(long, value_name = "THRESHOLD[:DEPTH]", value_parser = parse_adaptive)]
        adaptive: Option<cli::render::AdaptiveArg>,
        /// Render threads per process (default: every CPU; with MPI, the rank's share of them).
        #[arg(long)]
        threads: Option<u32>,
        /// Print rays cast per kind, intersection tests, timings and the work of every rank and
        /// thread.
        #[arg(long)]
        stats: bool,
        /// Neither read nor write the binary geometry cache of an NFF scene.
        #[arg(long, conflicts_with = "cache")]
        no_cache: bool,
        /// Write the geometry cache of an NFF scene whatever its size (by default only scenes
        /// of 100,000 primitives or more get one).
        #[arg(long)]
        cache: bool,
        /// Parallel mode: threads in one process, MPI ranks (one thread each), or both.
        #[arg(long, value_parser = ["threads", "mpi", "hybrid"])]
        parallel: Option<String>,
        /// How pixels are dealt to threads and ranks.
        #[arg(long, value_parser = ["pixel-cyclic", "scanline-cyclic", "block-cyclic", "dynamic"])]
        decomposition: Option<String>,
        /// Edge in pixels of dynamic tiles and block-cyclic blocks.
        #[arg(long = "block-size", alias = "tile-size")]
        block_size: Option<u32>,
        /// Output: written while rendering, after it, or by every MPI rank (8-bit PPM).
        #[arg(long, value_parser = ["async", "sync", "mpi-io"])]
        io: Option<String>,
        #[command(flatten)]
        shading: cli::shading::ShadingArgs,
    },
    /// Render a scene at a range of settings and report time, rays and error against a
    /// reference (Markdown table, CSV, SVG plot, contact sheet and images in DIR).
    ///
    /// Each --vary is a separate curve that changes one parameter from the scene's settings
    /// (several --vary do not make a grid).
    Sweep {
        scene: PathBuf,
        /// PARAMETER=VALUE,VALUE,...: samples=1,4,16,64; max_depth=1,2,4,8;
        /// texture_filter=nearest,bilinear,mip; adaptive=off,0.1,0.05:3 (THRESHOLD[:DEPTH]);
        /// volume_step=... (not supported by this build).
        #[arg(long, required = true)]
        vary: Vec<String>,
        /// Compare with this image (same resolution); default: a reference rendered with many
        /// samples and every varied parameter at its most accurate value.
        #[arg(long)]
        reference: Option<PathBuf>,
        /// Samples per pixel of the rendered reference (default: 4x the most any setting
        /// gives a pixel, 64..=1024).
        #[arg(long = "reference-samples")]
        reference_samples: Option<u32>,
        /// Samples per pixel for every curve but a `samples` one (also adaptive sampling's
        /// base); default: the scene's.
        #[arg(long)]
        samples: Option<u32>,
        /// Renders per setting; the median time is reported.
        #[arg(long, default_value_t = 3)]
        runs: u32,
        /// Resolution as WIDTHxHEIGHT.
        #[arg(long, value_parser = parse_res)]
        res: Option<(u32, u32)>,
        /// Render threads (default: every CPU).
        #[arg(long)]
        threads: Option<u32>,
        /// Directory for the report.
        #[arg(short, long = "output")]
        output: PathBuf,
    },
    /// Validate a scene and print what it contains; renders nothing.
    Check { scene: PathBuf },
    /// List every plugin found: file, kind, names, ABI version, parameters.
    Plugins {
        /// Extra directories or files to search first.
        #[arg(long = "plugin-path")]
        plugin_path: Vec<PathBuf>,
    },
    /// Generate an SPD scene (Eric Haines' Standard Procedural Databases); without a name, list
    /// them.
    Spd {
        /// balls, gears, lattice, mount, rings, teapot, tetra or tree.
        name: Option<String>,
        /// The SPD's size factor (recursion depth or resolution); default: the SPD's default.
        #[arg(short, long)]
        size: Option<u32>,
        /// Output file: .nff, .nff.gz or .ron (`-`: NFF on standard output).
        #[arg(short, long = "output")]
        output: Option<PathBuf>,
    },
}

fn parse_res(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got `{s}`"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("bad width in `{s}`"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("bad height in `{s}`"))?;
    if w == 0 || h == 0 || w > 65536 || h > 65536 || (w as u64 * h as u64) > (1 << 28) {
        return Err(format!(
            "resolution {w}x{h} out of range (1..=65536 each, at most 2^28 pixels)"
        ));
    }
    Ok((w, h))
}

fn parse_adaptive(s: &str) -> Result<cli::render::AdaptiveArg, String> {
    luxon::adaptive::parse(s, 3).map(cli::render::AdaptiveArg)
}

/// glibc raises its mmap threshold to the size of every large block freed, after which the
/// loader's freed buffers stay in the heap for the rest of the run (balls6: 96 MB peak instead
/// of 69 MB). A fixed threshold keeps large blocks mmapped and returned when freed.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn keep_large_blocks_returnable() {
    // SAFETY: mallopt only changes allocator parameters; called before any other thread runs.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 128 * 1024);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn keep_large_blocks_returnable() {}

fn main() -> ExitCode {
    keep_large_blocks_returnable();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render {
            scene,
            output,
            res,
            samples,
            adaptive,
            threads,
            stats,
            no_cache,
            cache,
            parallel,
            decomposition,
            block_size,
            io,
            shading,
        } => cli::render::run(
            &scene,
            &cli::render::Overrides {
                output,
                res,
                samples,
                adaptive,
                threads,
                stats,
                no_cache,
                cache,
                parallel,
                decomposition,
                block_size,
                io,
                shading,
            },
        ),
        Command::Sweep {
            scene,
            vary,
            reference,
            reference_samples,
            samples,
            runs,
            res,
            threads,
            output,
        } => cli::sweep::run(
            &scene,
            &cli::sweep::Args {
                vary,
                reference,
                reference_samples,
                samples,
                runs,
                res,
                threads,
                out: output,
            },
        ),
        Command::Check { scene } => cli::check::run(&scene),
        Command::Plugins { plugin_path } => {
            cli::plugins::run(&plugin_path);
            Ok(())
        }
        Command::Spd { name, size, output } => {
            cli::spd::run(name.as_deref(), size, output.as_deref())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("luxon: error: {e}");
            ExitCode::FAILURE
        }
    }
}
