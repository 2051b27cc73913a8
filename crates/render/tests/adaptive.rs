//! Adaptive multi-resolution shading (`render::adaptive`): the pyramid, the plan and the budget
//! keep their invariants on real frames, and the plan reduces to the full-resolution renderer
//! when it may not coarsen.

use rand::{Rng, SeedableRng, rngs::StdRng};
use render::adaptive::{self, Action, Prediction};
use render::{Estimator, Settings};

use crate::fixtures::bandwidths;
use crate::support::{phong, sky_lighting, sphere_scene};

#[test]
fn eq_11_takes_twice_the_nyquist_rate() {
    // Sampling rate 4 nu per pixel; level floor(log2(1 / (4 nu))) in [0, top].
    assert_eq!(adaptive::SAMPLES_PER_CYCLE, 4.0);
    assert_eq!(adaptive::level_of(0.5, 6), 0);
    assert_eq!(adaptive::level_of(0.25, 6), 0);
    assert_eq!(adaptive::level_of(0.2, 6), 0);
    assert_eq!(adaptive::level_of(0.125, 6), 1);
    assert_eq!(adaptive::level_of(0.1, 6), 1);
    assert_eq!(adaptive::level_of(1.0 / 128.0, 6), 5);
    assert_eq!(adaptive::level_of(1.0 / 129.0, 6), 5);
    assert_eq!(adaptive::level_of(1.0 / 256.0, 6), 6);
    assert_eq!(adaptive::level_of(1e-9, 6), 6);
    assert_eq!(adaptive::level_of(0.0, 6), 6);
    assert_eq!(adaptive::level_of(40.0, 6), 0);
}

#[test]
fn frames_average_the_noise_of_the_shaded_blocks() {
    // Frame 0 is the single frame's; the mean of 8 frames (their own seeds, so their own
    // predictions and samples) is nearer the converged estimate than one frame. A Phong lobe
    // under the sky at 4 samples per pixel: one frame's error is mostly noise.
    let (scene, material, lighting, bandwidths) = (sphere_scene(48, 48), phong(0), sky_lighting(), bandwidths());
    let settings = adaptive::Settings { predict_level: 1, ..adaptive::Settings::new(Estimator::Reference, 4) };
    let one = adaptive::render(&scene, material, &lighting, &bandwidths, &settings).unwrap().image;
    assert_eq!(adaptive::render_frames(&scene, material, &lighting, &bandwidths, &settings).unwrap(), one);
    let settings = adaptive::Settings { frames: 8, ..settings };
    let eight = adaptive::render_frames(&scene, material, &lighting, &bandwidths, &settings).unwrap();
    assert_eq!(eight.covered, one.covered);
    let truth = render::converged::converged(&scene, material, &lighting, 256, 1).unwrap();
    let error = |image: &render::Image| render::metrics::relative_error(&image.rgb, &truth.rgb);
    // Independent frames: the noise's share of the error falls by sqrt(8) = 2.8; the bound
    // leaves room for the up-sampling's bias, which frames do not average.
    println!("8 frames {:.4}, one {:.4}", error(&eight), error(&one));
    assert!(error(&eight) < 0.6 * error(&one), "8 frames {:.4} against one {:.4}", error(&eight), error(&one));
    assert_ne!(adaptive::frame_seed(0, 1), adaptive::frame_seed(1, 1));
    assert_eq!(adaptive::frame_seed(7, 0), 7);
}

#[test]
fn the_reflection_operator_matches_its_closed_form() {
    // R = P_x C_-c S B C_c on [0, nu] then T_d': |nu_a| = m + d c (nu + m) / cos, m = min(rho, nu).
    let mut rng = StdRng::seed_from_u64(5);
    for _ in 0..1000 {
        let (nu, rho) = (rng.random::<f64>() * 50.0, rng.random::<f64>() * 50.0);
        let (c, d, cos) = (rng.random::<f64>() * 3.0, rng.random::<f64>() * 10.0, 0.05 + 0.95 * rng.random::<f64>());
        let m = rho.min(nu);
        let expect = m + d * c * (nu + m) / cos;
        let got = adaptive::bandwidth_at_eye(nu, rho, c, d, cos);
        assert!((got - expect).abs() <= 1e-12 * expect.max(1.0), "{nu} {rho} {c} {d} {cos}: {got} vs {expect}");
    }
    // A flat surface shows the reflected bandwidth as it is, whatever the distance.
    assert_eq!(adaptive::bandwidth_at_eye(8.0, 3.0, 0.0, 100.0, 0.5), 3.0);
}

