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
        Lang::Glsl => {
            let mut module = part.module.clone();
            module.entry_points.push(naga::EntryPoint {
                name: super::wgsl::ENTRY_POINT.into(),
                stage: naga::ShaderStage::Compute,
                early_depth_test: None,
                workgroup_size: [1, 1, 1],
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
            let text = String::from_utf8(write_module(&module, &info, lang)?)
                .map_err(|e| Error(e.to_string()))?;
            let cut = text
                .rfind("void main()")
                .ok_or_else(|| Error("no entry point in the GLSL".into()))?;
            let kept: Vec<&str> = text[..cut]
                .lines()
                .filter(|l| {
                    !l.starts_with("layout(local_size_x") && !l.contains("GL_ARB_compute_shader")
                })
                .collect();
            Ok(format!(
                "{}
",
                kept.join("\n").trim_end()
            )
            .into_bytes())
        }
    }
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
        Lang::Glsl => {
            let mut text = String::new();
            let options = naga::back::glsl::Options {
                version: naga::back::glsl::Version::Desktop(450),
                ..Default::default()
            };
            let pipeline = naga::back::glsl::PipelineOptions {
                shader_stage: naga::ShaderStage::Compute,
                entry_point: super::wgsl::ENTRY_POINT.into(),
                multiview: None,
            };
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
