//! The previewer as a library: a bake rendered on the GPU by one of the papers' estimators
//! (`render` specifies them, `gpu` runs them), checked against the same render on the CPU, the
//! independent converged estimate and the table its wavelet encoding compresses, as captioned
//! pictures and a report ([`run`]); and the interactive window ([`window`]). `brdf-preview` is
//! its command line: a [`Request`]'s fields are that tool's options, and messages name them as
//! the options they are (`--spp`, `--max-samples`).
//!
//! Nothing is written here: [`run`] returns every picture as PNG bytes with the path and role it
//! is for ([`Output`]), so that the caller writes them together or not at all.

mod adaptive;
mod checks;
mod outputs;
mod scene;
mod views;
pub mod window;

pub use scene::mesh;

use std::path::{Path, PathBuf};
use std::time::Instant;

use envmap::ToneMapping;
use render::{Estimator, Image, Lighting, Scene, Settings, metrics};
use serde_json::json;

use crate::checks::{CONVERGED_SAMPLES, Converged, check_finite, check_psnr, check_work, converged};
use crate::outputs::{contact_sheet, db, json_db, names, png, sibling, tone_mapping, with_caption};
use crate::scene::scene;

/// An error that stops a preview: the request's own (a bake that cannot serve it, work over the
/// limit), a file's, or the renderers'. Messages are one lower-case line naming the file.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The request cannot be served as asked.
    #[error("{0}")]
    Invalid(String),
    #[error(transparent)]
    Bake(#[from] bake::Error),
    #[error(transparent)]
    Render(#[from] render::Error),
    #[error(transparent)]
    Gpu(#[from] gpu::GpuError),
    #[error(transparent)]
    Picture(#[from] envmap::Error),
    /// The window could not open or run.
    #[error("{0}")]
    Window(String),
}

/// `return Err(Error::Invalid(format!(...)))`.
macro_rules! bail {
    ($($message:tt)*) => {
        return Err($crate::Error::Invalid(format!($($message)*)))
    };
}
pub(crate) use bail;

/// What a preview renders: one of the papers' estimators at full resolution, or one adaptive
/// frame shaded by one of them where the predicted bandwidth asks for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Reference,
    Fis,
    Prefiltered,
    Adaptive,
    AdaptivePrefiltered,
}

impl Mode {
    /// The estimator of the shaded pixels.
    pub fn estimator(self) -> Estimator {
        match self {
            Mode::Reference | Mode::Adaptive => Estimator::Reference,
            Mode::Fis => Estimator::Fis,
            Mode::Prefiltered | Mode::AdaptivePrefiltered => Estimator::Prefiltered,
        }
    }

    pub fn is_adaptive(self) -> bool {
        matches!(self, Mode::Adaptive | Mode::AdaptivePrefiltered)
    }

    /// The name on the command line and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Adaptive => "adaptive",
            Mode::AdaptivePrefiltered => "adaptive-prefiltered",
            other => other.estimator().name(),
        }
    }
}

/// Which BRDF the estimators evaluate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Brdf {
    /// The MERL table (nearest lookup).
    Table,
    /// Its Haar wavelet encoding (Claustres et al. 2007), decoded on the GPU.
    WaveletBrdf,
}

/// A preview, as `brdf-preview`'s options ask for it (its `--help` says what each does).
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    pub bake: PathBuf,
    /// The picture to write (`None` with `window` or with only a `sheet`).
    pub out: Option<PathBuf>,
    pub material: Option<PathBuf>,
    pub brdf: Brdf,
    pub wavelet_brdf: Option<PathBuf>,
    pub wavelet_brdf_lod: f64,
    /// `sphere`, `torus` or the path of a Wavefront OBJ file.
    pub mesh: String,
    pub mode: Mode,
    pub spp: Option<u32>,
    pub frames: Option<u32>,
    pub aa: usize,
    pub predict_level: usize,
    pub allocation: render::adaptive::Allocation,
    pub lobe_weight: bool,
    pub layer_shift: u32,
    pub debug_views: bool,
    /// Width and height.
    pub size: (usize, usize),
    pub exposure: Option<f32>,
    /// Azimuth and elevation, degrees.
    pub camera: (f32, f32),
    pub seed: u32,
    pub validate: bool,
    pub converged: Option<u32>,
    /// Render the bake's glTF fit (`brdf-bake --fit`) beside the material, with the same estimator.
    pub compare_fit: bool,
    pub min_psnr: Option<f64>,
    pub max_samples: u64,
    pub sheet: Option<PathBuf>,
    /// Open the interactive window instead of rendering `out`.
    pub window: bool,
    /// With `window`: save what the window shows once its frames are done, and close it.
    pub window_screenshot: Option<PathBuf>,
}

