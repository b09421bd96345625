//! `luxon`: the command-line shell over the library.

// Unsafe code only where allowed by name (the allocator setting).
#![deny(unsafe_code)]

mod cli;

use clap::error::ErrorKind;
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
        // Boxed: the render options are most of the command's size.
        #[command(flatten)]
        overrides: Box<cli::render::Overrides>,
    },
    /// Render a scene at a range of settings and report time, rays and error against a
    /// reference (Markdown table, CSV, SVG plot, contact sheet and images in DIR).
    ///
    /// Each --vary is a separate curve that changes one parameter from the scene's settings
    /// (several --vary do not make a grid).
    Sweep {
        scene: PathBuf,
        #[command(flatten)]
        args: cli::sweep::Args,
    },
    /// Validate a scene and print what it contains; renders nothing.
    Check {
        scene: PathBuf,
        /// Memory budget to build the scene within (as for `render`); `check` prints it and
        /// what the scene holds of it.
        #[arg(long, value_name = "SIZE", value_parser = cli::parse_memory)]
        memory: Option<luxon_formats::MemorySize>,
        /// How instances are realised (as for `render`); `check` prints each prototype's way.
        #[arg(long, value_parser = ["auto", "bake", "share"])]
        instancing: Option<String>,
        /// An animated scene's shutter (as for `render`): LENGTH[:start|centre|end] or off.
        #[arg(long, value_name = "LENGTH[:start|centre|end]|off")]
        shutter: Option<String>,
    },
    /// List every plugin found: file, kind, names, ABI version, parameters.
    Plugins {
        /// Extra directories or files to search first.
        #[arg(long = "plugin-path")]
        plugin_path: Vec<PathBuf>,
    },
    /// Write any scene Luxon reads (RON, NFF, OBJ, Tachyon `.dat`) as an equivalent Luxon RON
    /// scene, to edit and render from then on.
    ///
    /// `luxon convert scene.dat scene.ron` (or `-o scene.ron`). What the source says that the
    /// RON scene cannot hold is printed as warnings and listed at the top of the file.
    Convert {
        scene: PathBuf,
        /// The RON file to write.
        #[arg(value_name = "OUT.ron")]
        out: Option<PathBuf>,
        /// The RON file to write (the same as OUT.ron).
        #[arg(short, long = "output", value_name = "OUT.ron", conflicts_with = "out")]
        output: Option<PathBuf>,
    },
    /// Start a plugin: write a crate with a minimal plugin of the kind, its parameter table,
    /// a scene that uses it and a README with the commands to build it and render.
    #[command(after_long_help = cli::usage::NEW_PLUGIN)]
    NewPlugin {
        /// The plugin's name, as scenes write it: `plugin: "NAME"` (lowercase letters, digits,
        /// `_` and `-`, starting with a letter).
        name: String,
        /// What the plugin provides.
        #[arg(long, value_enum)]
        kind: cli::new_plugin::Kind,
        /// The directory to create (default: ./NAME); an existing one must be empty.
        #[arg(long, value_name = "DIR")]
        dir: Option<PathBuf>,
        /// The SDK to build against: the directory of `luxon-plugin` (`plugins/sdk` of a
        /// checkout) or a version of it. Default: this checkout's `plugins/sdk` when the
        /// executable lies inside one, else the version this luxon speaks.
        #[arg(long, value_name = "DIR|VERSION")]
        sdk: Option<String>,
    },
    /// Render Tachyon scene files (`.dat`) with Tachyon's own command line, for drop-in use by
    /// VMD: `luxon tachyon [Tachyon's options] scene.dat` (see `luxon tachyon -help`).
    #[command(disable_help_flag = true)]
    Tachyon {
        /// Tachyon's options and scene files, in any order.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true, num_args = 0..)]
        args: Vec<std::ffi::OsString>,
    },
    /// Generate an SPD scene (Eric Haines' Standard Procedural Databases); without a name, list
    /// them.
    Spd {
        /// balls, gears, jacks, lattice, mount, rings, shells, sombrero, teapot, tetra or tree.
        name: Option<String>,
        /// The SPD's size factor (recursion depth or resolution); default: the SPD's default.
        #[arg(short, long)]
        size: Option<u32>,
        /// Output file: .nff, .nff.gz or .ron (`-`: NFF on standard output).
        #[arg(short, long = "output")]
        output: Option<PathBuf>,
    },
}

