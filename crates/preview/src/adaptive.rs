//! `Mode::Adaptive` and `Mode::AdaptivePrefiltered`: one frame of bandwidth-driven
//! multi-resolution shading on the GPU (`gpu::preview::Renderer::render_adaptive`, held to
//! `render::adaptive`), its checks and its debug views.

use std::path::Path;

use render::{Mode as Estimator, Scene, metrics};
use serde_json::json;

use crate::checks::{
    Converged, check_finite, check_psnr, check_work, converged, db, json_db, names, png, scene, sibling, tone_mapping,
    with_caption,
};
use crate::{Error, Host, Output, Rendered, Request};

/// One adaptive frame as `request` asks for it, written to `out`.
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
    let mode = request.mode.estimator();
    let settings = render::adaptive::Settings {
        supersample: request.aa,
        predict_level: request.predict_level,
        allocation: request.allocation,
        lobe_weight: request.lobe_weight,
        layer_shift: request.layer_shift,
        seed: request.seed,
        ..render::adaptive::Settings::new(mode, request.spp.unwrap_or(if mode == Estimator::Reference { 8 } else { 4 }))
    };
    let scene = scene(request)?;
    let ss = settings.supersample;
    let pixels = (scene.width * ss * scene.height * ss) as u128;
    let frame_samples = pixels * u128::from(settings.spp);
    let converged_samples = if request.validate || request.converged.is_some() {
        (scene.width * scene.height) as u128 * 3 * u128::from(request.converged.unwrap_or(256))
    } else {
        0
    };
    check_work(
        request,
        &[
            // A first frame compiles the pipelines, then the frame that is timed.
            ("on the GPU", 2 * frame_samples),
            ("for --validate on the CPU", if request.validate { frame_samples } else { 0 }),
            ("for the converged estimate on the CPU", converged_samples),
        ],
    )?;
    let tone_mapping = tone_mapping(request, lighting);
    let gpu = host.open_gpu()?;
    let render_scene = Scene { width: scene.width * ss, height: scene.height * ss, ..scene.clone() };
    let mut renderer = gpu::preview::Renderer::new(&gpu, &render_scene, &loaded.material, lighting)?;
    renderer.set_bandwidths(bandwidths)?;
    host.step(format!("{} on the GPU", request.mode.name()));
    // A driver may compile a pipeline at its first dispatch (lavapipe does, tens of
    // milliseconds): a frame first, so that ms_per_frame times the frame. The G-buffer and its
    // upload are the camera's, made once for all its frames as the other modes' raster pass is.
    renderer.render_adaptive(&loaded.material, lighting, &settings, Default::default())?;
    let geometry = renderer.adaptive_geometry(ss)?;
    // The frame's buffers come back after its timings, for the views and the checks that read them.
    let details = request.debug_views || request.validate || request.converged.is_some();
    let options = gpu::preview::FrameOptions { details, ..Default::default() };
    let frame = renderer.render_adaptive(&loaded.material, lighting, &settings, options)?;
    check_finite(request, &frame.image.rgb, "the GPU's adaptive frame")?;
    let t = frame.timings;
    let ms_per_frame = t.total_ms;
    let picture = metrics::tonemap(&frame.image, &tone_mapping);
    let aa = settings.supersample * settings.supersample;
    // The pre-convolved estimator's layers, where they are not the bake's.
    let layers = match (mode, settings.layer_shift) {
        (Estimator::Prefiltered, n) if n > 0 => format!(" ({n} layer{} sharper)", if n == 1 { "" } else { "s" }),
        _ => String::new(),
    };
    let caption = format!(
        "{} | {}{layers} | {} spp budget, {} samples | shaded fraction {:.3} | AA {aa}x | {}x{} | exposure {:+.2} EV",
        names(&loaded.manifest),
        request.mode.name(),
        settings.spp,
        frame.samples,
        frame.shaded_fraction(),
        scene.width,
        scene.height,
        tone_mapping.exposure_ev
    );
    let captioned = with_caption(&picture, scene.width, scene.height, &caption);
    let mut files = vec![Output {
        path: out.to_path_buf(),
        role: "preview",
        bytes: png(&captioned.rgb, captioned.width, captioned.height)?,
    }];
    if request.debug_views {
        let sheet = crate::views::debug_views(
            &frame,
            settings.allocation,
            &picture,
            &format!("{}: {}", request.mode.name(), names(&loaded.manifest)),
        );
        files.push(Output {
            path: sibling(out, "debug"),
            role: "debug-views",
            bytes: png(&sheet.rgb, sheet.width, sheet.height)?,
        });
    }
    let steps = match (t.submissions, t.gpu_clock) {
        (1, true) => format!(
            "one submission; on the GPU's clock prediction {:.1}, pyramids, plan and samples {:.1}, shading, \
             up-sampling and output {:.1}",
            t.predict_ms, t.plan_ms, t.shade_ms
        ),
        (1, false) => "one submission".to_string(),
        _ => format!(
            "prediction, pyramids and plan {:.1} on the GPU, samples {:.1} on the CPU, shading, up-sampling and output \
             {:.1} on the GPU",
            t.predict_ms, t.plan_ms, t.shade_ms
        ),
    };
    let mut report = vec![format!(
        "{}: {} on {} ({}), {ms_per_frame:.1} ms ({steps}; the camera's G-buffer on the CPU before, once: {:.1}); \
         shaded fraction {:.4}, {} samples of a budget of {}",
        out.display(),
        request.mode.name(),
        gpu.adapter_summary(),
        request.mesh,
        t.gbuffer_ms,
        frame.shaded_fraction(),
        frame.samples,
        frame.budget
    )];
    let mut value = json!({
        "bake": request.bake.display().to_string(),
        "mode": request.mode.name(),
        "adapter": gpu.adapter_summary(),
        "spp": settings.spp,
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
        "shaded_fraction": frame.shaded_fraction(),
        "shaded_per_level": frame.shaded_per_level,
        "samples": frame.samples,
        "budget": frame.budget,
        "mean_luminance": metrics::mean_luminance(&frame.image),
    });
    let mut problems = Vec::new();
    if request.validate {
        // The CPU's own prediction: the levels equal but where a direction on the edge of a
        // nearest texel reads its neighbour in f32 (the tests hold 98% of them equal). Only the
        // predictions are read, so its blocks are not shaded.
        host.step(format!("{} on the CPU (--validate)", request.mode.name()));
        let mut unshaded = |blocks: &[(u32, u32)]| Ok(vec![[0.0f32; 3]; blocks.len()]);
        let hooks = render::adaptive::Hooks { shader: Some(&mut unshaded), ..Default::default() };
        let own = render::adaptive::render_with(&geometry, &loaded.material, lighting, bandwidths, &settings, hooks)?;
        let predicted =
            frame.details().predictions.iter().zip(&own.details().predictions).filter(|(g, _)| g.level >= 0);
        let (pixels, differ) =
            predicted.fold((0usize, 0usize), |(n, d), (g, c)| (n + 1, d + usize::from(g.level != c.level)));
        // The same frame with the GPU's predictions on the CPU: the plan is the same (the weights
        // to f32 rounding: the GPU's are f32), the values equal to rounding.
        let mut replay = render::adaptive::replay_predictor(&frame.details().predictions);
        let hooks = render::adaptive::Hooks { predictor: Some(&mut replay), ..Default::default() };
        let cpu = render::adaptive::render_with(&geometry, &loaded.material, lighting, bandwidths, &settings, hooks)?;
        let cpu_picture = metrics::tonemap(&cpu.image, &tone_mapping);
        let psnr = metrics::psnr_db(&picture, &cpu_picture);
        let relative = metrics::relative_error(&frame.image.rgb, &cpu.image.rgb);
        let plan = frame.details().plan.compare(&cpu.details().plan, 1e-5);
        let same_plan = plan.is_ok();
        report.push(format!(
            "against the CPU: {differ} of {pixels} pixels predicted at another level than the CPU predicts; \
             with the GPU's predictions ({}): PSNR {} dB, relative error {relative:.2e}",
            match &plan {
                Ok(worst) => format!("the same plan, weights within {worst:.1e}"),
                Err(e) => format!("NOT the same plan: {e}"),
            },
            db(psnr)
        ));
        value["cpu"] = json!({
            "psnr_db": json_db(psnr),
            "relative_error": relative,
            "same_plan": same_plan,
            "prediction": { "pixels": pixels, "levels_differ": differ },
        });
        if !same_plan {
            problems.push(
                "the GPU's adaptive frame was planned differently from the CPU's with the same predictions".to_string(),
            );
        }
        if 50 * differ > pixels {
            problems.push(format!(
                "{differ} of {pixels} pixels were predicted at another level on the GPU than on the CPU"
            ));
        }
        check_psnr(request, "against the CPU", psnr, &mut problems);
    }
    if request.validate || request.converged.is_some() {
        let n = request.converged.unwrap_or(256);
        let Converged { image: converged, picture: converged_picture, psnr, relative } =
            converged(request, &scene, &loaded.material, lighting, n, (&frame.image, &picture), &tone_mapping, host)?;
        files.push(Output {
            path: sibling(out, "converged"),
            role: "converged",
            bytes: png(&converged_picture, scene.width, scene.height)?,
        });
        report.push(format!(
            "against the converged estimate ({n} samples per strategy): PSNR {} dB, relative error {relative:.3}",
            db(psnr)
        ));
        value["psnr_db"] = json_db(psnr);
        value["relative_error"] = json!(relative);
        value["converged"] = json!({ "samples_per_strategy": n, "psnr_db": json_db(psnr), "relative_error": relative });
        check_psnr(request, "against the converged estimate", psnr, &mut problems);
        if ss == 1 {
            // The same plan with the converged values in its shaded blocks: the up-sampling's
            // error alone, the PSNR no budget can pass (render pixels are the converged
            // estimate's pixels only without anti-aliasing).
            let predictions = &frame.details().predictions;
            let ceiling = render::adaptive::ceiling(
                &geometry,
                &loaded.material,
                lighting,
                bandwidths,
                &settings,
                predictions,
                &converged,
                None,
            )?;
            let ceiling = metrics::psnr_db(&metrics::tonemap(&ceiling.image, &tone_mapping), &converged_picture);
            report.push(format!(
                "the plan's ceiling (its shaded blocks given the converged values, as exact as they are): PSNR {} dB; \
                 near it, more --spp does not help, the up-sampling is the error",
                db(ceiling)
            ));
            value["ceiling_db"] = json_db(ceiling);
        }
    }
    Ok(Rendered { files, report, problems, json: value })
}