#[test]
fn the_min_pyramid_is_conservative() {
    let mut rng = StdRng::seed_from_u64(9);
    let (w, h, top) = (37, 23, 4);
    let predictions: Vec<Prediction> = (0..w * h)
        .map(|_| Prediction {
            bandwidth: 0.0,
            variance: rng.random::<f64>(),
            level: if rng.random::<f64>() < 0.05 { -1 } else { rng.random_range(0..=top as i32) },
        })
        .collect();
    let levels = adaptive::pyramid(&predictions, w, h, top);
    assert_eq!(levels.len(), top + 1);
    for k in 1..=top {
        let (parent, child) = (&levels[k], &levels[k - 1]);
        assert_eq!((parent.width, parent.height), (child.width.div_ceil(2), child.height.div_ceil(2)));
        for cy in 0..child.height {
            for cx in 0..child.width {
                let (c, p) = (cy * child.width + cx, (cy / 2) * parent.width + cx / 2);
                assert!(parent.min_level[p] <= child.min_level[c], "level {k}: a child finer than its parent");
                assert!(parent.max_variance[p] >= child.max_variance[c]);
                // A block valid at its level has valid children: no child needs a finer level.
                assert!(!parent.valid(p) || child.valid(c), "level {k}, block ({}, {})", cx / 2, cy / 2);
            }
        }
        // The min and the max are attained by a child (not merely bounds).
        for p in 0..parent.width * parent.height {
            let children: Vec<usize> = (0..child.width * child.height)
                .filter(|&c| (c / child.width / 2) * parent.width + (c % child.width) / 2 == p)
                .collect();
            assert_eq!(parent.min_level[p], children.iter().map(|&c| child.min_level[c]).min().unwrap());
            assert_eq!(parent.max_variance[p], children.iter().map(|&c| child.max_variance[c]).fold(0.0, f64::max));
        }
    }
}

/// Every invariant of a frame's plan (module docs): each valid block is shaded or up-sampled,
/// nothing else is computed; an up-sampled block's parents are computed and its weights are
/// positive and sum to 1; a non-rescued shaded block has no valid parent; every shadeable pixel
/// gets a value from a block no coarser than its own level; the samples are powers of two within
/// the cap and within the budget.
fn check_plan(frame: &adaptive::Adaptive, settings: &adaptive::Settings) {
    let plan = &frame.details().plan;
    let top = plan.levels.len() - 1;
    for (k, (level, actions)) in plan.levels.iter().zip(&plan.actions).enumerate() {
        assert_eq!(actions.len(), level.width * level.height);
        for (b, action) in actions.iter().enumerate() {
            let parent = (k < top).then(|| (b / level.width / 2) * plan.levels[k + 1].width + (b % level.width) / 2);
            let parent_valid = parent.is_some_and(|p| plan.levels[k + 1].valid(p));
            match *action {
                Action::Skip => assert!(!level.valid(b), "level {k} block {b}: valid but not computed"),
                Action::Shade { samples, rescued } => {
                    assert!(level.valid(b), "level {k} block {b}: shaded though a pixel needs a finer level");
                    assert!(rescued || !parent_valid, "level {k} block {b}: shaded though its parent is valid");
                    assert!(samples.is_power_of_two() && samples <= settings.max_spp, "{samples} samples");
                }
                Action::Upsample { parents, count } => {
                    assert!(level.valid(b) && parent_valid, "level {k} block {b}");
                    assert!((1..=4).contains(&count));
                    let mut sum = 0.0f64;
                    for &(p, w) in &parents[..count as usize] {
                        assert!(plan.levels[k + 1].valid(p as usize), "level {k} block {b}: parent {p} not computed");
                        assert_ne!(plan.actions[k + 1][p as usize], Action::Skip);
                        assert!(w > 0.0, "weight {w}");
                        sum += f64::from(w);
                    }
                    assert!((sum - 1.0).abs() <= 1e-6, "level {k} block {b}: weights sum to {sum}");
                    // No extrapolation: every parent of the bilinear four with a share of the
                    // block is valid, and counted (the sphere's depth is continuous).
                    let coarser = &plan.levels[k + 1];
                    let xs = bilinear_parents(b % level.width, k, coarser.width);
                    let ys = bilinear_parents(b / level.width, k, coarser.height);
                    for &py in &ys {
                        for &px in &xs {
                            let p = py * coarser.width + px;
                            assert!(
                                parents[..count as usize].iter().any(|&(q, _)| q as usize == p),
                                "level {k} block {b}: up-sampled without its bilinear parent {p} (valid: {})",
                                coarser.valid(p)
                            );
                        }
                    }
                }
            }
        }
    }
    for (p, prediction) in frame.details().predictions.iter().enumerate() {
        let action = plan.actions[0][p];
        if prediction.level < 0 {
            assert_eq!(action, Action::Skip);
            assert_eq!(frame.details().shaded_level[p], -1);
        } else {
            assert_ne!(action, Action::Skip, "shadeable pixel {p} is neither shaded nor up-sampled");
            let shaded = frame.details().shaded_level[p];
            assert!(
                (0..=prediction.level).contains(&shaded),
                "pixel {p}: shaded at {shaded}, needs {}",
                prediction.level
            );
        }
    }
    assert!(plan.samples() <= plan.budget, "{} samples over a budget of {}", plan.samples(), plan.budget);
}