/// glibc raises its mmap threshold to the size of every large block freed, after which the
/// loader's freed buffers stay in the heap for the rest of the run (balls6: 96 MB peak instead
/// of 69 MB). A fixed threshold keeps large blocks mmapped and returned when freed.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[allow(unsafe_code)]
fn keep_large_blocks_returnable() {
    // SAFETY: mallopt takes two integers and only changes a parameter of glibc's allocator
    // (under the allocator's own lock); the threshold is within its valid range. It runs first in
    // `main`, before any other thread exists.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 128 * 1024);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn keep_large_blocks_returnable() {}

/// This build uses x86-64-v3 instructions (`.cargo/config.toml`): on an older CPU, say so and
/// how to rebuild rather than die on an illegal instruction. Out of line and first in `main`, so
/// nothing built for v3 runs before it (the detection itself is in the standard library).
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
#[inline(never)]
fn check_cpu() {
    let v3 = std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
        && std::arch::is_x86_feature_detected!("bmi2");
    if !v3 {
        eprintln!(
            "luxon: error: this build needs an x86-64-v3 CPU (AVX2, FMA, BMI2), which this one is \
             not; rebuild for any x86-64 with RUSTFLAGS=\"-C target-cpu=x86-64\" cargo build --release"
        );
        std::process::exit(1);
    }
}

/// Exit statuses: 0 success (and `--help`, `--version`), 1 any error (command line included),
/// 128 + n killed by signal n (see `cli::signals`).
fn main() -> ExitCode {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    check_cpu();
    // Before anything can log: plugin messages reach stderr only through this sink.
    cli::log_to_stderr();
    keep_large_blocks_returnable();
    cli::signals::install();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(e),
    };
    let result = match cli.command {
        Command::Render { scene, overrides } => cli::render::run(&scene, &overrides),
        Command::Sweep { scene, args } => cli::sweep::run(&scene, &args),
        Command::Check {
            scene,
            memory,
            instancing,
            shutter,
        } => cli::check::run(&scene, memory, instancing, shutter),
        Command::Plugins { plugin_path } => {
            cli::plugins::run(&plugin_path);
            Ok(())
        }
        Command::Convert { scene, out, output } => match out.or(output) {
            Some(output) => cli::convert::run(&scene, &output),
            None => Err(luxon::Error::Usage(
                "luxon convert: name the RON file to write: luxon convert SCENE OUT.ron".into(),
            )),
        },
        Command::NewPlugin {
            name,
            kind,
            dir,
            sdk,
        } => cli::new_plugin::run(&name, kind, dir.as_deref(), sdk.as_deref()),
        Command::Tachyon { args } => cli::tachyon::run(&args),
        Command::Spd { name, size, output } => {
            cli::spd::run(name.as_deref(), size, output.as_deref())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            luxon::error::print_error(&e.to_string());
            ExitCode::FAILURE
        }
    }
}

/// A command-line error as one `luxon: error:` line and status 1, like every other error;
/// `--help` and `--version` print as usual with status 0, and `luxon` alone prints the help to
/// stderr with status 1.
fn usage_error(e: clap::Error) -> ExitCode {
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            let _ = e.print();
            ExitCode::SUCCESS
        }
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            eprint!("{}", e.render());
            ExitCode::FAILURE
        }
        _ => {
            let sub = std::env::args().skip(1).find(|a| !a.starts_with('-'));
            let sub = sub.filter(|a| Cli::command_names().any(|n| n == *a));
            luxon::error::print_error(&cli::usage::one_line(&e.to_string(), sub.as_deref()));
            ExitCode::FAILURE
        }
    }
}

impl Cli {
    fn command_names() -> impl Iterator<Item = String> {
        use clap::CommandFactory;
        Cli::command()
            .get_subcommands()
            .map(|c| c.get_name().to_string())
            .collect::<Vec<_>>()
            .into_iter()
    }
}
