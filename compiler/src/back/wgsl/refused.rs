//! `Refused`: why the kernel asked for cannot render a scene (`choose`), with the data of each
//! reason and the limit that would let it.

use super::interp::Unfit;
use std::fmt;

/// Why the kernel asked for cannot render a scene.
#[derive(Debug, Clone, PartialEq)]
pub enum Refused {
    /// The scene's meshes take `mib` MiB of `scene_data`, above the limit of `limit` MiB;
    /// `raise` says how to raise it.
    MeshData { mib: u64, limit: u64, raise: String },
    /// The interpreted kernel was asked for a scene traced analytically, which has no
    /// distance program in its kernel.
    InterpretedTraced,
    /// The interpreted kernel cannot hold the scene's programs; `raise` says how to raise the
    /// limit that would let it, where one would.
    Interpreted { unfit: Unfit, raise: Option<String> },
}

impl fmt::Display for Refused {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            Refused::MeshData { mib, limit, raise } => write!(
                f,
                "the scene's meshes take {mib} MiB of scene_data, above the scene_data limit \
                 of {limit} MiB; {raise}"
            ),
            Refused::InterpretedTraced => write!(
                f,
                "the interpreted kernel runs a distance program, and this scene is traced \
                 analytically, with no distance program in its kernel; march it with \
                 `--set method=march`, or use `--kernel specialised` or `--kernel auto`"
            ),
            Refused::Interpreted { unfit, raise } => {
                let raise = raise.as_deref().unwrap_or_default();
                match unfit {
                    Unfit::Registers(needed, file) => write!(
                        f,
                        "the interpreted kernel cannot run this scene: its distance program \
                         needs {needed} registers and the kernel has {file}; {raise} (or use \
                         `--kernel specialised`)"
                    ),
                    Unfit::Words(words) => write!(
                        f,
                        "the interpreted kernel cannot run this scene: its distance programs \
                         take {words} instructions, more than the 2^24 it can address; use \
                         `--kernel specialised`"
                    ),
                    Unfit::Bytes(bytes, mib) => write!(
                        f,
                        "the interpreted kernel cannot run this scene: its distance program \
                         takes {} MiB of scene_data, above the scene_data limit of {mib} MiB; \
                         {raise} (or use `--kernel specialised`)",
                        bytes.div_ceil(1 << 20)
                    ),
                }
            }
        }
    }
}

impl std::error::Error for Refused {}
