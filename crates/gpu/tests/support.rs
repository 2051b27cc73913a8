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