/// A picture a preview made: where it goes, what it is (`preview`, `difference`, `converged`,
/// `table`, `fit`, `fit-difference`, `debug-views`, `contact-sheet`) and its PNG bytes.
#[derive(Clone, Debug, PartialEq)]
pub struct Output {
    pub path: PathBuf,
    pub role: &'static str,
    pub bytes: Vec<u8>,
}

/// What a preview made: its pictures, a report for people, the problems its checks found (a
/// PSNR under `min_psnr`, an adaptive frame planned differently on the GPU and the CPU) and its
/// figures as one JSON object (without the files, which the caller describes once written).
#[derive(Clone, Debug, PartialEq)]
pub struct Rendered {
    pub files: Vec<Output>,
    pub report: Vec<String>,
    pub problems: Vec<String>,
    pub json: serde_json::Value,
}

/// How a preview ended.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    Rendered(Rendered),
    /// The window was closed; with a screenshot, a line saying what it shows.
    Window(Option<String>),
}

/// What the caller lends a preview: a progress bar, and the way to open the GPU.
pub trait Host: Sync {
    /// A new step begins (`"reference on the GPU"`).
    fn step(&self, _what: String) {}
    /// Within the current step, `done` of `total` units are done (from any thread).
    fn work(&self, _done: u64, _total: u64) {}
    /// The GPU the renders run on.
    fn open_gpu(&self) -> Result<gpu::Gpu, gpu::GpuError> {
        gpu::Gpu::new()
    }
}

/// A host with no progress bar that opens the GPU plainly.
impl Host for () {}

/// Renders, checks and pictures a bake as `request` asks (or opens its window).
pub fn run(request: &Request, host: &dyn Host) -> Result<Outcome, Error> {
    // Where the outputs go must exist before anything is rendered.
    for path in request.out.iter().chain(&request.sheet) {
        checks::check_output_folder(path)?;
    }
    let mut loaded = bake::load(&request.bake, request.material.as_deref())?;
    set_wavelet_brdf(request, &mut loaded)?;
    // Every output is encoded before any is written.
    let mut rendered = Rendered { files: Vec::new(), report: Vec::new(), problems: Vec::new(), json: json!({}) };
    if let Some(path) = &request.sheet {
        let sheet = contact_sheet(&loaded)?;
        let bytes = png(&sheet.rgb, sheet.width, sheet.height)?;
        rendered.files.push(Output { path: path.clone(), role: "contact-sheet", bytes });
    }
    if request.out.is_none() && !request.window {
        return Ok(Outcome::Rendered(rendered));
    }
    let Some(lighting) = &loaded.lighting else {
        bail!(
            "{}: the bake has no environment, nothing to light the material with: bake it with brdf-bake --env",
            request.bake.display()
        );
    };
    if request.compare_fit && (request.window || !matches!(request.mode, Mode::Reference | Mode::Fis)) {
        bail!(
            "--compare-fit renders the reference and fis modes to a file: the prefiltered and adaptive modes read the \
             measured material's layer selection and bandwidth atlas, which the fit has none of"
        );
    }
    let step = if request.mode.is_adaptive() {
        if request.window {
            bail!("--window renders the reference, fis and prefiltered modes; the adaptive modes render to a file");
        }
        let out = request.out.as_ref().expect("a request renders to `out` unless it opens the window");
        adaptive::render(request, &loaded, lighting, out, host)?
    } else {
        match estimator(request, &loaded, lighting, host)? {
            Outcome::Rendered(step) => step,
            window => return Ok(window),
        }
    };
    rendered.files.extend(step.files);
    rendered.report.extend(step.report);
    rendered.problems.extend(step.problems);
    rendered.json = step.json;
    Ok(Outcome::Rendered(rendered))
}

