//! Other shading languages, written by naga from the validated WGSL kernel: SPIR-V, MSL,
//! GLSL and HLSL (`sdfc compile --emit spirv|msl|glsl|hlsl`).

use super::wgsl::Kernel;
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
    let (module, info) = (&kernel.module, &kernel.info);
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
