//! Unit tests of the adaptive renderer's stages.

use super::{
    Action, Allocation, Level, LevelSamples, Pixel, Settings, allocate, allocation, area_allocation, lobe_similarity,
    pixels, shares, upsample_weights, weighted_allocation,
};
use crate::Estimator;
use crate::shade::visibility;
use crate::{Camera, Mesh, Scene};
use glam::DVec3;

#[test]
fn the_curvature_of_a_sphere_is_one_over_its_radius() {
    // Interpolated vertex normals of a finely tessellated sphere: the median over the
    // pixels is within 2% of 1 / R (the tessellation's flat spans and the one-sided
    // differences at the silhouette are the rest).
    for radius in [1.0f32, 0.5] {
        let scene = Scene { mesh: Mesh::sphere(radius, 256, 128), camera: Camera::default(), width: 96, height: 96 };
        let gbuffer = visibility(&scene).unwrap();
        let mut curvature: Vec<f64> = pixels(&scene.camera, &gbuffer).iter().flatten().map(|p| p.curvature).collect();
        curvature.sort_by(f64::total_cmp);
        let median = curvature[curvature.len() / 2];
        let expect = 1.0 / f64::from(radius);
        assert!((median / expect - 1.0).abs() < 0.02, "radius {radius}: median curvature {median}");
    }
}

#[test]
fn the_lobe_similarity_is_a_normalized_inner_product() {
    let z = DVec3::Z;
    for lambda in [0.0, 0.5, 4.0, 100.0, 4096.0] {
        assert!((lobe_similarity(z, lambda, z, lambda) - 1.0).abs() < 1e-9, "lambda {lambda}");
    }
    let tilted = DVec3::new(0.2f64.sin(), 0.0, 0.2f64.cos());
    let mut previous = 1.0;
    for lambda in [1.0, 10.0, 100.0, 1000.0] {
        let w = lobe_similarity(z, lambda, tilted, lambda);
        assert!(w > 0.0 && w < previous, "lambda {lambda}: {w} (sharper lobes 0.2 rad apart are less alike)");
        // Symmetric, and at most 1 (Cauchy-Schwarz) for different sharpness too.
        assert!((w - lobe_similarity(tilted, lambda, z, lambda)).abs() < 1e-12);
        assert!(lobe_similarity(z, lambda, tilted, 3.0 * lambda) <= 1.0);
        previous = w;
    }
    // Equal sharp lobes at an angle a: d = 2 lambda cos(a / 2) and sinh(d) ~ exp(d) / 2, so
    // the weight is exp(2 lambda (cos(a / 2) - 1)) / cos(a / 2) (~ exp(-lambda a^2 / 4)).
    let (lambda, a) = (1000.0f64, 0.2f64);
    let expect = (2.0 * lambda * ((a / 2.0).cos() - 1.0)).exp() / (a / 2.0).cos();
    let w = lobe_similarity(z, lambda, tilted, lambda);
    assert!((w / expect - 1.0).abs() < 1e-9, "{w} vs {expect}");
}

#[test]
fn a_coarse_block_gets_samples_for_the_pixels_it_stands_for() {
    // One shaded block at level 0 and one at level 2 (16 pixels), the same variance; 10
    // samples. Variance: equal ideal shares, 5 and 5, rounded to 4 and 4. StdDev and Area:
    // weights 1 and sqrt(16) = 4, ideal shares 1 + 8 / 5 = 2.6 and 1 + 32 / 5 = 7.4, rounded
    // to 2 and 4, and the 4 left double the block furthest below its share (7.4 / 4): 2 and 8.
    let level = |k: usize, variance: f64| Level {
        level: k,
        width: 1,
        height: 1,
        min_level: vec![k as i32],
        max_variance: vec![variance],
    };
    for (allocation, variance_2, expect) in [
        (Allocation::Variance, 3.0, [4, 4]),
        (Allocation::StdDev, 3.0, [2, 8]),
        (Allocation::Area, 3.0, [2, 8]),
        // StdDev follows the variance too; Area does not: sqrt(16 * 3 / 48) = 1.
        (Allocation::StdDev, 3.0 / 16.0, [4, 4]),
        (Allocation::Area, 3.0 / 16.0, [2, 8]),
    ] {
        let levels = [level(0, 3.0), level(1, 0.0), level(2, variance_2)];
        let shade = Action::Shade { samples: 0, rescued: false };
        let mut actions = vec![vec![shade], vec![Action::Skip], vec![shade]];
        let settings = Settings { allocation, ..Settings::new(Estimator::Reference, 1) };
        allocate(&levels, &mut actions, 10, &settings).unwrap();
        let got = [0, 2].map(|k| match actions[k][0] {
            Action::Shade { samples, .. } => samples,
            _ => unreachable!(),
        });
        assert_eq!(got, expect, "{} with variances 3 and {variance_2}", allocation.name());
    }
}