/// Along one axis, the blocks of level `k + 1` (`n` of them) that bilinear interpolation gives a
/// share of block `b` of level `k`, from the blocks' centres (`b 2^k + floor(2^k / 2)`, the
/// module docs' "Coarse to fine"), clamped at the edges.
fn bilinear_parents(b: usize, k: usize, n: usize) -> Vec<usize> {
    let centre = |b: usize, level: usize| (b * (1 << level) + (1 << level) / 2) as f64;
    let t = ((centre(b, k) - centre(0, k + 1)) / f64::from(1u32 << (k + 1))).clamp(0.0, (n - 1) as f64);
    let (lo, hi) = (t.floor() as usize, t.ceil() as usize);
    if lo == hi { vec![lo] } else { vec![lo, hi] }
}

#[test]
fn every_pixel_is_shaded_at_its_level_or_upsampled_from_shaded_parents() {
    let (material, lighting, bandwidths) = (phong(0), sky_lighting(), bandwidths());
    // An odd size, so that the pyramid has partial blocks at the right and bottom edges.
    let scene = sphere_scene(83, 61);
    let mut coarse_levels = 0;
    // Each allocation twice.
    let allocations = [adaptive::Allocation::Variance, adaptive::Allocation::StdDev, adaptive::Allocation::Area];
    let cases = [(Estimator::Reference, 1, 8), (Estimator::Prefiltered, 1, 2), (Estimator::Reference, 2, 4)];
    for (i, (mode, supersample, spp)) in cases.into_iter().enumerate() {
        for predict_level in [0, 1] {
            let allocation = allocations[(2 * i + predict_level) % 3];
            let settings =
                adaptive::Settings { supersample, predict_level, allocation, ..adaptive::Settings::new(mode, spp) };
            let frame = adaptive::render(&scene, material, &lighting, &bandwidths, &settings).unwrap();
            check_plan(&frame, &settings);
            let per_level = &frame.shaded_per_level;
            coarse_levels += per_level[1..].iter().filter(|&&n| n > 0).count();
            // The budget is used: rounding to powers of two loses less than half.
            assert!(2 * frame.samples > frame.budget, "{} of {}", frame.samples, frame.budget);
            println!(
                "{} ss {supersample} predict {predict_level} {}: shaded {:.3}, per level {per_level:?}",
                mode.name(),
                allocation.name(),
                frame.shaded_fraction()
            );
            assert!(frame.shaded_fraction() > 0.0 && frame.shaded_fraction() < 1.0, "{}", frame.shaded_fraction());
        }
    }
    assert!(coarse_levels >= 6, "the frames shade at coarse levels too ({coarse_levels} level-frames)");

    // With 003's lobe weight and a rescue threshold the invariants hold too, and blocks whose
    // weights sum to little are shaded rather than up-sampled.
    let settings = adaptive::Settings {
        lobe_weight: true,
        rescue_below: 0.3,
        ..adaptive::Settings::new(Estimator::Prefiltered, 4)
    };
    let frame = adaptive::render(&scene, material, &lighting, &bandwidths, &settings).unwrap();
    check_plan(&frame, &settings);
    let rescued = frame
        .details()
        .plan
        .actions
        .iter()
        .flatten()
        .filter(|a| matches!(a, Action::Shade { rescued: true, .. }))
        .count();
    assert!(rescued > 0, "no block rescued");
}

