//! The `sdfc` command-line tool: check, compile, render, benchmark and compare `.sdf` scenes,
//! chart their speed against accuracy, view them live, and mesh them.

use clap::{CommandFactory, Parser, Subcommand};
use std::process::ExitCode;

use sdfc_runtime::commands;

/// sdfc compiles scenes of signed distance fields to images, shaders and programs.
#[derive(Debug, Parser)]
#[command(
    name = "sdfc",
    version,
    about,
    long_about = None,
    after_long_help = commands::limits_help()
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Check scenes for errors; exit 0 when clean, 1 on errors, 2 on usage or IO problems.
    Check(commands::check::CheckArgs),
    /// Compile a scene to one of the textual targets.
    Compile(commands::compile::CompileArgs),
    /// Render a scene to an image (PNG, JPEG or OpenEXR, by the output's extension) or an
    /// animation to numbered images, an animated PNG or a video.
    Render(commands::render::RenderArgs),
    /// Time the rendering of scenes.
    Bench(commands::bench::BenchArgs),
    /// Compare two rendered images (RMSE, PSNR, differing pixels, and first hits when both
    /// have a depth sidecar).
    Compare(commands::compare::CompareArgs),
    /// Chart speed against accuracy over swept render settings, with the Pareto front.
    Pareto(commands::pareto::ParetoArgs),
    /// Mesh a scene's surface (STL, OBJ, PLY, glTF or 3MF), watertight and with sharp edges kept.
    Mesh(commands::mesh::MeshArgs),
    /// List the devices `--devices` can name: CUDA devices and wgpu adapters by index, and
    /// the CPU.
    Devices(commands::devices::DevicesArgs),
    /// Show a scene in a window that reloads it whenever it (or a file it imports) is saved.
    #[command(after_help = VIEW_KEYS)]
    View(commands::view::ViewArgs),
    /// Format scene files in one layout, comments kept (`--check`: name those that would
    /// change, exit 1 if any would).
    Fmt(commands::fmt::FmtArgs),
    /// Serve the Language Server Protocol on standard input and output, for editors
    /// (docs/editors.md).
    Lsp(LspArgs),
    /// Print a completion script for bash, zsh or fish on standard output.
    ///
    /// Install it where the shell looks: bash `sdfc completions bash >
    /// ~/.local/share/bash-completion/completions/sdfc`, zsh a file `_sdfc` in a directory of
    /// `$fpath`, fish `~/.config/fish/completions/sdfc.fish`.
    Completions(CompletionsArgs),
}

/// `sdfc completions`' arguments.
#[derive(Debug, clap::Args)]
struct CompletionsArgs {
    /// The shell to complete in.
    #[arg(value_enum)]
    shell: Shell,
}

/// The shells `sdfc completions` writes for.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum Shell {
    Bash,
    Zsh,
    Fish,
}

/// The keys and mouse of `sdfc view`'s window (docs/viewer.md), listed by its `--help`.
const VIEW_KEYS: &str = "In the window:
  left drag                  orbit the camera around its target
  shift-drag, middle drag    pan
  wheel                      zoom
  R                          the file's camera again
  S, Tab                     statistics in the title (on or off)
  Space                      pause or play an animated scene
  P                          hide or show the parameter panel (a scene with parameters)
  Esc, Q                     quit";

/// `sdfc lsp`'s arguments.
#[derive(Debug, clap::Args)]
struct LspArgs {
    /// Talk over standard input and output (the only transport; accepted because clients
    /// pass it).
    #[arg(long)]
    stdio: bool,
    /// The limits of checking each document, and `file_size`: of each file read, and of a
    /// message (twice it, for a document and its JSON escapes).
    #[command(flatten)]
    limits: commands::LimitArgs,
}

fn main() -> ExitCode {
    commands::main_started();
    report_unwritable_stdout();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            if let Err(why) = e.print() {
                eprintln!("error: cannot write to standard output: {why}");
                return ExitCode::from(2);
            }
            // clap reports --help and --version as "errors" with exit code 0.
            return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
        }
    };
    if matches!(
        cli.command,
        Command::Check(_)
            | Command::Compile(_)
            | Command::Compare(_)
            | Command::Fmt(_)
            | Command::Completions(_)
    ) {
        end_quietly_on_a_closed_stdout();
    }
    match cli.command {
        Command::Check(args) => commands::check::run(args),
        Command::Devices(args) => commands::devices::run(args),
        Command::Compile(args) => commands::compile::run(args),
        Command::Render(args) => commands::render::run(args),
        Command::Bench(args) => commands::bench::run(args),
        Command::Compare(args) => commands::compare::run(args),
        Command::Pareto(args) => commands::pareto::run(args),
        Command::Mesh(args) => commands::mesh::run(args),
        Command::View(args) => commands::view::run(args),
        Command::Fmt(args) => commands::fmt::run(args),
        Command::Lsp(args) => sdfc_runtime::lsp::run(args.limits.limits()),
        Command::Completions(args) => completions(args.shell),
    }
}

/// Restores the default action of SIGPIPE, which Rust's runtime sets to be ignored: a
/// command whose standard output is closed before it is done (`sdfc completions bash | head
/// -1`) then ends at its next write, quietly, as `cat` and `grep` do, instead of failing on the
/// write with an error message (or a panic, in `println!`). Only for the commands that open no
/// device and no window, whose only pipe is standard output: a GPU driver or a window system
/// may write to pipes and sockets of its own, whose closing must not end the process.
/// `println!` panics when standard output cannot be written (a full disk: `> /dev/full`);
/// that panic is reported as the write error it is, `error: cannot write to standard output:
/// …`, exit 2, not as a crash (exit 101). Every other panic goes to the default hook.
fn report_unwritable_stdout() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if let Some(why) = message.strip_prefix("failed printing to stdout: ") {
            sdfc_runtime::frontend::unwritable_stdout(&why);
        }
        default(info)
    }));
}

fn end_quietly_on_a_closed_stdout() {
    #[cfg(unix)]
    // SAFETY: `signal` only sets the disposition of SIGPIPE; it is called before any thread
    // of this process starts.
    #[allow(unsafe_code)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Writes the completion script of `shell` on standard output.
fn completions(shell: Shell) -> ExitCode {
    use clap_complete::Shell as S;
    let shell = match shell {
        Shell::Bash => S::Bash,
        Shell::Zsh => S::Zsh,
        Shell::Fish => S::Fish,
    };
    let mut out = Vec::new();
    clap_complete::generate(shell, &mut Cli::command(), "sdfc", &mut out);
    use std::io::Write;
    match std::io::stdout().write_all(&out) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: cannot write the completion script: {e}");
            ExitCode::from(2)
        }
    }
}