#[test]
fn the_area_allocation_per_level_is_the_water_filling_of_every_block() {
    // Independent reference: `weighted_allocation` over every block with the weight 2^k, in
    // f64, against `allocation`'s Area path (per level, in integers); random levels, counts,
    // budgets (at most 300 samples per block) and caps, with empty levels and budgets at
    // exactly one sample per block among them.
    let mut state = 7u32;
    let mut next = |n: u32| {
        state = crate::pcg_hash(state);
        state % n
    };
    let (mut doubled, mut capped) = (0, 0);
    for case in 0..2000 {
        let levels = 1 + next(7) as usize;
        let counts: Vec<u64> = (0..levels).map(|_| u64::from(next(4).min(1) * next(40))).collect();
        let n: u64 = counts.iter().sum();
        if n == 0 {
            continue;
        }
        let budget = if case % 10 == 0 { n } else { n + u64::from(next(300)) * n / u64::from(1 + next(8)) };
        let max_spp = 1 << next(9);
        let blocks: Vec<(usize, f64)> =
            counts.iter().enumerate().flat_map(|(k, &c)| (0..c).map(move |_| (k, 0.0))).collect();
        let weights: Vec<f64> = blocks.iter().map(|&(k, _)| (1u64 << k) as f64).collect();
        let expect = weighted_allocation(&weights, budget, max_spp);
        let settings = Settings { allocation: Allocation::Area, max_spp, ..Settings::new(Estimator::Reference, 1) };
        let got = allocation(&blocks, budget, &settings).unwrap();
        assert_eq!(got, expect, "counts {counts:?}, budget {budget}, max_spp {max_spp}");
        assert!(got.iter().map(|&s| u64::from(s)).sum::<u64>() <= budget);
        let per_level = area_allocation(&counts, budget, max_spp).unwrap();
        doubled += usize::from(per_level.iter().any(|l| l.doubled > 0));
        capped += usize::from(per_level.iter().any(|l| l.samples == max_spp && max_spp > 1));
    }
    // The cases reach both the doubling and the cap.
    assert!(doubled > 500 && capped > 100, "{doubled} cases doubled, {capped} capped");
    // Levels 0 and 2 tie (ideal over samples 3 / 2: shares 1.5, 2, 3 of 13 samples, W = 14,
    // spare 7): the lesser level doubles first, both its blocks, and the 1 sample left
    // doubles neither of level 2's (taking level 2 first would double one of each).
    let tie = area_allocation(&[2, 2, 2], 13, 8).unwrap();
    let expect = [(1, 2), (2, 0), (2, 0)].map(|(samples, doubled)| LevelSamples { samples, doubled });
    assert_eq!(tie, expect);
    let weights = [1.0, 1.0, 2.0, 2.0, 4.0, 4.0];
    assert_eq!(weighted_allocation(&weights, 13, 8), [2, 2, 2, 2, 2, 2]);
    // A budget below a sample per block is the same error either way.
    let error = area_allocation(&[3, 1], 3, 4).unwrap_err().to_string();
    assert!(error.contains("less than one for each of the 4 shaded"), "{error}");
}

#[test]
fn a_parent_weighted_below_the_least_weight_does_not_count() {
    // A 2 x 1 child level under a 1 x 1 parent: the child block (0, 0) up-samples from the
    // one parent with g_z = exp(-dz^2 / 2), dz = depth difference / (sigma depth). At a
    // difference of 0.25 (dz 12.5: g_z about 1e-34, below 2^-100 though f64 holds it) the
    // parent does not count and the block is rescued; at 0.2 (dz 10: g_z about 2e-22) it
    // counts, with weight 1.
    let pixel = |depth: f64| Pixel { cos_o: 1.0, depth, curvature: 0.0, screen_normal: [0.0; 2], mirror: DVec3::Z };
    let level = |k: usize, width: usize| Level {
        level: k,
        width,
        height: 1,
        min_level: vec![1; width],
        max_variance: vec![0.0; width],
    };
    let (child, parent) = (level(0, 2), level(1, 1));
    let settings = Settings::new(Estimator::Reference, 1);
    for (difference, counts) in [(0.25, false), (0.2, true)] {
        // The child block's pixel is (0, 0); the parent's is (1, 0).
        let pixels = [Some(pixel(1.0)), Some(pixel(1.0 + difference))];
        let weights = upsample_weights(&child, &parent, (0, 0), &pixels, (2, 1), &settings, None);
        assert_eq!(weights.is_some(), counts, "depth difference {difference}");
        if let Some((parents, count)) = weights {
            assert_eq!((count, parents[0]), (1, (0, 1.0)));
        }
    }
}

#[test]
fn water_filling_respects_the_budget_the_cap_and_the_proportions() {
    let weights = [0.0, 1.0, 2.0, 4.0, 100.0, 0.5];
    for (budget, cap) in [(6.0, 256.0), (50.0, 256.0), (50.0, 16.0), (1000.0, 16.0), (10_000.0, 1e9)] {
        let s = shares(&weights, budget, cap);
        let total: f64 = s.iter().sum();
        assert!((total - f64::min(budget, cap * weights.len() as f64)).abs() < 1e-9, "{budget} {cap}: {s:?}");
        assert!(s.iter().all(|&x| (1.0..=cap + 1e-9).contains(&x)), "{budget} {cap}: {s:?}");
        // Below the cap, every share is 1 plus the same multiple of its weight.
        let open: Vec<usize> = (0..weights.len()).filter(|&i| s[i] < cap - 1e-9 && weights[i] > 0.0).collect();
        for pair in open.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            let (ra, rb) = ((s[a] - 1.0) / weights[a], (s[b] - 1.0) / weights[b]);
            assert!((ra - rb).abs() <= 1e-9 * ra.max(rb), "{budget} {cap}: {s:?}");
        }
    }
    // No variance anywhere: equal shares.
    assert_eq!(shares(&[0.0; 4], 40.0, 256.0), vec![10.0; 4]);
}
