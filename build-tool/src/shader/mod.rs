//! The runtime's WGSL sampling kernel (`nuld_runtime::shader`) in other shading
//! languages, through naga's back ends: GLSL (compute shader, `#version 450`),
//! HLSL (shader model 5.1), MSL (2.0), SPIR-V (1.0 binary) and WGSL itself.
//!
//! Every translation is checked before it is returned: the WGSL source is parsed
//! and validated; the output is parsed back and validated where naga has a front
//! end for the language (WGSL, SPIR-V, GLSL), and for HLSL and MSL the validated
//! module is what the back end wrote ([`Check`] says which check an output had).
//!
//! The layout the WGSL assumes (byte offsets, codes, struct layouts) is held to
//! `nuld_core`'s Rust definitions by [`layout`].

pub mod layout;

use naga::back::{glsl, hlsl, msl, spv, wgsl};
use naga::valid::{Capabilities, ModuleInfo, ValidationFlags, Validator};
use naga::{Module, ShaderStage};
use nuld_runtime::shader::{kernel_wgsl, KERNEL_ENTRY_POINT};

/// A shading language `build-tool shader --lang` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Lang {
    /// WGSL (WebGPU), as naga writes it back.
    Wgsl,
    /// GLSL 4.50 core, compute shader (Vulkan / OpenGL 4.5).
    Glsl,
    /// HLSL, shader model 5.1 (Direct3D 12).
    Hlsl,
    /// Metal Shading Language 2.0.
    Msl,
    /// SPIR-V 1.0, binary (Vulkan).
    Spv,
}

impl Lang {
    /// Every language, in CLI order.
    pub const ALL: [Lang; 5] = [Lang::Wgsl, Lang::Glsl, Lang::Hlsl, Lang::Msl, Lang::Spv];

    /// The language's name as `--lang` spells it.
    pub fn name(self) -> &'static str {
        match self {
            Lang::Wgsl => "wgsl",
            Lang::Glsl => "glsl",
            Lang::Hlsl => "hlsl",
            Lang::Msl => "msl",
            Lang::Spv => "spv",
        }
    }
}

/// How a translation was checked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Check {
    /// The output was parsed back by naga's front end and validated.
    RoundTrip,
    /// No naga front end reads the language: the module the back end wrote was
    /// validated.
    ValidatedModule,
}

/// A translated kernel: the bytes to write (UTF-8 text, or SPIR-V words
/// little-endian) and how they were checked.
#[derive(Clone, Debug)]
pub struct Translation {
    /// The shader, ready to write to a file.
    pub bytes: Vec<u8>,
    /// The check the output passed.
    pub check: Check,
}

/// A failed translation: one line naming the stage and naga's message.
#[derive(Debug, thiserror::Error)]
pub enum ShaderError {
    /// The WGSL source did not parse.
    #[error("the WGSL kernel does not parse: {0}")]
    Parse(String),
    /// naga's validator rejected a module (the source or a parsed-back output).
    #[error("{what} does not validate: {message}")]
    Invalid {
        /// Which module.
        what: &'static str,
        /// naga's message.
        message: String,
    },
    /// A back end failed.
    #[error("the {lang} back end failed: {message}")]
    Backend {
        /// The language.
        lang: &'static str,
        /// naga's message.
        message: String,
    },
    /// The output did not parse back.
    #[error("the {lang} output does not parse back: {message}")]
    ParseBack {
        /// The language.
        lang: &'static str,
        /// naga's message.
        message: String,
    },
    /// The parsed-back output lacks the kernel's entry point.
    #[error("the {lang} output has no compute entry point")]
    NoEntryPoint {
        /// The language.
        lang: &'static str,
    },
}

/// One line of a naga error and its sources (naga's `Display` of a validation
/// error names only the outer context).
fn one_line(e: &dyn std::error::Error) -> String {
    let mut parts = vec![e.to_string()];
    let mut source = e.source();
    while let Some(s) = source {
        parts.push(s.to_string());
        source = s.source();
    }
    parts.join(": ").replace('\n', " ")
}

