//! `sdfc devices`: what `--devices` can name on this machine: the CUDA devices and the wgpu
//! adapters by index (name, memory, backend), and the CPU.

use crate::gpu::cuda::Cuda;
use std::process::ExitCode;

/// Arguments of `sdfc devices` (none).
#[derive(Debug, clap::Args)]
pub struct DevicesArgs {}

/// Runs `sdfc devices`: one line per device, CUDA's first, then wgpu's, then the CPU.
pub fn run(_args: DevicesArgs) -> ExitCode {
    let count = Cuda::count();
    if count == 0 {
        match Cuda::open() {
            Err(e) => println!("cuda: none ({e})"),
            Ok(_) => println!("cuda: none"),
        }
    }
    for i in 0..count {
        match Cuda::open_device(i, false) {
            Ok(c) => println!(
                "cuda {i}: {}, {:.1} GiB",
                c.describe(),
                c.memory() as f64 / (1u64 << 30) as f64
            ),
            Err(e) => println!("cuda {i}: cannot be opened: {e}"),
        }
    }
    let adapters = crate::gpu::wgpu::adapters();
    if adapters.is_empty() {
        println!("wgpu: none (no Vulkan, Metal or DX12 adapter)");
    }
    for (i, a) in adapters.iter().enumerate() {
        println!("wgpu {i}: {}", crate::gpu::wgpu::describe_adapter(a));
    }
    println!(
        "cpu: the CPU renderer, {} threads",
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    println!(
        "(--devices takes indices of CUDA devices with --backend cuda, and with --backend auto where CUDA has a device; of wgpu adapters with --backend wgpu, or auto without CUDA; and `cpu`)"
    );
    ExitCode::SUCCESS
}
