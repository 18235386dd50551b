//! `sdfc compile`: write a scene as one of the textual targets.

use crate::backend::Backend;
use crate::frontend::{self, DiagnosticFormat};
use clap::ValueEnum;
use sdfc_compiler::{
    dump_ast, dump_ir, lower_within, parse, ptx, rust,
    shader::{self, Lang},
    shadertoy, wgsl, LowerOptions, Lowered, Scene,
};
use std::path::PathBuf;
use std::process::ExitCode;

/// What `sdfc compile` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Emit {
    /// The syntax tree of the entry file.
    Ast,
    /// The checked scene IR.
    Ir,
    /// The distance program (flat scalar SSA).
    Program,
    /// The distance program as a Rust function over glam.
    Rust,
    /// The WGSL renderer kernel, specialised to the scene.
    Wgsl,
    /// The kernel as SPIR-V (binary).
    Spirv,
    /// The kernel as Metal Shading Language.
    Msl,
    /// The kernel as GLSL 4.50.
    Glsl,
    /// The kernel as HLSL.
    Hlsl,
    /// The kernel as PTX for the CUDA driver.
    Ptx,
    /// The kernel's scene uniform `Params` (binding 0) as bytes (binary).
    Params,
    /// The kernel's storage buffer `scene_data` (binding 4) as bytes (binary), for a scene
    /// whose kernel reads one.
    SceneData,
    /// The kernel's entry point, workgroup size and bindings, with the layout of each
    /// binding's type (JSON).
    Layout,
    /// One GLSL ES page with `mainImage` that renders the scene on Shadertoy (camera rays
    /// only; docs/embedding.md).
    Shadertoy,
}

impl Emit {
    /// Whether the target is binary (refused on a terminal).
    fn binary(self) -> bool {
        matches!(self, Emit::Spirv | Emit::Params | Emit::SceneData)
    }
}

/// Which part of the generated code `sdfc compile` writes (docs/embedding.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Part {
    /// The whole renderer kernel (the shading languages and PTX).
    #[default]
    Kernel,
    /// The scene's distance function alone (`--emit wgsl|glsl|hlsl|msl|rust`), with its
    /// material table, for a user's own shader or program.
    Map,
}

/// Arguments of `sdfc compile`.
#[derive(Debug, clap::Args)]
pub struct CompileArgs {
    /// Scene file.
    pub file: PathBuf,
    /// The target to write.
    #[arg(long, value_enum)]
    pub emit: Emit,
    /// Output file (default: standard output; binary SPIR-V is not written to a terminal).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// The part to write: the renderer kernel, or the distance function alone.
    #[arg(long, value_enum, default_value_t)]
    pub part: Part,
    /// The name of the distance function (`--part map`); every name the part declares
    /// starts with it, so two scenes' parts can live in one shader.
    #[arg(long, default_value = wgsl::part::DEFAULT_NAME)]
    pub name: String,
    /// How to print diagnostics.
    #[arg(long, value_enum, default_value_t)]
    pub diagnostics: DiagnosticFormat,
    /// The PTX target architecture (`--emit ptx`): 70 for sm_70, 80, 90, ...
    #[arg(long, default_value_t = 70, value_parser = clap::value_parser!(u32).range(50..=120))]
    pub sm: u32,
    /// Optimisation level of the distance program: 0 lowers the scene literally, 1 runs every
    /// pass (folding, sharing, dead code, scene simplification, bounding-volume culling).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u8).range(0..=1))]
    pub opt: u8,
    /// Override a render setting before compiling, as for `sdfc render` (the kernel is
    /// specialised to the method, relaxation and `max_depth`). May be repeated.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// The kernel of a marched scene (`--part kernel`): its distance program written as code,
    /// or interpreted from `scene_data` (then `--emit scene-data` writes the program's words),
    /// or auto as `sdfc render` chooses. [default: specialised]
    #[arg(long, value_enum)]
    pub kernel: Option<crate::backend::Kernel>,
    #[command(flatten)]
    pub limits: super::LimitArgs,
}