/// Validates `module` with every check and no optional capability beyond what a
/// compute kernel on any WebGPU device has.
pub fn validate(module: &Module, what: &'static str) -> Result<ModuleInfo, ShaderError> {
    Validator::new(ValidationFlags::all(), Capabilities::default())
        .validate(module)
        .map_err(|e| ShaderError::Invalid {
            what,
            message: one_line(e.as_inner()),
        })
}

/// The runtime's kernel (`nuld_runtime::shader::kernel_wgsl`) parsed and validated.
pub fn kernel_module() -> Result<(Module, ModuleInfo), ShaderError> {
    let module = naga::front::wgsl::parse_str(kernel_wgsl())
        .map_err(|e| ShaderError::Parse(e.emit_to_string(kernel_wgsl()).replace('\n', " ")))?;
    let info = validate(&module, "the WGSL kernel")?;
    Ok((module, info))
}

/// The kernel in `lang`, checked ([`Check`]).
pub fn translate(lang: Lang) -> Result<Translation, ShaderError> {
    let (module, info) = kernel_module()?;
    let backend = |message: String| ShaderError::Backend {
        lang: lang.name(),
        message,
    };
    let parse_back = |message: String| ShaderError::ParseBack {
        lang: lang.name(),
        message,
    };
    let (bytes, parsed) = match lang {
        Lang::Wgsl => {
            let text = wgsl::write_string(&module, &info, wgsl::WriterFlags::empty())
                .map_err(|e| backend(one_line(&e)))?;
            let back = naga::front::wgsl::parse_str(&text)
                .map_err(|e| parse_back(e.emit_to_string(&text).replace('\n', " ")))?;
            (text.into_bytes(), Some(back))
        }
        Lang::Spv => {
            let options = spv::Options {
                flags: spv::WriterFlags::empty(),
                ..spv::Options::default()
            };
            let pipeline = spv::PipelineOptions {
                shader_stage: ShaderStage::Compute,
                entry_point: KERNEL_ENTRY_POINT.to_string(),
            };
            let words = spv::write_vec(&module, &info, &options, Some(&pipeline))
                .map_err(|e| backend(one_line(&e)))?;
            let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
            let back = naga::front::spv::parse_u8_slice(&bytes, &Default::default())
                .map_err(|e| parse_back(one_line(&e)))?;
            (bytes, Some(back))
        }
        Lang::Glsl => {
            // `layout(binding = N)` from each resource's WGSL `@binding(N)` (all
            // resources are in group 0).
            let binding_map = module
                .global_variables
                .iter()
                .filter_map(|(_, v)| v.binding)
                .filter_map(|b| u8::try_from(b.binding).ok().map(|slot| (b, slot)))
                .collect();
            let options = glsl::Options {
                version: glsl::Version::Desktop(450),
                writer_flags: glsl::WriterFlags::empty(),
                binding_map,
                ..glsl::Options::default()
            };
            let pipeline = glsl::PipelineOptions {
                shader_stage: ShaderStage::Compute,
                entry_point: KERNEL_ENTRY_POINT.to_string(),
                multiview: None,
            };
            let mut text = String::new();
            glsl::Writer::new(
                &mut text,
                &module,
                &info,
                &options,
                &pipeline,
                naga::proc::BoundsCheckPolicies::default(),
            )
            .and_then(|mut w| w.write())
            .map_err(|e| backend(one_line(&e)))?;
            let mut frontend = naga::front::glsl::Frontend::default();
            let back = frontend
                .parse(
                    &naga::front::glsl::Options::from(ShaderStage::Compute),
                    &text,
                )
                .map_err(|e| parse_back(e.emit_to_string(&text).replace('\n', " ")))?;
            (text.into_bytes(), Some(back))
        }
        Lang::Hlsl => {
            let options = hlsl::Options::default();
            let pipeline = hlsl::PipelineOptions {
                entry_point: Some((ShaderStage::Compute, KERNEL_ENTRY_POINT.to_string())),
            };
            let mut text = String::new();
            hlsl::Writer::new(&mut text, &options, &pipeline)
                .write(&module, &info, None)
                .map_err(|e| backend(one_line(&e)))?;
            (text.into_bytes(), None)
        }
        Lang::Msl => {
            let options = msl::Options {
                lang_version: (2, 0),
                ..msl::Options::default()
            };
            let pipeline = msl::PipelineOptions {
                entry_point: Some((ShaderStage::Compute, KERNEL_ENTRY_POINT.to_string())),
                ..msl::PipelineOptions::default()
            };
            let (text, _) = msl::write_string(&module, &info, &options, &pipeline)
                .map_err(|e| backend(one_line(&e)))?;
            (text.into_bytes(), None)
        }
    };
    let check = match parsed {
        Some(back) => {
            validate(&back, "the parsed-back output")?;
            if !back
                .entry_points
                .iter()
                .any(|ep| ep.stage == ShaderStage::Compute)
            {
                return Err(ShaderError::NoEntryPoint { lang: lang.name() });
            }
            Check::RoundTrip
        }
        None => Check::ValidatedModule,
    };
    Ok(Translation { bytes, check })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shader_kernel_parses_and_validates() {
        let (module, _) = kernel_module().unwrap();
        let ep = &module.entry_points[0];
        assert_eq!(ep.name, KERNEL_ENTRY_POINT);
        assert_eq!(ep.stage, ShaderStage::Compute);
        assert_eq!(
            ep.workgroup_size,
            [nuld_runtime::shader::KERNEL_WORKGROUP_SIZE, 1, 1]
        );
    }

    /// The library text alone, with the blob binding the README tells users to
    /// declare, is a valid module (no dependency on the kernel's text).
    #[test]
    fn shader_library_validates_with_the_documented_binding() {
        let src = format!(
            "@group(0) @binding(0) var<storage, read> {}: array<u32>;\n{}",
            nuld_runtime::shader::BLOB_VARIABLE,
            nuld_runtime::shader::WGSL
        );
        let module = naga::front::wgsl::parse_str(&src).unwrap();
        validate(&module, "the library").unwrap();
        for name in [
            "nuld_point",
            "nuld_direction",
            "nuld_sample",
            "nuld_sample_network",
            "nuld_sample_brdf",
            "nuld_sample_brdf_network",
            "nuld_sample_brdf_randomized",
            "nuld_sample_brdf_network_randomized",
            "nuld_pdf_brdf",
            "nuld_albedo_brdf",
            "nuld_sample_metallic",
            "nuld_pdf_metallic",
            "nuld_albedo",
            "nuld_weight",
        ] {
            assert!(
                module
                    .functions
                    .iter()
                    .any(|(_, f)| f.name.as_deref() == Some(name)),
                "{name}"
            );
        }
    }

    /// The README's example shader (tests/examples/shader_sample.wgsl) after the
    /// library is a valid module: what a user copies compiles.
    #[test]
    fn shader_readme_example_validates() {
        let src = [
            nuld_runtime::shader::WGSL,
            include_str!("../../../tests/examples/shader_sample.wgsl"),
        ]
        .concat();
        let module = naga::front::wgsl::parse_str(&src).unwrap();
        validate(&module, "the README example").unwrap();
    }

    #[test]
    fn shader_translations_pass_their_checks() {
        for lang in Lang::ALL {
            let t = translate(lang).unwrap_or_else(|e| panic!("{}: {e}", lang.name()));
            let want = match lang {
                Lang::Hlsl | Lang::Msl => Check::ValidatedModule,
                _ => Check::RoundTrip,
            };
            assert_eq!(t.check, want, "{}", lang.name());
            match lang {
                Lang::Spv => {
                    // The SPIR-V magic number, little-endian.
                    assert_eq!(t.bytes[..4], 0x0723_0203u32.to_le_bytes());
                    assert_eq!(t.bytes.len() % 4, 0);
                }
                Lang::Glsl => {
                    let text = String::from_utf8(t.bytes).unwrap();
                    assert!(text.starts_with("#version 450"), "{}", &text[..40]);
                    assert!(text.contains("local_size_x = 64"));
                }
                Lang::Hlsl => {
                    let text = String::from_utf8(t.bytes).unwrap();
                    assert!(text.contains("[numthreads(64, 1, 1)]"));
                }
                Lang::Msl => {
                    let text = String::from_utf8(t.bytes).unwrap();
                    assert!(text.contains("kernel void"));
                }
                Lang::Wgsl => {
                    let text = String::from_utf8(t.bytes).unwrap();
                    assert!(text.contains("@compute"));
                }
            }
        }
    }
}