#[test]
fn a_plan_that_may_not_coarsen_is_the_full_resolution_renderer() {
    // The pyramid's top at 0 and the cap at the mean: every shadeable pixel is shaded with
    // exactly spp samples, so the frame equals render::render pixel for pixel (at the view's
    // own layer: no shift).
    let (material, lighting, bandwidths) = (phong(1), sky_lighting(), bandwidths());
    let scene = sphere_scene(40, 30);
    for mode in [Estimator::Reference, Estimator::Prefiltered] {
        let settings = adaptive::Settings {
            max_level: Some(0),
            max_spp: 8,
            seed: 3,
            layer_shift: 0,
            ..adaptive::Settings::new(mode, 8)
        };
        let frame = adaptive::render(&scene, material, &lighting, &bandwidths, &settings).unwrap();
        let full =
            render::render(&scene, material, &lighting, &Settings { estimator: mode, spp: 8, frames: 1, seed: 3 })
                .unwrap();
        assert_eq!(frame.image.covered, full.covered);
        assert_eq!(frame.image.rgb, full.rgb, "{}", mode.name());
        assert_eq!(frame.shaded_fraction(), 1.0);
    }
}

#[test]
fn a_block_of_more_samples_than_a_vector_reads_whole_vectors() {
    // Vectors of 8 samples (each of phong's slices cut into 1024 of them). A plan that may not
    // coarsen, at 32 samples per pixel and the cap at the mean, shades every pixel with four
    // whole vectors, the frames 0 to 3 of its walk: the full-resolution renderer's 4 frames of 8.
    let (phong, lighting, bandwidths) = (phong(1), sky_lighting(), bandwidths());
    let s = &phong.samples;
    let samples = render::SampleSet { n_samples: 8, n_vectors: s.n_vectors * s.n_samples / 8, ..s.clone() };
    let material = render::Material { samples, ..phong.clone() };
    let scene = sphere_scene(40, 30);
    for mode in [Estimator::Reference, Estimator::Prefiltered] {
        let settings = adaptive::Settings {
            max_level: Some(0),
            max_spp: 32,
            seed: 3,
            layer_shift: 0,
            ..adaptive::Settings::new(mode, 32)
        };
        let frame = adaptive::render(&scene, &material, &lighting, &bandwidths, &settings).unwrap();
        let full =
            render::render(&scene, &material, &lighting, &Settings { estimator: mode, spp: 8, frames: 4, seed: 3 })
                .unwrap();
        assert_eq!(frame.image.rgb, full.rgb, "{}", mode.name());
        // Not the first frame's vector four times over.
        let first =
            render::render(&scene, &material, &lighting, &Settings { estimator: mode, spp: 8, frames: 1, seed: 3 })
                .unwrap();
        assert_ne!(frame.image.rgb, first.rgb);
    }
    // A coarse plan with the default cap spends its budget: its coarse blocks take many vectors
    // (a cap of one vector, as before, left all but 8 samples a block of it unspent).
    let settings = adaptive::Settings {
        allocation: adaptive::Allocation::Area,
        ..adaptive::Settings::new(Estimator::Reference, 64)
    };
    let frame = adaptive::render(&scene, &material, &lighting, &bandwidths, &settings).unwrap();
    let counts: Vec<u32> = frame
        .details()
        .plan
        .actions
        .iter()
        .flatten()
        .filter_map(|a| match *a {
            Action::Shade { samples, .. } => Some(samples),
            _ => None,
        })
        .collect();
    let most = *counts.iter().max().unwrap();
    assert!(most > 8 && most <= settings.block_cap(&material.samples), "{most} samples");
    assert!(2 * frame.samples > frame.budget && frame.samples <= frame.budget, "{} of {}", frame.samples, frame.budget);
    assert!(frame.samples > 8 * counts.len() as u64);
}