/// Compiles and writes the requested target.
pub fn run(args: CompileArgs) -> ExitCode {
    let limits = args.limits.limits();
    let mut loaded = match frontend::load_with(&args.file, &limits) {
        Ok(l) => l,
        Err(msg) => {
            eprintln!("error: {msg}");
            return ExitCode::from(2);
        }
    };
    if let Some(msg) = part_refused(&args) {
        eprintln!("error: {msg}");
        return ExitCode::from(2);
    }
    frontend::print_diagnostics_on_stderr(&loaded.diagnostics, &loaded.sources, args.diagnostics);
    if args.emit.binary() && args.output.is_none() && {
        use std::io::IsTerminal;
        std::io::stdout().is_terminal()
    } {
        let what = if args.emit == Emit::Spirv {
            "SPIR-V"
        } else {
            "this target"
        };
        eprintln!(
            "error: {what} is binary and standard output is a terminal; write it to a file with `-o FILE` (or redirect it)"
        );
        return ExitCode::from(2);
    }
    let text = match args.emit {
        Emit::Ast => {
            // The AST is shown even for a file with errors in later stages, but not with
            // syntax errors (the tree would be partial).
            let entry = sdfc_compiler::FileId(0);
            let (ast, diags) = parse(entry, loaded.sources.text(entry));
            if sdfc_compiler::diagnostics::has_errors(&diags) {
                return ExitCode::from(1);
            }
            dump_ast(&ast)
        }
        other => {
            let Some(mut scene) = loaded.scene.take() else {
                return ExitCode::from(1);
            };
            let overrides = crate::job::Overrides {
                set: args.set.clone(),
                ..Default::default()
            };
            let job = crate::job::Job::new(Backend::Auto, overrides, limits.clone());
            if let Err(e) = job.settings(&mut scene) {
                return e.exit();
            }
            let scene = &scene;
            if other == Emit::Ir {
                return write_output(args.output.as_deref(), &dump_ir(scene));
            }
            let options = LowerOptions::level(args.opt);
            let lowered = match lower_within(scene, &options, &limits) {
                Ok(lowered) => lowered,
                Err(d) => {
                    frontend::print_diagnostics_on_stderr(&[d], &loaded.sources, args.diagnostics);
                    return ExitCode::from(1);
                }
            };
            // `--set method=trace` on a scene that cannot be traced: refused as a setting.
            if let Err(msg) = crate::backend::method_allowed(scene, &lowered.traceable) {
                eprintln!("error: {msg}");
                return ExitCode::from(2);
            }
            // The Shadertoy page renders camera rays only: say what of this scene it leaves out.
            let missing = shadertoy::left_out(scene);
            if other == Emit::Shadertoy && !missing.is_empty() {
                eprintln!(
                    "warning: the Shadertoy page renders camera rays with Phong shading only; it leaves out this scene's {} (docs/embedding.md)",
                    missing.join(", ")
                );
            }
            let result = match args.part {
                Part::Kernel => emit(scene, &lowered, other, args.sm, args.kernel),
                Part::Map => emit_map(scene, &lowered, other, &args.name),
            };
            match result {
                Ok(bytes) => return write_bytes(args.output.as_deref(), &bytes),
                Err(msg) => {
                    eprintln!("{msg}");
                    return ExitCode::from(1);
                }
            }
        }
    };
    write_output(args.output.as_deref(), &text)
}

/// Why `--part`/`--name` do not fit the other arguments, if they do not.
fn part_refused(args: &CompileArgs) -> Option<String> {
    let kernel_target = !matches!(
        args.emit,
        Emit::Ast | Emit::Ir | Emit::Program | Emit::Rust | Emit::Shadertoy
    );
    if args.kernel.is_some() && (args.part == Part::Map || !kernel_target) {
        return Some(
            "`--kernel` chooses the renderer kernel: it goes with `--part kernel` and --emit \
             wgsl, spirv, msl, glsl, hlsl, ptx, params, scene-data or layout"
                .into(),
        );
    }
    match args.part {
        Part::Kernel if args.name != wgsl::part::DEFAULT_NAME => {
            Some("`--name` names the distance function of `--part map`".into())
        }
        Part::Map
            if !matches!(
                args.emit,
                Emit::Wgsl | Emit::Glsl | Emit::Hlsl | Emit::Msl | Emit::Rust
            ) =>
        {
            Some(format!(
                "`--part map` is written as wgsl, glsl, hlsl, msl or rust, not `{}`",
                args.emit
                    .to_possible_value()
                    .map_or(String::new(), |v| v.get_name().to_string())
            ))
        }
        Part::Map if !wgsl::part::valid_name(&args.name) => Some(format!(
            "`--name {}` is not a name for a function: use ASCII letters, digits and `_`, not starting with a digit or `__`, at most 64 characters, and not a word WGSL or Rust reserves",
            args.name
        )),
        _ => None,
    }
}

/// Why a scene with a `mesh` has no form in a target without a GPU buffer.
const MESH_DATA: &str = "error: {} has no form for a scene with a `mesh`: its triangles and \
     their hierarchy are data the renderer kernels read from `scene_data`, not code";

