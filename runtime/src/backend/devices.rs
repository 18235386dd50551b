//! `--devices`: the devices a render is asked to use ([`Devices`], each a [`Device`]), parsed
//! and resolved to the backend's own.

use super::{Backend, Resolve, Usage};
use crate::gpu::{self, cuda::Cuda};

/// Which devices a render uses (`--devices`).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Devices {
    /// The one device `--backend` picks.
    #[default]
    Auto,
    /// Every GPU of the backend: every CUDA device, or every wgpu adapter (the CPU is not
    /// one of them).
    All,
    /// These, in order: GPUs by index (CUDA devices, or wgpu adapters, as `sdfc devices`
    /// lists them), and `cpu`. An index given twice opens the device twice: two logical
    /// devices that share it.
    List(Vec<Device>),
}

/// One entry of `--devices`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Device {
    /// The CPU renderer.
    Cpu,
    /// A GPU by index.
    Gpu(usize),
}

impl Devices {
    /// Reads `--devices`: `auto`, `all`, or a comma-separated list of indices and `cpu`.
    pub fn parse(text: &str) -> Result<Devices, Usage> {
        match text.trim() {
            "auto" => return Ok(Devices::Auto),
            "all" => return Ok(Devices::All),
            _ => {}
        }
        text.split(',')
            .map(|entry| match entry.trim() {
                "cpu" => Ok(Device::Cpu),
                e => e
                    .parse()
                    .map(Device::Gpu)
                    .map_err(|_| Usage::DevicesEntry(e.into())),
            })
            .collect::<Result<Vec<_>, _>>()
            .map(Devices::List)
    }

    /// The devices of `backend` these name; `None` for `auto` (the one device the backend
    /// picks). Every caller reports a failure as `job::Error::unavailable` does: GPUs asked of
    /// the CPU backend are a usage error, `all` finding none a device error.
    pub fn resolve(&self, backend: Backend) -> Result<Option<Vec<Device>>, Resolve> {
        let list: Vec<Device> = match self {
            Devices::Auto => return Ok(None),
            Devices::All => match gpu_kind(backend)? {
                Backend::Cuda => (0..Cuda::count()).map(Device::Gpu).collect(),
                _ => (0..gpu::wgpu::adapters().len()).map(Device::Gpu).collect(),
            },
            Devices::List(list) => list.clone(),
        };
        if list.is_empty() {
            return Err(Resolve::NoDevice(match gpu_kind(backend)? {
                Backend::Cuda => "cuda",
                _ => "wgpu",
            }));
        }
        Ok(Some(list))
    }

    /// `Err` naming the first entry `backend` cannot render on (a GPU with `--backend cpu`).
    pub fn check(&self, backend: Backend) -> Result<(), Usage> {
        match self {
            Devices::List(list) if backend == Backend::Cpu => {
                match list.iter().find_map(|d| match d {
                    Device::Gpu(i) => Some(*i),
                    Device::Cpu => None,
                }) {
                    Some(i) => Err(Usage::GpuOnCpu(i)),
                    None => Ok(()),
                }
            }
            Devices::All if backend == Backend::Cpu => Err(Usage::AllOnCpu),
            _ => Ok(()),
        }
    }
}

/// Whose GPUs `--devices` indexes: CUDA's or wgpu's (for `auto`, CUDA's where a driver has
/// devices).
pub(super) fn gpu_kind(backend: Backend) -> Result<Backend, Usage> {
    match backend {
        Backend::Cuda | Backend::Wgpu => Ok(backend),
        Backend::Auto if Cuda::count() > 0 => Ok(Backend::Cuda),
        Backend::Auto => Ok(Backend::Wgpu),
        Backend::Cpu => Err(Usage::GpusOnCpu),
    }
}