#[test]
fn the_block_cap_is_max_spp_within_a_slice() {
    let phong = phong(1);
    let s = &phong.samples;
    let three =
        render::SampleSet { n_vectors: 3, n_samples: 8, texels: s.texels[..s.n_slices * 24].to_vec(), ..s.clone() };
    let settings = adaptive::Settings::new(Estimator::Reference, 4);
    assert_eq!(settings.max_spp, adaptive::MAX_SPP);
    // 3 vectors of 8: 24 samples a slice, 16 the largest power of two within them.
    assert_eq!(settings.block_cap(&three), 16);
    assert_eq!(adaptive::Settings { max_spp: 4, ..settings }.block_cap(&three), 4);
    assert_eq!(settings.block_cap(s), (s.n_vectors * s.n_samples) as u32);
    let (lighting, bandwidths) = (sky_lighting(), bandwidths());
    let odd = adaptive::Settings { max_spp: 24, ..settings };
    let error = adaptive::render(&sphere_scene(8, 8), phong, &lighting, &bandwidths, &odd).unwrap_err().to_string();
    assert!(error.contains("max_spp 24 must be a power of two"), "{error}");
}

#[test]
fn pre_convolved_blocks_read_the_layer_layer_shift_sharper() {
    // Three layers of the sky, each a different scale of it; every view picks layer 0. A plan
    // that may not coarsen with a layer shift is the full-resolution renderer with the views'
    // layers moved that far, to the map itself past the last layer at most.
    let (material, sky, bandwidths) = (phong(1), sky_lighting(), bandwidths());
    let scaled = |k: f32| {
        envmap::EnvMap::new(
            sky.layers[0].width(),
            sky.layers[0].height(),
            sky.layers[0].rgb().iter().map(|v| v * k).collect(),
        )
        .unwrap()
    };
    // Without peaks: their part is the same in every layer, and the smooth layers, the scaled
    // copies less the peaks' convolution, would be clamped at 0 where that exceeds them.
    let lighting = render::Lighting {
        peaks: None,
        ..render::Lighting::new(sky.mips.clone(), vec![scaled(1.0), scaled(2.0), scaled(4.0)], vec![1, 4, 16])
            .expect("a valid map")
    };
    let scene = sphere_scene(40, 30);
    let mut seen = Vec::new();
    for shift in [0, 1, 2, 3, 9] {
        let settings = adaptive::Settings {
            max_level: Some(0),
            max_spp: 8,
            seed: 3,
            layer_shift: shift,
            ..adaptive::Settings::new(Estimator::Prefiltered, 8)
        };
        let frame = adaptive::render(&scene, material, &lighting, &bandwidths, &settings).unwrap();
        let layer = shift.min(3);
        let moved =
            render::Material { view_layers: vec![layer as f32; material.view_layers.len()], ..material.clone() };
        let full = render::render(
            &scene,
            &moved,
            &lighting,
            &Settings { estimator: Estimator::Prefiltered, spp: 8, frames: 1, seed: 3 },
        )
        .unwrap();
        assert_eq!(frame.image.rgb, full.rgb, "shift {shift}");
        // The mesh's light (the background is level 0 of the mips, the same in every frame).
        let covered = frame.image.rgb.chunks_exact(3).zip(&frame.image.covered).filter(|&(_, &c)| c);
        seen.push(covered.map(|(rgb, _)| rgb.iter().map(|&v| f64::from(v)).sum::<f64>()).sum::<f64>());
    }
    // The layers differ, so the shifts do: the layers' light doubles per layer, (4 - 1) / (2 - 1)
    // = 3 with the part read elsewhere taken out, less what the samples whose footprints are
    // broader than layer 2 read of layer 1 (no footprint is broader than layer 1, which a
    // sample reads one layer sharper than its own: `render::PREFILTERED_FOOTPRINT_LAYERS`).
    // Measured: 2.987.
    let ratio = (seen[2] - seen[0]) / (seen[1] - seen[0]);
    assert!(ratio > 2.95 && ratio < 3.0 + 1e-5, "{seen:?}: (4 - 1) / (2 - 1) = {ratio}");
    assert_ne!(seen[3], seen[2], "past the last layer the map itself");
    assert_eq!(seen[3], seen[4]);
}

