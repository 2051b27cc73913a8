//! `Mode::Adaptive` and `Mode::AdaptivePrefiltered`: frames of bandwidth-driven
//! multi-resolution shading on the GPU (`gpu::preview::Renderer::render_adaptive`, held to
//! `render::adaptive`), averaged, their checks and the first frame's debug views.

use std::path::Path;

use render::{Estimator, Scene, metrics};
use serde_json::{Value, json};

use crate::checks::{CONVERGED_SAMPLES, Converged, check_finite, check_psnr, check_work, converged};
use crate::outputs::{db, json_db, names, png, sibling, tone_mapping, with_caption};
use crate::scene::scene;
use crate::{Error, Host, Output, Rendered, Request};

/// The mean of the adaptive frames `request` asks for (`render::adaptive`, "Frames"), written to
/// `out`.
pub(crate) fn render(
    request: &Request,
    loaded: &bake::Loaded,
    lighting: &render::Lighting,
    out: &Path,
    host: &dyn Host,
) -> Result<Rendered, Error> {
    let bandwidths = loaded.bandwidths.as_ref().ok_or_else(|| {
        Error::Invalid(format!(
            "{}: the bake has no environment bandwidth and atlas: bake it with brdf-bake --env",
            request.bake.display()
        ))
    })?;
    let settings = render::adaptive::Settings {
        supersample: request.aa,
        predict_level: request.predict_level,
        allocation: request.allocation,
        lobe_weight: request.lobe_weight,
        layer_shift: request.layer_shift,
        seed: request.seed,
        frames: request.frames.unwrap_or(render::adaptive::FRAMES),
        ..render::adaptive::Settings::new(request.mode.estimator(), request.spp.unwrap_or(render::adaptive::SPP))
    };
    let scene = scene(request)?;
    check_adaptive_work(request, &scene, &settings)?;
    let tone_mapping = tone_mapping(request, lighting);
    let gpu = host.open_gpu()?;
    let ss = settings.supersample;
    let render_scene = Scene { width: scene.width * ss, height: scene.height * ss, ..scene.clone() };
    let mut renderer = gpu::preview::Renderer::new(&gpu, &render_scene, &loaded.material, lighting)?;
    renderer.set_bandwidths(bandwidths)?;
    host.step(format!("{} on the GPU", request.mode.name()));
    let inputs = Inputs { request, loaded, lighting, bandwidths, settings: &settings, host };
    let mut frames = inputs.frames(&renderer)?;
    let picture = metrics::tonemap(&frames.image, &tone_mapping);
    let mut step = inputs.picture(&frames, &picture, &scene, &tone_mapping, out, &gpu)?;
    std::mem::take(&mut frames.validation).report(request, (&frames.image, &picture), &tone_mapping, &mut step);
    if request.validate || request.converged.is_some() {
        let view = (&frames.image, &picture[..]);
        inputs.against_converged(&scene, &frames, view, &tone_mapping, out, &mut step)?;
    }
    Ok(step)
}

/// Fails where the frames, the CPU's validation and the converged estimate would take more
/// samples than `--max-samples` allows.
fn check_adaptive_work(request: &Request, scene: &Scene, settings: &render::adaptive::Settings) -> Result<(), Error> {
    let ss = settings.supersample;
    let pixels = (scene.width * ss * scene.height * ss) as u128;
    let frame_samples = pixels * u128::from(settings.spp);
    let converged_samples = if request.validate || request.converged.is_some() {
        (scene.width * scene.height) as u128 * 3 * u128::from(request.converged.unwrap_or(CONVERGED_SAMPLES))
    } else {
        0
    };
    let frames_samples = u128::from(settings.frames) * frame_samples;
    check_work(
        request,
        &[
            // A first frame compiles the pipelines, then the frames that are timed.
            ("on the GPU", frame_samples + frames_samples),
            ("for --validate on the CPU", if request.validate { frames_samples } else { 0 }),
            ("for the converged estimate on the CPU", converged_samples),
        ],
    )
}

/// What the frames of a request are rendered and checked from.
struct Inputs<'a> {
    request: &'a Request,
    loaded: &'a bake::Loaded,
    lighting: &'a render::Lighting,
    bandwidths: &'a render::adaptive::Bandwidths,
    settings: &'a render::adaptive::Settings,
    host: &'a dyn Host,
}