/// With `--brdf wavelet-brdf`, the material's wavelet encoding: the one `--wavelet-brdf` names
/// or one baked now, at `--wavelet-brdf-lod`.
fn set_wavelet_brdf(request: &Request, loaded: &mut bake::Loaded) -> Result<(), Error> {
    if request.brdf != Brdf::WaveletBrdf {
        if request.wavelet_brdf.is_some() {
            bail!("--wavelet-brdf names the asset for --brdf wavelet-brdf; add --brdf wavelet-brdf to render with it");
        }
        return Ok(());
    }
    let (path, brdf) = match &request.wavelet_brdf {
        Some(path) => (path.clone(), bake::load_wavelet_brdf(path, loaded)?),
        None => bake::bake_wavelet_brdf(loaded)?,
    };
    let levels = brdf.grid().levels() as f64;
    if !(0.0..=levels).contains(&request.wavelet_brdf_lod) {
        bail!(
            "--wavelet-brdf-lod {} is outside 0 to {levels} (the levels of {})",
            request.wavelet_brdf_lod,
            path.display()
        );
    }
    loaded.material.wavelet_brdf = Some(render::WaveletBrdfLod { brdf, lod: request.wavelet_brdf_lod });
    Ok(())
}

/// One of the estimators (`reference`, `fis`, `prefiltered`) on the GPU, written to `out` or shown
/// in the window, with the checks `request` asks for: the table's render where the material is
/// a wavelet encoding, the CPU's (`--validate`), the converged estimate (`--converged`).
fn estimator(request: &Request, loaded: &bake::Loaded, lighting: &Lighting, host: &dyn Host) -> Result<Outcome, Error> {
    let mode = request.mode.estimator();
    let settings = Settings::previewer(mode, &loaded.material.samples, request.spp, request.frames, request.seed);
    let scene = scene(request)?;
    let pixels = (scene.width * scene.height) as u128;
    let gpu_samples = pixels * u128::from(settings.spp) * u128::from(settings.frames);
    let fit = match request.compare_fit {
        true => {
            let (path, table) = bake::bake_fit_table(loaded)?;
            Some((path, render::Material { table, wavelet_brdf: None, ..loaded.material.clone() }))
        }
        false => None,
    };
    let renders = 1 + u128::from(loaded.material.wavelet_brdf.is_some()) + u128::from(request.compare_fit);
    let converged_samples = request.converged.or(request.compare_fit.then_some(CONVERGED_SAMPLES));
    check_work(
        request,
        &[
            ("on the GPU", renders * gpu_samples),
            ("for --validate on the CPU", if request.validate { gpu_samples } else { 0 }),
            ("for the converged estimate on the CPU", pixels * 3 * u128::from(converged_samples.unwrap_or(0))),
        ],
    )?;
    let tone_mapping = tone_mapping(request, lighting);
    if request.window {
        let screenshot = request.window_screenshot.as_deref();
        let shown = window::run(&loaded.material, lighting, &scene, &settings, &tone_mapping, screenshot)?;
        return Ok(Outcome::Window(shown));
    }
    let gpu = host.open_gpu()?;
    let out = request.out.as_ref().expect("a request renders to `out` unless it opens the window");
    let mut renderer = gpu::preview::Renderer::new(&gpu, &scene, &loaded.material, lighting)?;
    host.step(format!("{} on the GPU", mode.name()));
    let start = Instant::now();
    let image = renderer.render_frames(&settings)?;
    check_finite(request, &image.rgb, "the GPU render")?;
    let ms_per_frame = start.elapsed().as_secs_f64() * 1e3 / f64::from(settings.frames);
    let picture = metrics::tonemap(&image, &tone_mapping);
    let render = EstimatorRender {
        scene: &scene,
        settings: &settings,
        tone_mapping: &tone_mapping,
        out,
        image: &image,
        picture: &picture,
    };
    let mut step = render.rendered(request, loaded, &gpu, ms_per_frame)?;
    if loaded.material.wavelet_brdf.is_some() {
        render.against_table(request, &gpu, loaded, lighting, host, &mut step)?;
    }
    if request.validate {
        render.against_cpu(request, loaded, lighting, host, &mut step)?;
    }
    let converged = match converged_samples {
        Some(n) => Some((n, render.converged(request, loaded, lighting, n, host)?)),
        None => None,
    };
    if let (Some(_), Some((n, converged))) = (request.converged, &converged) {
        render.against_converged(*n, converged, request, &mut step)?;
    }
    if let (Some(fit), Some(converged)) = (fit, &converged) {
        render.against_fit(request, &gpu, loaded, lighting, fit, converged, host, &mut step)?;
    }
    Ok(Outcome::Rendered(step))
}