#[test]
fn the_exact_shader_gives_the_plans_ceiling() {
    // A reference image of scattered values (a pixel's index times a prime, modulo 1000),
    // which no interpolation reproduces: a plan that may not coarsen
    // takes it back exactly, a coarser plan equals it at its shaded blocks' pixels only and
    // up-samples between them, and a reference too small is an error naming the pixel.
    let (material, lighting, bandwidths) = (phong(1), sky_lighting(), bandwidths());
    let scene = sphere_scene(80, 60);
    let settings = Settings { estimator: Estimator::Reference, spp: 1, frames: 1, seed: 0 };
    let full = render::render(&scene, material, &lighting, &settings).unwrap();
    let reference = render::Image { rgb: (0..full.rgb.len()).map(|i| (i / 3 * 7919 % 1000) as f32).collect(), ..full };
    let render_exact = |settings: &adaptive::Settings, reference: &render::Image| {
        let mut exact = adaptive::exact_shader(reference);
        adaptive::render_with(
            &adaptive::Geometry::of_scene(&scene, settings.supersample)?,
            material,
            &lighting,
            &bandwidths,
            settings,
            adaptive::Hooks { shader: Some(&mut exact), ..Default::default() },
        )
    };
    let fine =
        adaptive::Settings { max_level: Some(0), max_spp: 8, ..adaptive::Settings::new(Estimator::Reference, 8) };
    let frame = render_exact(&fine, &reference).unwrap();
    for i in (0..80 * 60).filter(|&i| frame.details().predictions[i].level >= 0) {
        assert_eq!(frame.image.rgb[3 * i], reference.rgb[3 * i], "pixel {i}");
    }
    let coarse = adaptive::Settings::new(Estimator::Reference, 8);
    let frame = render_exact(&coarse, &reference).unwrap();
    let is_exact = |i: usize| frame.image.rgb[3 * i] == reference.rgb[3 * i];
    let from =
        |level: fn(i32) -> bool| (0..80 * 60).filter(|&i| level(frame.details().shaded_level[i])).collect::<Vec<_>>();
    let (own, upsampled) = (from(|l| l == 0), from(|l| l > 0));
    assert!(own.iter().all(|&i| is_exact(i)), "pixels shaded on their own take their reference value");
    assert!(!upsampled.is_empty(), "the plan shades coarse blocks");
    assert!(upsampled.iter().filter(|&&i| is_exact(i)).count() < upsampled.len() / 2, "up-sampled pixels interpolate");
    let small = render::Image { width: 4, height: 4, rgb: vec![0.0; 48], covered: vec![true; 16] };
    let error = render_exact(&fine, &small).unwrap_err().to_string();
    assert!(error.contains("outside the reference image of 4 x 4"), "{error}");
}

#[test]
fn a_prediction_level_above_the_pyramid_is_its_top() {
    // 40 x 30 has a pyramid of 5 levels (top 4, blocks of 16 x 16): predict levels above it
    // mean the top, and shifts beyond the word size do not wrap. The sphere leaves most of the
    // blocks' own pixels uncovered.
    let (material, lighting, bandwidths) = (phong(1), sky_lighting(), bandwidths());
    let scene = sphere_scene(40, 30);
    let frame = |predict_level: usize| {
        let settings = adaptive::Settings { predict_level, ..adaptive::Settings::new(Estimator::Reference, 4) };
        adaptive::render(&scene, material, &lighting, &bandwidths, &settings).unwrap()
    };
    let top = frame(4);
    // Every shadeable pixel has a prediction, and the blocks that hold pixels off the sphere
    // share theirs by quarters rather than predicting every pixel: as many predictions as the
    // recursion has sources, 150 for 444 pixels (3 x 2 blocks of 16 x 16, all split; the
    // sphere is small, and its two outer rings predict pixel by pixel).
    let shadeable: Vec<&Prediction> = top.details().predictions.iter().filter(|p| p.level >= 0).collect();
    let mut distinct: Vec<(u64, u64)> =
        shadeable.iter().map(|p| (p.bandwidth.to_bits(), p.variance.to_bits())).collect();
    distinct.sort_unstable();
    distinct.dedup();
    assert_eq!(shadeable.len(), top.shadeable);
    let covered: Vec<bool> = top.details().predictions.iter().map(|p| p.level >= 0).collect();
    let mut sources: Vec<usize> = sources_by_recursion(&covered, (40, 30), 4).into_iter().flatten().collect();
    sources.sort_unstable();
    sources.dedup();
    assert!(sources.len() < shadeable.len() / 2, "{} sources for {} pixels", sources.len(), shadeable.len());
    assert_eq!(distinct.len(), sources.len(), "{} predictions for {} pixels", distinct.len(), shadeable.len());
    for predict_level in [5, 40, 64, usize::MAX] {
        let f = frame(predict_level);
        assert_eq!(f.details().predictions, top.details().predictions, "predict level {predict_level}");
        assert_eq!(f.image.rgb, top.image.rgb, "predict level {predict_level}");
    }
}