/// The frames of a request, averaged, with what their checks keep of them.
struct Frames {
    image: render::Image,
    /// The first frame, with its buffers where a view or a check reads them.
    first: render::adaptive::Adaptive,
    sum: Sums,
    validation: Validation,
    /// Each frame's settings and predictions, for the ceiling (without anti-aliasing).
    predictions: Vec<(render::adaptive::Settings, Vec<render::adaptive::Prediction>)>,
    geometry: std::sync::Arc<render::adaptive::Geometry>,
}

/// Where an adaptive frame's time goes, in words, from its timings (ms).
fn steps(t: &render::adaptive::Timings) -> String {
    match (t.submissions, t.gpu_clock) {
        (1, true) => format!(
            "one submission; on the GPU's clock prediction {:.1}, pyramids, plan and samples {:.1}, shading, \
             up-sampling and output {:.1}",
            t.predict_ms, t.plan_ms, t.shade_ms
        ),
        (1, false) => "one submission".to_string(),
        _ => format!(
            "prediction, pyramids and plan {:.1} on the GPU, samples {:.1} on the CPU, shading, up-sampling and \
             output {:.1} on the GPU",
            t.predict_ms, t.plan_ms, t.shade_ms
        ),
    }
}

impl Inputs<'_> {
    /// The frames on the GPU, each validated on the CPU as it comes where asked.
    fn frames(&self, renderer: &gpu::preview::Renderer) -> Result<Frames, Error> {
        let Inputs { request, loaded, lighting, bandwidths, settings, host } = *self;
        // A driver may compile a pipeline at its first dispatch (lavapipe does, tens of
        // milliseconds): a frame first, so that ms_per_frame times the frames. The G-buffer and
        // its upload are the camera's, made once for all its frames as the other modes' raster
        // pass is.
        renderer.render_adaptive(&loaded.material, lighting, settings, Default::default())?;
        let geometry = renderer.adaptive_geometry(settings.supersample)?;
        // Each frame's buffers come back after its timings, for the views and the checks that
        // read them; the checks run frame by frame, so that no frame's buffers are kept but the
        // first's (the debug views) and, for the ceiling, the predictions.
        let details = request.debug_views || request.validate || request.converged.is_some();
        let options = gpu::preview::FrameOptions { details, ..Default::default() };
        let mut mean = render::adaptive::FrameMean::default();
        let mut validation = Validation::default();
        let mut predictions = Vec::new();
        let mut first = None;
        let mut sum = Sums::default();
        let frames = settings.frames;
        for f in 0..frames {
            let settings =
                render::adaptive::Settings { seed: render::adaptive::frame_seed(settings.seed, f), ..*settings };
            let frame = renderer.render_adaptive(&loaded.material, lighting, &settings, options)?;
            check_finite(request, &frame.image.rgb, "the GPU's adaptive frame")?;
            mean.add(&frame.image);
            sum.add(&frame);
            if request.validate {
                host.step(format!("{} frame {} of {frames} on the CPU (--validate)", request.mode.name(), f + 1));
                validation.add(&frame, &geometry, loaded, lighting, bandwidths, &settings)?;
            }
            if settings.supersample == 1 && (request.validate || request.converged.is_some()) {
                predictions.push((settings, frame.details().predictions.clone()));
            }
            if f == 0 {
                first = Some(frame);
            }
        }
        let (Some(first), Some(image)) = (first, mean.mean()) else {
            return Err(Error::Invalid("--frames: expected at least one frame".into()));
        };
        Ok(Frames { image, first, sum, validation, predictions, geometry })
    }

    /// The captioned picture, the first frame's debug views where asked, the report's line and
    /// the JSON of the frames.
    fn picture(
        &self,
        frames: &Frames,
        picture: &[u8],
        scene: &Scene,
        tone_mapping: &envmap::ToneMapping,
        out: &Path,
        gpu: &gpu::Gpu,
    ) -> Result<Rendered, Error> {
        let Inputs { request, loaded, settings, .. } = *self;
        let Frames { sum, first: frame, .. } = frames;
        let n = settings.frames;
        let t = sum.timings(n);
        let shaded_fraction = sum.mean_shaded_fraction(n);
        let caption = self.caption(frames, scene, tone_mapping);
        let captioned = with_caption(picture, scene.width, scene.height, &caption);
        let mut files = vec![Output {
            path: out.to_path_buf(),
            role: "preview",
            bytes: png(&captioned.rgb, captioned.width, captioned.height)?,
        }];
        if request.debug_views {
            // The first frame's: the frames' plans differ a little (their own predictions).
            let first_picture = metrics::tonemap(&frame.image, tone_mapping);
            let sheet = crate::views::debug_views(
                frame,
                settings.allocation,
                &first_picture,
                &format!("{}: {} (frame 1 of {n})", request.mode.name(), names(&loaded.manifest)),
            );
            files.push(Output {
                path: sibling(out, "debug"),
                role: "debug-views",
                bytes: png(&sheet.rgb, sheet.width, sheet.height)?,
            });
        }
        let report = vec![format!(
            "{}: {} on {} ({}), {n} frames of {:.1} ms ({}; the camera's G-buffer on the CPU \
             before, once: {:.1}); shaded fraction {shaded_fraction:.4}, {} samples of a budget of {}",
            out.display(),
            request.mode.name(),
            gpu.adapter_summary(),
            request.mesh,
            t.total_ms,
            steps(&t),
            t.gbuffer_ms,
            sum.samples,
            sum.budget
        )];
        let json = self.json(frames, scene, tone_mapping, gpu);
        Ok(Rendered { files, report, problems: Vec::new(), json })
    }

    /// The picture's caption: the bake, the estimator, the budget and samples, the shaded
    /// fraction, the anti-aliasing, the size and the exposure.
    fn caption(&self, frames: &Frames, scene: &Scene, tone_mapping: &envmap::ToneMapping) -> String {
        let Inputs { request, loaded, settings, .. } = *self;
        let (sum, n) = (&frames.sum, settings.frames);
        let aa = settings.supersample * settings.supersample;
        // The prefiltered estimator's layers, where they are not the bake's.
        let layers = match (settings.estimator, settings.layer_shift) {
            (Estimator::Prefiltered, k) if k > 0 => format!(" ({k} layer{} sharper)", if k == 1 { "" } else { "s" }),
            _ => String::new(),
        };
        let shaded_fraction = sum.mean_shaded_fraction(n);
        format!(
            "{} | {}{layers} | {} spp budget x {n} frames, {} samples | shaded fraction {shaded_fraction:.3} | AA \
             {aa}x | {}x{} | exposure {:+.2} EV",
            names(&loaded.manifest),
            request.mode.name(),
            settings.spp,
            sum.samples,
            scene.width,
            scene.height,
            tone_mapping.exposure_ev
        )
    }

    /// The JSON of the frames: their settings, timings, shaded fraction and samples.
    fn json(&self, frames: &Frames, scene: &Scene, tone_mapping: &envmap::ToneMapping, gpu: &gpu::Gpu) -> Value {
        let Inputs { request, settings, .. } = *self;
        let Frames { sum, first: frame, image, .. } = frames;
        let n = settings.frames;
        let t = sum.timings(n);
        let ms_per_frame = t.total_ms;
        let aa = settings.supersample * settings.supersample;
        let shaded_fraction = sum.mean_shaded_fraction(n);
        json!({
            "bake": request.bake.display().to_string(),
            "mode": request.mode.name(),
            "adapter": gpu.adapter_summary(),
            "spp": settings.spp,
            "frames": n,
            "aa": aa,
            "predict_level": settings.predict_level,
            "allocation": settings.allocation.name(),
            "lobe_weight": settings.lobe_weight,
            "layer_shift": settings.layer_shift,
            "width": scene.width,
            "height": scene.height,
            "exposure_ev": tone_mapping.exposure_ev,
            "ms_per_frame": ms_per_frame,
            "timings_ms": {
                "gbuffer": t.gbuffer_ms,
                "prediction": t.predict_ms,
                "plan_and_samples": t.plan_ms,
                "shading": t.shade_ms,
                "submissions": t.submissions,
                "gpu_clock": t.gpu_clock,
            },
            "shaded_fraction": shaded_fraction,
            "shaded_per_level": frame.shaded_per_level,
            "samples": sum.samples,
            "budget": sum.budget,
            "mean_luminance": metrics::mean_luminance(image),
        })
    }

    /// Against the converged estimate, and without anti-aliasing the plans' ceiling: the same
    /// plans with the converged values in their shaded blocks, averaged, the up-sampling's error
    /// alone, the PSNR no budget can pass (render pixels are the converged estimate's pixels only
    /// without anti-aliasing).
    fn against_converged(
        &self,
        scene: &Scene,
        frames: &Frames,
        (image, picture): (&render::Image, &[u8]),
        tone_mapping: &envmap::ToneMapping,
        out: &Path,
        step: &mut Rendered,
    ) -> Result<(), Error> {
        let Inputs { request, loaded, lighting, bandwidths, host, .. } = *self;
        let n = request.converged.unwrap_or(CONVERGED_SAMPLES);
        let Converged { image: converged, picture: converged_picture, psnr, relative } =
            converged(request, scene, &loaded.material, lighting, n, (image, picture), tone_mapping, host)?;
        step.files.push(Output {
            path: sibling(out, "converged"),
            role: "converged",
            bytes: png(&converged_picture, scene.width, scene.height)?,
        });
        step.report.push(format!(
            "against the converged estimate ({n} samples per strategy): PSNR {} dB, relative error {relative:.3}",
            db(psnr)
        ));
        step.json["psnr_db"] = json_db(psnr);
        step.json["relative_error"] = json!(relative);
        step.json["converged"] =
            json!({ "samples_per_strategy": n, "psnr_db": json_db(psnr), "relative_error": relative });
        check_psnr(request, "against the converged estimate", psnr, &mut step.problems);
        if self.settings.supersample != 1 {
            return Ok(());
        }
        let mut ceiling = render::adaptive::FrameMean::default();
        for (settings, predictions) in &frames.predictions {
            let frame = render::adaptive::ceiling(
                &frames.geometry,
                &loaded.material,
                lighting,
                bandwidths,
                settings,
                predictions,
                &converged,
                None,
            )?;
            ceiling.add(&frame.image);
        }
        if let Some(ceiling) = ceiling.mean() {
            let ceiling = metrics::psnr_db(&metrics::tonemap(&ceiling, tone_mapping), &converged_picture);
            step.report.push(format!(
                "the plans' ceiling (their shaded blocks given the converged values, as exact as they are): PSNR {} \
                 dB; near it, more --spp does not help, the up-sampling is the error",
                db(ceiling)
            ));
            step.json["ceiling_db"] = json_db(ceiling);
        }
        Ok(())
    }
}

