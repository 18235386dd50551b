//! Other shading languages, written by naga from the validated WGSL kernel: SPIR-V, MSL,
//! GLSL and HLSL (`sdfc compile --emit spirv|msl|glsl|hlsl`); and the scene's distance
//! function alone ([`super::wgsl::part`], `--part map`) in MSL, GLSL and HLSL.

use super::wgsl::{part::Part, Kernel};
use std::fmt;

/// A shading language naga can write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lang {
    /// SPIR-V 1.x binary.
    SpirV,
    /// Metal Shading Language.
    Msl,
    /// GLSL 4.50 (compute).
    Glsl,
    /// HLSL shader model 5.1.
    Hlsl,
}

/// A naga back end refused the module (a compiler bug: the module was validated).
#[derive(Debug, Clone, PartialEq)]
pub struct Error(pub String);

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(
            f,
            "internal compiler error while writing the shader: {}",
            self.0
        )
    }
}

impl std::error::Error for Error {}

/// The kernel in `lang`: text for the text languages, little-endian words for SPIR-V.
pub fn write(kernel: &Kernel, lang: Lang) -> Result<Vec<u8>, Error> {
    write_module(&kernel.module, &kernel.info, lang)
}

/// The functions of a distance function's part (no entry point) in `lang`, a text language.
/// GLSL writes one entry point: the part is written with an empty one, which is then cut
/// off with its workgroup line and compute extension, leaving `#version` and the functions.
pub fn write_part(part: &Part, lang: Lang) -> Result<Vec<u8>, Error> {
    match lang {
        Lang::SpirV => Err(Error(
            "SPIR-V holds entry points, and the distance function alone has none".into(),
        )),
        Lang::Msl | Lang::Hlsl => write_module(&part.module, &part.info, lang),
        Lang::Glsl => library_glsl(part, naga::back::glsl::Version::Desktop(450)),
    }
}

/// The part as GLSL ES 3.00 functions, for a WebGL fragment shader (the Shadertoy page):
/// no `#version`, `precision` or entry point, which the page that includes it provides.
pub(crate) fn write_part_es(part: &Part) -> Result<String, Error> {
    let text = String::from_utf8(library_glsl(
        part,
        naga::back::glsl::Version::new_gles(300),
    )?)
    .map_err(|e| Error(e.to_string()))?;
    let kept: Vec<&str> = text
        .lines()
        .filter(|l| !l.starts_with("#version") && !l.starts_with("precision "))
        .collect();
    Ok(format!("{}\n", kept.join("\n").trim()))
}

/// The part's functions in GLSL `version`, as a library: written with an empty entry point
/// (compute for desktop GLSL, fragment for GLSL ES) that is cut off with its stage lines.
fn library_glsl(part: &Part, version: naga::back::glsl::Version) -> Result<Vec<u8>, Error> {
    let stage = if version.is_es() {
        naga::ShaderStage::Fragment
    } else {
        naga::ShaderStage::Compute
    };
    let mut module = part.module.clone();
    module.entry_points.push(naga::EntryPoint {
        name: super::wgsl::ENTRY_POINT.into(),
        stage,
        early_depth_test: None,
        workgroup_size: if version.is_es() { [0; 3] } else { [1; 3] },
        workgroup_size_overrides: None,
        function: naga::Function::default(),
        mesh_info: None,
        task_payload: None,
        incoming_ray_payload: None,
    });
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .map_err(|e| Error(e.to_string()))?;
    let text = String::from_utf8(glsl(&module, &info, version, stage)?)
        .map_err(|e| Error(e.to_string()))?;
    let cut = text
        .rfind("void main()")
        .ok_or_else(|| Error("no entry point in the GLSL".into()))?;
    let kept: Vec<&str> = text[..cut]
        .lines()
        .filter(|l| !l.starts_with("layout(local_size_x") && !l.contains("GL_ARB_compute_shader"))
        .collect();
    Ok(format!("{}\n", kept.join("\n").trim_end()).into_bytes())
}

/// A validated module in `lang`.
fn write_module(
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    lang: Lang,
) -> Result<Vec<u8>, Error> {
    let err = |e: &dyn fmt::Display| Error(e.to_string());
    match lang {
        Lang::SpirV => {
            let pipeline = naga::back::spv::PipelineOptions {
                shader_stage: naga::ShaderStage::Compute,
                entry_point: super::wgsl::ENTRY_POINT.into(),
            };
            let words = naga::back::spv::write_vec(
                module,
                info,
                &naga::back::spv::Options::default(),
                Some(&pipeline),
            )
            .map_err(|e| err(&e))?;
            Ok(words.iter().flat_map(|w| w.to_le_bytes()).collect())
        }
        Lang::Msl => {
            let (text, _) = naga::back::msl::write_string(
                module,
                info,
                &naga::back::msl::Options::default(),
                &naga::back::msl::PipelineOptions::default(),
            )
            .map_err(|e| err(&e))?;
            Ok(text.into_bytes())
        }
        Lang::Glsl => glsl(
            module,
            info,
            naga::back::glsl::Version::Desktop(450),
            naga::ShaderStage::Compute,
        ),
        Lang::Hlsl => {
            let mut text = String::new();
            let options = naga::back::hlsl::Options::default();
            let pipeline = naga::back::hlsl::PipelineOptions::default();
            let mut w = naga::back::hlsl::Writer::new(&mut text, &options, &pipeline);
            w.write(module, info, None).map_err(|e| err(&e))?;
            Ok(text.into_bytes())
        }
    }
}

/// A module with one entry point, [`super::wgsl::ENTRY_POINT`] of `stage`, in GLSL `version`.
fn glsl(
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    version: naga::back::glsl::Version,
    stage: naga::ShaderStage,
) -> Result<Vec<u8>, Error> {
    let mut text = String::new();
    let options = naga::back::glsl::Options {
        version,
        ..Default::default()
    };
    let pipeline = naga::back::glsl::PipelineOptions {
        shader_stage: stage,
        entry_point: super::wgsl::ENTRY_POINT.into(),
        multiview: None,
    };
    let err = |e: &dyn fmt::Display| Error(e.to_string());
    let mut w = naga::back::glsl::Writer::new(
        &mut text,
        module,
        info,
        &options,
        &pipeline,
        naga::proc::BoundsCheckPolicies::default(),
    )
    .map_err(|e| err(&e))?;
    w.write().map_err(|e| err(&e))?;
    Ok(text.into_bytes())
}