#[test]
fn a_budget_below_one_sample_per_shaded_pixel_is_refused() {
    let (material, lighting, bandwidths) = (phong(0), sky_lighting(), bandwidths());
    let settings =
        adaptive::Settings { max_level: Some(0), supersample: 4, ..adaptive::Settings::new(Estimator::Reference, 1) };
    let error = adaptive::render(&sphere_scene(16, 16), material, &lighting, &bandwidths, &settings).unwrap_err();
    assert!(error.to_string().contains("raise spp"), "{error}");
}

/// A bad setting is reported as such before the scene is rasterized: here the scene (0 x 0) would
/// be refused too, with another message.
#[test]
fn the_settings_are_checked_before_the_scene() {
    let (material, lighting, bandwidths) = (phong(0), sky_lighting(), bandwidths());
    let settings = adaptive::Settings { supersample: 3, ..adaptive::Settings::new(Estimator::Reference, 1) };
    let error = adaptive::render(&sphere_scene(0, 0), material, &lighting, &bandwidths, &settings).unwrap_err();
    assert!(error.to_string().contains("supersample (3) 1, 2 or 4"), "{error}");
}

/// The recursion the module docs describe, written out: block `(bx, by)` of level `k` predicts
/// at its pixel when all its pixels are inner (shadeable, and so are their neighbours in the
/// image), or at level 0, else splits into its quarters.
fn sources_by_recursion(shadeable: &[bool], (w, h): (usize, usize), l: usize) -> Vec<Option<usize>> {
    fn visit(k: usize, (bx, by): (usize, usize), s: &[bool], (w, h): (usize, usize), out: &mut [Option<usize>]) {
        let (x0, y0) = (bx << k, by << k);
        if x0 >= w || y0 >= h {
            return;
        }
        let half = (1 << k) / 2;
        let (x, y) = ((x0 + half).min(w - 1), (y0 + half).min(h - 1));
        let inner = |x: usize, y: usize| {
            let neighbours = [(x.wrapping_sub(1), y), (x + 1, y), (x, y.wrapping_sub(1)), (x, y + 1)];
            s[y * w + x] && neighbours.iter().all(|&(nx, ny)| nx >= w || ny >= h || s[ny * w + nx])
        };
        let whole = (y0..(y0 + (1 << k)).min(h)).all(|py| (x0..(x0 + (1 << k)).min(w)).all(|px| inner(px, py)));
        if k > 0 && !whole {
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                visit(k - 1, (2 * bx + dx, 2 * by + dy), s, (w, h), out);
            }
            return;
        }
        for py in y0..(y0 + (1 << k)).min(h) {
            for px in x0..(x0 + (1 << k)).min(w) {
                if s[py * w + px] {
                    out[py * w + px] = Some(y * w + x);
                }
            }
        }
    }
    let mut out = vec![None; w * h];
    for by in 0..h.div_ceil(1 << l) {
        for bx in 0..w.div_ceil(1 << l) {
            visit(l, (bx, by), shadeable, (w, h), &mut out);
        }
    }
    out
}

#[test]
fn prediction_pixels_follow_the_block_recursion() {
    // A ragged mask (holes, a partial last block row and column) at every level up to above the
    // image: each shadeable pixel takes the prediction of the pixel the recursion gives it, that
    // pixel takes its own, and the list is row-major without repeats.
    let (w, h) = (13, 10);
    let shadeable: Vec<bool> = (0..w * h).map(|i| (i * 7919 + i / w * 31) % 5 != 0 && i % w != 6).collect();
    for l in 0..5 {
        let (pixels, of_pixel) = adaptive::prediction_pixels(&shadeable, (w, h), l);
        let expected = sources_by_recursion(&shadeable, (w, h), l);
        assert!(pixels.windows(2).all(|p| p[0] < p[1]), "level {l}: {pixels:?}");
        for i in 0..w * h {
            let got = (of_pixel[i] != u32::MAX).then(|| pixels[of_pixel[i] as usize] as usize);
            assert_eq!(got, expected[i], "level {l}, pixel {i}");
        }
        for (j, &p) in pixels.iter().enumerate() {
            assert_eq!(of_pixel[p as usize], j as u32, "level {l}: pixel {p} predicts for itself");
        }
    }
}