impl Validation {
    /// `--validate`'s figures: the frames on the CPU from the GPU's predictions against the GPU's.
    fn report(
        self,
        request: &Request,
        (image, picture): (&render::Image, &[u8]),
        tone_mapping: &envmap::ToneMapping,
        step: &mut Rendered,
    ) {
        let Some(cpu) = self.cpu.mean() else { return };
        let Validation { pixels, differ, ref plan, .. } = self;
        let cpu_picture = metrics::tonemap(&cpu, tone_mapping);
        let psnr = metrics::psnr_db(picture, &cpu_picture);
        let relative = metrics::relative_error(&image.rgb, &cpu.rgb);
        let same_plan = plan.is_ok();
        step.report.push(format!(
            "against the CPU: {differ} of {pixels} pixels predicted at another level than the CPU predicts; with the \
             GPU's predictions ({}): PSNR {} dB, relative error {relative:.2e}",
            match plan {
                Ok(worst) => format!("the same plans, weights within {worst:.1e}"),
                Err(e) => format!("NOT the same plan: {e}"),
            },
            db(psnr)
        ));
        step.json["cpu"] = json!({
            "psnr_db": json_db(psnr),
            "relative_error": relative,
            "same_plan": same_plan,
            "prediction": { "pixels": pixels, "levels_differ": differ },
        });
        if !same_plan {
            step.problems.push(
                "the GPU's adaptive frame was planned differently from the CPU's with the same predictions".into(),
            );
        }
        if 50 * differ > pixels {
            step.problems.push(format!(
                "{differ} of {pixels} pixels were predicted at another level on the GPU than on the CPU"
            ));
        }
        check_psnr(request, "against the CPU", psnr, &mut step.problems);
    }
}

