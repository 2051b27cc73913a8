//! What the GPU tests share: one device per test process, and a log that CI shows.

use std::io::Write;
use std::sync::OnceLock;

use gpu::Gpu;

/// The device every test uses. Panics with [`gpu::GpuError::NoAdapter`]'s message, which says
/// how to install lavapipe, where the machine has no adapter: GPU tests fail, never skip.
pub fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Result<Gpu, String>> = OnceLock::new();
    let gpu = GPU.get_or_init(|| {
        let gpu = Gpu::new().map_err(|e| e.to_string());
        if let Ok(gpu) = &gpu {
            log(&format!("gpu tests run on {}", gpu.adapter_summary()));
        }
        gpu
    });
    match gpu {
        Ok(gpu) => gpu,
        Err(e) => panic!("{e}"),
    }
}

/// Straight to stderr: the test harness captures `eprintln!` of passing tests, and CI logs must
/// show which adapter ran and what the comparisons measured.
pub fn log(line: &str) {
    let _ = writeln!(std::io::stderr(), "{line}");
}

/// A device on Mesa's GL alone (llvmpipe through EGL), with `cap` applied to the limits it asks
/// for. Panics with the packages to install where the machine has no GL adapter: the portability
/// tests fail, never skip.
pub fn gl_gpu(cap: &dyn Fn(wgpu::Limits) -> wgpu::Limits) -> Gpu {
    let gpu = Gpu::with_backends(wgpu::Backends::GL, cap).unwrap_or_else(|e| {
        panic!(
            "no GL adapter ({e}): on Debian/Ubuntu install Mesa's EGL and GL drivers with \
             'apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri'"
        )
    });
    log(&format!("gl tests run on {}", gpu.adapter_summary()));
    gpu
}
