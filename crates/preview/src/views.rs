//! `--mode adaptive` and `--mode adaptive-prefiltered`: the debug views of an adaptive frame
//! (`render::adaptive`, on the GPU).

use picture::colormap::{Scale, inferno, viridis};
use picture::layout::{Axis, Grid as Panels, caption, heat_map, stack};
use picture::legend::Legend;
use picture::{Canvas, format_number};
use render::adaptive::Adaptive;

/// Black: pixels the views say nothing about (background, silhouettes).
const NONE: [u8; 3] = [0, 0, 0];

/// The debug views of a frame, as the papers' figures show them (001 Fig. 9, 11, 12): the
/// picture, the level each pixel was shaded at, samples per pixel, the predicted image bandwidth
/// and the predicted variance, each with a legend.
pub fn debug_views(
    frame: &Adaptive,
    allocation: render::adaptive::Allocation,
    picture_rgb: &[u8],
    title: &str,
) -> Canvas {
    let (w, h) = (frame.width, frame.height);
    let details = frame.details();
    let (ow, oh) = (frame.image.width, frame.image.height);
    let zoom = (256 / w.max(h)).max(1);
    let axes = (Axis::new("x, pixels", 0.0, w as f64), Axis::new("y, pixels", 0.0, h as f64));
    let shadeable = |i: usize| details.predictions[i].level >= 0;
    let top = details.plan.levels.len() - 1;

    let levels = Scale::linear(0.0, top.max(1) as f64);
    let level_image = Canvas::from_fn(w, h, |x, y| {
        let l = details.shaded_level[y * w + x];
        if l < 0 { NONE } else { viridis(levels.position(f64::from(l))) }
    });
    let positive = |values: Vec<f64>| -> Vec<f64> { values.into_iter().filter(|v| *v > 0.0).collect() };
    let log_scale = |values: &[f64], decades: f64| {
        let hi = values.iter().copied().fold(0.0f64, f64::max).max(1e-30);
        Scale::log(hi * 10f64.powf(-decades), hi).nice()
    };
    let heat = |values: &dyn Fn(usize) -> f64, scale: &Scale, map: fn(f64) -> [u8; 3]| {
        Canvas::from_fn(w, h, |x, y| {
            let i = y * w + x;
            let v = values(i);
            if !shadeable(i) || v <= 0.0 { NONE } else { map(scale.position(v).clamp(0.0, 1.0)) }
        })
    };
    let spp: Vec<f64> = positive(details.samples_per_pixel.iter().map(|&s| f64::from(s)).collect());
    let spp_scale = log_scale(&spp, 4.0);
    let bandwidth: Vec<f64> = positive(details.predictions.iter().map(|p| p.bandwidth).collect());
    let bandwidth_scale = Scale::log(1e-3, 1.0);
    let variance: Vec<f64> = positive(details.predictions.iter().map(|p| p.variance).collect());
    let variance_scale = log_scale(&variance, 6.0);

    let mut panels = Panels::new(3);
    panels.title(title);
    let image = Canvas::from_rgb8(ow, oh, picture_rgb.to_vec()).resized(w, h);
    panels.add(heat_map(&image, zoom, &axes.0, &axes.1), "the frame");
    panels.add(heat_map(&level_image, zoom, &axes.0, &axes.1), "level each pixel was shaded at");
    panels.add(
        heat_map(&heat(&|i| f64::from(details.samples_per_pixel[i]), &spp_scale, inferno), zoom, &axes.0, &axes.1),
        "samples per pixel",
    );
    panels.add(
        heat_map(&heat(&|i| details.predictions[i].bandwidth, &bandwidth_scale, inferno), zoom, &axes.0, &axes.1),
        "predicted image bandwidth",
    );
    panels.add(
        heat_map(&heat(&|i| details.predictions[i].variance, &variance_scale, viridis), zoom, &axes.0, &axes.1),
        "predicted variance",
    );
    let width = panels.width();
    let text = caption_text(frame, allocation);
    panels.footer(stack(&[
        Legend::new(levels, viridis, "shaded at level k (a block of s x s pixels, s = 2 to the power k; linear)")
            .render(width),
        Legend::new(spp_scale, inferno, "samples per pixel (log scale)")
            .clipped(spp_scale.clipping(&spp))
            .render(width),
        Legend::new(bandwidth_scale, inferno, "predicted image bandwidth, cycles per pixel (log scale)")
            .clipped(bandwidth_scale.clipping(&bandwidth))
            .render(width),
        Legend::new(variance_scale, viridis, "predicted variance, luminance squared (log scale)")
            .clipped(variance_scale.clipping(&variance))
            .render(width),
        caption(&text, width),
    ]));
    panels.render()
}

/// The caption under the debug views: the shaded blocks per level, the samples against the
/// budget, and how each view reads.
fn caption_text(frame: &Adaptive, allocation: render::adaptive::Allocation) -> String {
    let per_level: Vec<String> = frame
        .shaded_per_level
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(k, n)| format!("{n} at {k}"))
        .collect();
    let per_cycle = render::adaptive::SAMPLES_PER_CYCLE;
    let fraction = format_number((frame.shaded_fraction() * 1e4).round() / 1e4);
    let (samples, budget) = (frame.samples, frame.budget);
    let allocation = match allocation {
        render::adaptive::Allocation::Variance => "in proportion to the variance",
        render::adaptive::Allocation::StdDev => "in proportion to the square root of its pixels times the variance",
        render::adaptive::Allocation::Area => "in proportion to the square root of its pixels (the variance not used)",
    };
    format!(
        "Level k: the pixel's value comes from a block of s x s pixels, s = 2 to the power k, shaded once and \
         up-sampled (0: shaded on its own). Shaded blocks per level: {per_level}. {samples} samples of a budget of \
         {budget}; shaded fraction {fraction}. Samples per pixel: a shaded block's samples over its pixels. \
         Bandwidth: cycles per pixel from the environment's and the BRDF's bandwidth through the paper's reflection \
         operators (001 eq. 3-6); the level is floor(log2(1 / ({per_cycle} bandwidth))), {per_cycle} samples per \
         cycle. Variance: the bound of 001 eq. 9 (eq. 10 when prefiltered). A shaded block's samples: \
         {allocation}. Black: background or silhouette.",
        per_level = per_level.join(", "),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each figure lands in its own place in the caption (they were once formatted out of
    /// order, so that the budget read as the samples per cycle).
    #[test]
    fn the_caption_puts_each_figure_in_its_place() {
        let frame = Adaptive {
            image: render::Image { width: 0, height: 0, rgb: Vec::new(), covered: Vec::new() },
            width: 0,
            height: 0,
            shadeable: 1000,
            shaded_per_level: vec![7, 0, 3],
            samples: 123_456,
            budget: 123_457,
            timings: render::adaptive::Timings::default(),
            details: None,
        };
        let text = caption_text(&frame, render::adaptive::Allocation::Area);
        assert!(text.contains("Shaded blocks per level: 7 at 0, 3 at 2."), "{text}");
        assert!(text.contains("123456 samples of a budget of 123457; shaded fraction 0.01."), "{text}");
        let per_cycle = render::adaptive::SAMPLES_PER_CYCLE;
        assert!(text.contains(&format!("floor(log2(1 / ({per_cycle} bandwidth))), {per_cycle} samples per cycle")));
        assert!(text.contains("A shaded block's samples: in proportion to the square root of its pixels"), "{text}");
    }
}