/// The frames' figures, summed.
#[derive(Default)]
struct Sums {
    timings: render::adaptive::Timings,
    shaded_fraction: f64,
    samples: u64,
    budget: u64,
}

impl Sums {
    fn add(&mut self, frame: &render::adaptive::Adaptive) {
        let (t, s) = (&frame.timings, &mut self.timings);
        s.gbuffer_ms = t.gbuffer_ms;
        s.predict_ms += t.predict_ms;
        s.plan_ms += t.plan_ms;
        s.shade_ms += t.shade_ms;
        s.total_ms += t.total_ms;
        s.submissions = t.submissions;
        s.gpu_clock = t.gpu_clock;
        self.shaded_fraction += frame.shaded_fraction();
        self.samples += frame.samples;
        self.budget += frame.budget;
    }

    /// The shaded fraction of a mean frame of `frames`.
    fn mean_shaded_fraction(&self, frames: u32) -> f64 {
        self.shaded_fraction / f64::from(frames)
    }

    /// The timings of a mean frame of `frames`.
    fn timings(&self, frames: u32) -> render::adaptive::Timings {
        let n = f64::from(frames.max(1));
        let t = self.timings;
        render::adaptive::Timings {
            predict_ms: t.predict_ms / n,
            plan_ms: t.plan_ms / n,
            shade_ms: t.shade_ms / n,
            total_ms: t.total_ms / n,
            ..t
        }
    }
}