#[test]
fn a_predictor_replaces_the_prediction_and_is_checked() {
    // The frame's own predictions replayed make the same frame; a predictor that answers for the
    // wrong pixels or with values that are no bandwidth is an error naming what is wrong.
    let (material, lighting, bandwidths) = (phong(1), sky_lighting(), bandwidths());
    let scene = sphere_scene(40, 30);
    let settings = adaptive::Settings { predict_level: 1, ..adaptive::Settings::new(Estimator::Reference, 4) };
    let frame = adaptive::render(&scene, material, &lighting, &bandwidths, &settings).unwrap();
    let with = |predictor: adaptive::Predictor| {
        let hooks = adaptive::Hooks { predictor: Some(predictor), ..Default::default() };
        let geometry = adaptive::Geometry::of_scene(&scene, settings.supersample)?;
        adaptive::render_with(&geometry, material, &lighting, &bandwidths, &settings, hooks)
    };
    let replayed = with(&mut adaptive::replay_predictor(&frame.details().predictions)).unwrap();
    assert_eq!(replayed.details().predictions, frame.details().predictions);
    assert_eq!(replayed.details().plan.actions, frame.details().plan.actions);
    assert_eq!(replayed.image.rgb, frame.image.rgb);
    let short = with(&mut |pixels: &[u32]| Ok(vec![[0.1, 1.0]; pixels.len() - 1])).unwrap_err().to_string();
    assert!(short.contains("predictions for"), "{short}");
    let nan = with(&mut |pixels: &[u32]| Ok(vec![[f64::NAN, 1.0]; pixels.len()])).unwrap_err().to_string();
    assert!(nan.contains("render pixel") && nan.contains("NaN"), "{nan}");
    let none = vec![adaptive::Prediction { level: -1, ..Default::default() }; frame.details().predictions.len()];
    let missing = with(&mut adaptive::replay_predictor(&none)).unwrap_err().to_string();
    assert!(missing.contains("no prediction to replay"), "{missing}");
}

/// Grading bounds each shadeable pixel's level by the finest within `GRADE_RADIUS` plus
/// `GRADE_SLACK`, and leaves the pixels that are not shadeable alone: against a direct minimum
/// over each pixel's square, on random levels with holes, and on one fine pixel in a coarse field.
#[test]
fn grading_bounds_a_level_by_its_neighbourhood() {
    let (w, h) = (37, 23);
    let mut rng = StdRng::seed_from_u64(7);
    let levels: Vec<i32> = (0..w * h).map(|_| if rng.random_bool(0.1) { -1 } else { rng.random_range(0..6) }).collect();
    let predictions = |levels: &[i32]| -> Vec<Prediction> {
        levels.iter().map(|&level| Prediction { level, ..Default::default() }).collect()
    };
    let mut graded = predictions(&levels);
    adaptive::grade_levels(&mut graded, w, h);
    let r = adaptive::GRADE_RADIUS as i64;
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let own = levels[(y * w as i64 + x) as usize];
            let least = (-r..=r)
                .flat_map(|dy| (-r..=r).map(move |dx| (x + dx, y + dy)))
                .filter(|&(qx, qy)| qx >= 0 && qy >= 0 && qx < w as i64 && qy < h as i64)
                .map(|(qx, qy)| levels[(qy * w as i64 + qx) as usize])
                .filter(|&l| l >= 0)
                .min();
            let want = match least {
                _ if own < 0 => -1,
                Some(least) => own.min(least + adaptive::GRADE_SLACK),
                None => own,
            };
            assert_eq!(graded[(y * w as i64 + x) as usize].level, want, "pixel ({x}, {y})");
        }
    }
    // One fine pixel among coarse ones: its square takes the slack's level, the rest keep theirs.
    let mut field = vec![5; w * h];
    field[11 * w + 17] = 0;
    let mut graded = predictions(&field);
    adaptive::grade_levels(&mut graded, w, h);
    let refined = graded.iter().filter(|p| p.level == adaptive::GRADE_SLACK).count();
    let side = 2 * adaptive::GRADE_RADIUS + 1;
    assert_eq!(refined, side * side - 1);
    assert_eq!(graded.iter().filter(|p| p.level == 5).count(), w * h - side * side);
}