/// The bytes of the distance function alone, named `name`, in `target`.
pub fn emit_map(
    scene: &Scene,
    lowered: &Lowered,
    target: Emit,
    name: &str,
) -> Result<Vec<u8>, String> {
    if lowered.program.meshes().next().is_some() {
        return Err(MESH_DATA.replace("{}", "`--part map`"));
    }
    let lang = match target {
        Emit::Rust => {
            let mut text = rust::write_named(&lowered.program, name);
            if let Some(glow) = wgsl::part::Glow::of(scene, lowered) {
                text.push_str(&rust::write_glow(&glow, name));
            }
            return Ok(text.into_bytes());
        }
        Emit::Wgsl => None,
        Emit::Glsl => Some(Lang::Glsl),
        Emit::Hlsl => Some(Lang::Hlsl),
        Emit::Msl => Some(Lang::Msl),
        other => {
            let v = other.to_possible_value();
            return Err(format!(
                "error: `--part map` has no `{}` form",
                v.map_or(String::new(), |v| v.get_name().to_string())
            ));
        }
    };
    let part = wgsl::part::write(scene, lowered, name).map_err(|e| e.to_string())?;
    match lang {
        None => Ok(part.source.into_bytes()),
        Some(lang) => shader::write_part(&part, lang).map_err(|e| e.to_string()),
    }
}

/// The bytes of a target that needs the distance program (`sdfc compile --part kernel`,
/// and the Python package's `Scene.compile`).
pub fn emit(
    scene: &Scene,
    lowered: &Lowered,
    target: Emit,
    sm: u32,
    kernel: Option<crate::backend::Kernel>,
) -> Result<Vec<u8>, String> {
    let program = &lowered.program;
    let meshes = program.meshes().next().is_some();
    if meshes && matches!(target, Emit::Rust | Emit::Shadertoy) {
        return Err(MESH_DATA.replace("{}", "this target"));
    }
    let lang = match target {
        Emit::Program => return Ok(program.dump().into_bytes()),
        Emit::Rust => return Ok(rust::write(program).into_bytes()),
        Emit::Shadertoy => {
            return shadertoy::write(scene, lowered)
                .map(String::into_bytes)
                .map_err(|e| e.to_string())
        }
        Emit::Ast | Emit::Ir => {
            return Err("internal error: the AST and IR are not emitted from a program".into())
        }
        Emit::Spirv => Some(Lang::SpirV),
        Emit::Msl => Some(Lang::Msl),
        Emit::Glsl => Some(Lang::Glsl),
        Emit::Hlsl => Some(Lang::Hlsl),
        Emit::Wgsl | Emit::Ptx | Emit::Params | Emit::SceneData | Emit::Layout => None,
    };
    let options = wgsl::Options {
        kernel: kernel.map_or(wgsl::KernelChoice::Specialised, |k| k.choice()),
        ..wgsl::Options::default()
    };
    wgsl::choose(scene, lowered, &options).map_err(|e| format!("error: {e}"))?;
    let kernel = wgsl::write_with(scene, lowered, &options).map_err(|e| e.to_string())?;
    match target {
        Emit::Params => {
            return wgsl::uniforms(&kernel.contract.uniform, scene, program.lipschitz())
                .map_err(|e| format!("internal compiler error: {e}"))
        }
        Emit::SceneData => {
            return kernel.data.ok_or_else(|| {
                "error: this scene's kernel reads no `scene_data` (only one of more than 256 traced primitives or 256 marched instances, or an interpreted one, does)".into()
            })
        }
        Emit::Layout => {
            let value = wgsl::layout::interface(&kernel).map_err(|e| e.to_string())?;
            let mut text = serde_json::to_string_pretty(&value).map_err(|e| e.to_string())?;
            text.push('\n');
            return Ok(text.into_bytes());
        }
        _ => {}
    }
    if target == Emit::Ptx {
        let options = ptx::Options {
            sm,
            entry_point: wgsl::ENTRY_POINT.to_string(),
        };
        return ptx::write(&kernel.module, &kernel.info, &options)
            .map(|ptx| ptx.text.into_bytes())
            .map_err(|e| e.to_string());
    }
    match lang {
        None => Ok(kernel.source.into_bytes()),
        Some(lang) => shader::write(&kernel, lang).map_err(|e| e.to_string()),
    }
}

/// Writes `text` to a file (atomically) or to standard output.
pub fn write_output(path: Option<&std::path::Path>, text: &str) -> ExitCode {
    write_bytes(path, text.as_bytes())
}

/// Writes bytes to a file (atomically) or to standard output.
pub fn write_bytes(path: Option<&std::path::Path>, bytes: &[u8]) -> ExitCode {
    match path {
        None => match super::write_stdout(bytes) {
            Ok(()) => ExitCode::SUCCESS,
            Err(code) => code,
        },
        Some(p) => match crate::image::write_atomic(p, bytes) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: cannot write `{}`: {e}", p.display());
                ExitCode::from(2)
            }
        },
    }
}