/// `--validate`, frame by frame: the CPU's own predictions against the GPU's, and each frame
/// again on the CPU from the GPU's predictions (the same plan, the values equal to rounding).
struct Validation {
    /// Predicted pixels, and those the CPU predicts at another level.
    pixels: usize,
    differ: usize,
    /// The largest weight difference of the frames' plans, or the first frame planned otherwise.
    plan: Result<f64, String>,
    cpu: render::adaptive::FrameMean,
}

impl Default for Validation {
    fn default() -> Self {
        Validation { pixels: 0, differ: 0, plan: Ok(0.0), cpu: Default::default() }
    }
}

impl Validation {
    fn add(
        &mut self,
        frame: &render::adaptive::Adaptive,
        geometry: &render::adaptive::Geometry,
        loaded: &bake::Loaded,
        lighting: &render::Lighting,
        bandwidths: &render::adaptive::Bandwidths,
        settings: &render::adaptive::Settings,
    ) -> Result<(), Error> {
        // The CPU's own prediction: the levels equal but where a direction on the edge of a
        // nearest texel reads its neighbour in f32 (the tests hold 98% of them equal). Only the
        // predictions are read, so its blocks are not shaded.
        let mut unshaded = |blocks: &[(u32, u32)]| Ok(vec![[0.0f32; 3]; blocks.len()]);
        let hooks = render::adaptive::Hooks { shader: Some(&mut unshaded), ..Default::default() };
        let own = render::adaptive::render_with(geometry, &loaded.material, lighting, bandwidths, settings, hooks)?;
        for (g, c) in frame.details().predictions.iter().zip(&own.details().predictions).filter(|(g, _)| g.level >= 0) {
            self.pixels += 1;
            self.differ += usize::from(g.level != c.level);
        }
        // The same frame with the GPU's predictions on the CPU: the plan is the same (the weights
        // to f32 rounding: the GPU's are f32), the values equal to rounding.
        let mut replay = render::adaptive::replay_predictor(&frame.details().predictions);
        let hooks = render::adaptive::Hooks { predictor: Some(&mut replay), ..Default::default() };
        let cpu = render::adaptive::render_with(geometry, &loaded.material, lighting, bandwidths, settings, hooks)?;
        self.plan = match (&self.plan, frame.details().plan.compare(&cpu.details().plan, 1e-5)) {
            (Err(e), _) => Err(e.clone()),
            (Ok(_), Err(e)) => Err(e.to_string()),
            (Ok(a), Ok(b)) => Ok(a.max(f64::from(b))),
        };
        self.cpu.add(&cpu.image);
        Ok(())
    }
}