/// Another material's render beside an estimator's ([`EstimatorRender::beside`]): its picture,
/// and its PSNR and relative error against the estimator's render.
struct Beside {
    picture: Vec<u8>,
    psnr: f64,
    relative: f64,
}

/// An estimator's render on the GPU, for the checks that compare it.
struct EstimatorRender<'a> {
    scene: &'a Scene,
    settings: &'a Settings,
    tone_mapping: &'a ToneMapping,
    out: &'a Path,
    image: &'a Image,
    picture: &'a [u8],
}

impl EstimatorRender<'_> {
    /// The captioned picture, the report's line and the JSON of the render.
    fn rendered(
        &self,
        request: &Request,
        loaded: &bake::Loaded,
        gpu: &gpu::Gpu,
        ms_per_frame: f64,
    ) -> Result<Rendered, Error> {
        let (scene, settings, tone_mapping, out) = (self.scene, self.settings, self.tone_mapping, self.out);
        let mode = settings.estimator;
        let brdf = match &loaded.material.wavelet_brdf {
            Some(w) => format!("wavelet-brdf {}:1, lod {}", picture::format_number(w.brdf.ratio()), w.lod),
            None => "table".to_string(),
        };
        let caption = format!(
            "{} | {} | {brdf} | {} spp x {} frames | {}x{} | exposure {:+.2} EV",
            names(&loaded.manifest),
            mode.name(),
            settings.spp,
            settings.frames,
            scene.width,
            scene.height,
            tone_mapping.exposure_ev
        );
        let captioned = with_caption(self.picture, scene.width, scene.height, &caption);
        Ok(Rendered {
            files: vec![Output {
                path: out.to_path_buf(),
                role: "preview",
                bytes: png(&captioned.rgb, captioned.width, captioned.height)?,
            }],
            report: vec![format!(
                "{}: {} on {} ({}), {:.1} ms per frame",
                out.display(),
                mode.name(),
                gpu.adapter_summary(),
                request.mesh,
                ms_per_frame
            )],
            problems: Vec::new(),
            json: json!({
                "bake": request.bake.display().to_string(),
                "mode": mode.name(),
                "brdf": match request.brdf { Brdf::Table => "table", Brdf::WaveletBrdf => "wavelet-brdf" },
                "spp": settings.spp,
                "frames": settings.frames,
                "width": scene.width,
                "height": scene.height,
                "exposure_ev": tone_mapping.exposure_ev,
                "adapter": gpu.adapter_summary(),
                "ms_per_frame": ms_per_frame,
                "mean_luminance": metrics::mean_luminance(self.image),
            }),
        })
    }

    /// The same render of another `material` on the GPU (`what` names it: "from the table"), its
    /// picture, and its PSNR and relative error against this render.
    fn beside(
        &self,
        request: &Request,
        gpu: &gpu::Gpu,
        material: &render::Material,
        lighting: &Lighting,
        what: &str,
        host: &dyn Host,
    ) -> Result<Beside, Error> {
        let settings = self.settings;
        host.step(format!("{} {what} on the GPU", settings.estimator.name()));
        let image = gpu::preview::Renderer::new(gpu, self.scene, material, lighting)?.render_frames(settings)?;
        check_finite(request, &image.rgb, &format!("the GPU render {what}"))?;
        let picture = metrics::tonemap(&image, self.tone_mapping);
        let psnr = metrics::psnr_db(self.picture, &picture);
        let relative = metrics::relative_error(&self.image.rgb, &image.rgb);
        Ok(Beside { picture, psnr, relative })
    }

    /// What the wavelet compression costs: the same render from the table itself.
    fn against_table(
        &self,
        request: &Request,
        gpu: &gpu::Gpu,
        loaded: &bake::Loaded,
        lighting: &Lighting,
        host: &dyn Host,
        step: &mut Rendered,
    ) -> Result<(), Error> {
        let scene = self.scene;
        let table_material = render::Material { wavelet_brdf: None, ..loaded.material.clone() };
        let Beside { picture: table_picture, psnr, relative } =
            self.beside(request, gpu, &table_material, lighting, "from the table", host)?;
        step.files.push(Output {
            path: sibling(self.out, "table"),
            role: "table",
            bytes: png(&table_picture, scene.width, scene.height)?,
        });
        step.report.push(format!(
            "against the table (same estimator, same samples, the MERL table's nearest lookup): PSNR {} dB, \
             relative error {relative:.3}",
            db(psnr)
        ));
        step.json["against_table"] = json!({ "psnr_db": json_db(psnr), "relative_error": relative });
        Ok(())
    }

    /// `--validate`: the same render on the CPU, and the difference picture.
    fn against_cpu(
        &self,
        request: &Request,
        loaded: &bake::Loaded,
        lighting: &Lighting,
        host: &dyn Host,
        step: &mut Rendered,
    ) -> Result<(), Error> {
        let scene = self.scene;
        host.step(format!("{} on the CPU (--validate)", self.settings.estimator.name()));
        let cpu = render::render_with_progress(scene, &loaded.material, lighting, self.settings, &|done, all| {
            host.work(done, all)
        })?;
        check_finite(request, &cpu.rgb, "the CPU render")?;
        let cpu_picture = metrics::tonemap(&cpu, self.tone_mapping);
        let psnr = metrics::psnr_db(self.picture, &cpu_picture);
        let relative = metrics::relative_error(&self.image.rgb, &cpu.rgb);
        let coverage = self.image.covered.iter().zip(&cpu.covered).filter(|(a, b)| a != b).count();
        let difference =
            picture::layout::difference(self.picture, &cpu_picture, scene.width, scene.height, "GPU - CPU");
        step.files.push(Output {
            path: sibling(self.out, "difference"),
            role: "difference",
            bytes: png(&difference.rgb, difference.width, difference.height)?,
        });
        step.report.push(format!(
            "against the CPU (same estimator, same samples): PSNR {} dB, relative error {relative:.2e}, {coverage} \
             pixels covered by one renderer only",
            db(psnr)
        ));
        step.json["psnr_db"] = json_db(psnr);
        step.json["relative_error"] = json!(relative);
        step.json["coverage_mismatches"] = json!(coverage);
        check_psnr(request, "against the CPU", psnr, &mut step.problems);
        Ok(())
    }

    /// The material's converged estimate of `n` samples per strategy on the CPU, and the render
    /// measured against it.
    fn converged(
        &self,
        request: &Request,
        loaded: &bake::Loaded,
        lighting: &Lighting,
        n: u32,
        host: &dyn Host,
    ) -> Result<Converged, Error> {
        let rendered = (self.image, self.picture);
        converged(request, self.scene, &loaded.material, lighting, n, rendered, self.tone_mapping, host)
    }

    /// `--converged N`: the render against the converged estimate of `n` samples per strategy.
    fn against_converged(
        &self,
        n: u32,
        converged: &Converged,
        request: &Request,
        step: &mut Rendered,
    ) -> Result<(), Error> {
        let scene = self.scene;
        let Converged { image: converged, picture: converged_picture, psnr, relative } = converged;
        let (psnr, relative) = (*psnr, *relative);
        let luminance_ratio = metrics::mean_luminance(self.image) / metrics::mean_luminance(converged);
        step.files.push(Output {
            path: sibling(self.out, "converged"),
            role: "converged",
            bytes: png(converged_picture, scene.width, scene.height)?,
        });
        step.report.push(format!(
            "against the converged estimate ({n} samples per strategy): PSNR {} dB, relative error {relative:.3}, \
             mean luminance ratio {luminance_ratio:.4}",
            db(psnr)
        ));
        step.json["converged"] = json!({
            "samples_per_strategy": n,
            "psnr_db": json_db(psnr),
            "relative_error": relative,
            "mean_luminance_ratio": luminance_ratio,
        });
        check_psnr(request, "against the converged estimate", psnr, &mut step.problems);
        Ok(())
    }

    /// `--compare-fit`: the bake's glTF fit (`brdf-bake --fit`, tabulated on the MERL grid, so that
    /// the estimator renders the fitted BRDF exactly) with the same estimator, samples and camera:
    /// its picture (OUT-fit.png), its difference from the material's (OUT-fit-difference.png, with
    /// its scale), and the PSNR of the fit against the material's render and against its
    /// converged estimate, beside the render's own (what noise alone costs). The fit is sampled
    /// with the material's importance samples: each sample weighed by its own density, the
    /// estimator stays unbiased for the fit (multiple importance sampling with the environment
    /// covers where the material's table has no density), and both pictures share their samples.
    #[allow(clippy::too_many_arguments)]
    fn against_fit(
        &self,
        request: &Request,
        gpu: &gpu::Gpu,
        loaded: &bake::Loaded,
        lighting: &Lighting,
        (path, fit_material): (PathBuf, render::Material),
        (n, converged): &(u32, Converged),
        host: &dyn Host,
        step: &mut Rendered,
    ) -> Result<(), Error> {
        let (scene, settings) = (self.scene, self.settings);
        let Beside { picture: fit_picture, psnr, relative } =
            self.beside(request, gpu, &fit_material, lighting, "of the glTF fit", host)?;
        let fit_converged = metrics::psnr_db(&fit_picture, &converged.picture);
        let caption = format!(
            "glTF fit of {} ({}) | {} | {} spp x {} frames | exposure {:+.2} EV",
            names(&loaded.manifest),
            path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned()),
            settings.estimator.name(),
            settings.spp,
            settings.frames,
            self.tone_mapping.exposure_ev
        );
        let captioned = with_caption(&fit_picture, scene.width, scene.height, &caption);
        let difference =
            picture::layout::difference(self.picture, &fit_picture, scene.width, scene.height, "material - glTF fit");
        step.files.push(Output {
            path: sibling(self.out, "fit"),
            role: "fit",
            bytes: png(&captioned.rgb, captioned.width, captioned.height)?,
        });
        step.files.push(Output {
            path: sibling(self.out, "fit-difference"),
            role: "fit-difference",
            bytes: png(&difference.rgb, difference.width, difference.height)?,
        });
        step.report.push(format!(
            "the glTF fit ({}) against the material (same estimator, same samples): PSNR {} dB, relative error \
             {relative:.2e}; against the material's converged estimate ({n} samples per strategy): the fit {} dB, the \
             material's render {} dB",
            path.display(),
            db(psnr),
            db(fit_converged),
            db(converged.psnr)
        ));
        step.json["fit"] = json!({
            "table": path.display().to_string(),
            "psnr_db": json_db(psnr),
            "relative_error": relative,
            "against_converged": {
                "samples_per_strategy": n,
                "fit_psnr_db": json_db(fit_converged),
                "material_psnr_db": json_db(converged.psnr),
            },
        });
        Ok(())
    }
}
