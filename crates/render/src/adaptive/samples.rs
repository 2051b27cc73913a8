//! A frame's samples shared among its shaded blocks (module docs, "Samples").

use crate::error::Error;

use super::*;

/// Splits `budget` among blocks of the given variances: each at least 1 and at most `cap`, the
/// rest in proportion to the variance, what a capped block cannot take going to the others
/// (water filling). The shares sum to `min(budget, cap * n)`.
pub(super) fn shares(variance: &[f64], budget: f64, cap: f64) -> Vec<f64> {
    let mut share = vec![1.0; variance.len()];
    let mut open: Vec<usize> = (0..variance.len()).collect();
    let mut spare = budget - variance.len() as f64;
    while spare > 0.0 && !open.is_empty() {
        let total: f64 = open.iter().map(|&i| variance[i]).sum();
        let portion = |i: usize| if total > 0.0 { spare * variance[i] / total } else { spare / open.len() as f64 };
        let full: Vec<usize> = open.iter().copied().filter(|&i| share[i] + portion(i) >= cap).collect();
        if full.is_empty() {
            for &i in &open {
                share[i] += portion(i);
            }
            break;
        }
        for &i in &full {
            spare -= cap - share[i];
            share[i] = cap;
        }
        open.retain(|&i| share[i] < cap);
    }
    share
}

/// Gives every shaded block its samples (module docs, "Samples").
pub(super) fn allocate(
    levels: &[Level],
    actions: &mut [Vec<Action>],
    budget: u64,
    settings: &Settings,
) -> Result<(), Error> {
    // (level, block, variance)
    let shaded: Vec<(usize, usize, f64)> = actions
        .iter()
        .enumerate()
        .flat_map(|(k, row)| {
            row.iter()
                .enumerate()
                .filter(|(_, a)| matches!(a, Action::Shade { .. }))
                .map(move |(b, _)| (k, b, levels[k].max_variance[b]))
        })
        .collect();
    let blocks: Vec<(usize, f64)> = shaded.iter().map(|&(k, _, variance)| (k, variance)).collect();
    let samples = allocation(&blocks, budget, settings)?;
    for ((k, b, _), n) in shaded.into_iter().zip(samples) {
        if let Action::Shade { samples, .. } = &mut actions[k][b] {
            *samples = n;
        }
    }
    Ok(())
}

/// The samples of each shaded block (module docs, "Samples"), given as `(level, max variance)`
/// in the plan's order: by level, finest first, then by block index. `budget` samples in all.
/// A renderer that plans elsewhere (`gpu::preview`) allocates with this, or with
/// [`area_allocation`], so that its blocks get exactly the samples the CPU's plan gives them.
pub fn allocation(blocks: &[(usize, f64)], budget: u64, settings: &Settings) -> Result<Vec<u32>, Error> {
    let max_spp = settings.max_spp;
    if settings.allocation == Allocation::Area {
        let top = blocks.iter().map(|&(k, _)| k).max().unwrap_or(0);
        let mut counts = vec![0u64; top + 1];
        for &(k, _) in blocks {
            counts[k] += 1;
        }
        let per_level = area_allocation(&counts, budget, max_spp)?;
        // Each block's rank in its level, in the plan's order.
        let mut rank = vec![0u64; top + 1];
        return Ok(blocks
            .iter()
            .map(|&(k, _)| {
                let LevelSamples { samples, doubled } = per_level[k];
                rank[k] += 1;
                if rank[k] <= doubled { 2 * samples } else { samples }
            })
            .collect());
    }
    check_budget(blocks.len() as u64, budget)?;
    let weights: Vec<f64> = blocks
        .iter()
        .map(|&(k, variance)| match settings.allocation {
            Allocation::Variance => variance,
            Allocation::StdDev => ((1u64 << (2 * k)) as f64 * variance).sqrt(),
            Allocation::Area => unreachable!("allocated per level above"),
        })
        .collect();
    Ok(weighted_allocation(&weights, budget, max_spp))
}

/// A frame's budget must give every shaded block a sample.
pub fn check_budget(shaded: u64, budget: u64) -> Result<(), Error> {
    if shaded > budget {
        return Err(Error::Invalid(format!(
            "a budget of {budget} samples is less than one for each of the {shaded} shaded pixels: raise spp"
        )));
    }
    Ok(())
}

/// The samples of blocks of the given weights (module docs, "Samples"): the water-filled
/// shares, each rounded down to a power of two, then the rest handed out by doubling the blocks
/// furthest below their share, in order, while it fits.
pub(super) fn weighted_allocation(weights: &[f64], budget: u64, max_spp: u32) -> Vec<u32> {
    let ideal = shares(weights, budget as f64, f64::from(max_spp));
    let floor_pow2 = |x: f64| -> u32 {
        let x = x.min(f64::from(max_spp)).max(1.0);
        1u32 << (x.log2().floor() as u32)
    };
    let mut samples: Vec<u32> = ideal.iter().map(|&x| floor_pow2(x)).collect();
    let mut left = budget - samples.iter().map(|&n| u64::from(n)).sum::<u64>();
    let mut order: Vec<usize> = (0..weights.len()).collect();
    order.sort_by(|&a, &b| {
        (ideal[b] / f64::from(samples[b])).total_cmp(&(ideal[a] / f64::from(samples[a]))).then(a.cmp(&b))
    });
    for i in order {
        if samples[i] < max_spp && u64::from(samples[i]) <= left {
            left -= u64::from(samples[i]);
            samples[i] *= 2;
        }
    }
    samples
}

/// The samples of one level's shaded blocks under [`Allocation::Area`]: the first `doubled`
/// blocks of the level, in the plan's order, get `2 samples`, the others `samples`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LevelSamples {
    pub samples: u32,
    pub doubled: u64,
}

/// [`Allocation::Area`]'s samples from the count of shaded blocks per level alone (level 0
/// first), in exact integer arithmetic: every block of a level has the same weight `2^k`, so the
/// same share, the same power of two below it, and the blocks that double are the first of
/// their level that fit (module docs, "Samples"). The water filling: a level is full when
/// `1 + spare 2^k / W >= max_spp` (`W` the open levels' `sum n_k 2^k`), that is when
/// `spare 2^k >= (max_spp - 1) W`; full levels take `max_spp` and leave the rest to the others
/// until none is full; a level's samples are then the largest power of two `2^m <= max_spp`
/// with `2^m W <= W + spare 2^k`, and the levels below their share double, furthest below
/// first (the least level first among equals), while their samples fit what is left.
/// `gpu::preview` computes the same in `preview_adaptive.wgsl`'s `adaptive_allocate`, with
/// 64-bit sums of shifts for the products (every factor but the counts a power of two).
/// `max_spp` is a power of two ([`check_settings`]).
pub fn area_allocation(counts: &[u64], budget: u64, max_spp: u32) -> Result<Vec<LevelSamples>, Error> {
    debug_assert!(max_spp.is_power_of_two());
    check_budget(counts.iter().sum(), budget)?;
    let cap = u128::from(max_spp);
    let weight = |k: usize| u128::from(counts[k]) << k;
    let mut capped = vec![false; counts.len()];
    let open = |capped: &[bool]| -> Vec<usize> { (0..counts.len()).filter(|&k| counts[k] > 0 && !capped[k]).collect() };
    let mut spare = u128::from(budget - counts.iter().sum::<u64>());
    // The last round's spare and W, where it shared among open levels.
    let mut shared = None;
    loop {
        let open = open(&capped);
        let total: u128 = open.iter().map(|&k| weight(k)).sum();
        if spare == 0 || total == 0 {
            break;
        }
        let full: Vec<usize> = open.into_iter().filter(|&k| spare << k >= (cap - 1) * total).collect();
        if full.is_empty() {
            shared = Some((spare, total));
            break;
        }
        for k in full {
            spare -= u128::from(counts[k]) * (cap - 1);
            capped[k] = true;
        }
    }
    // Each level's ideal share as a fraction, and its power of two.
    let ideal = |k: usize| -> (u128, u128) {
        match shared {
            _ if capped[k] => (cap, 1),
            Some((spare, total)) => (total + (spare << k), total),
            None => (1, 1),
        }
    };
    let mut levels: Vec<LevelSamples> = (0..counts.len())
        .map(|k| {
            let (num, den) = ideal(k);
            let mut samples = 1u128;
            while 2 * samples <= cap && 2 * samples * den <= num {
                samples *= 2;
            }
            LevelSamples { samples: samples as u32, doubled: 0 }
        })
        .collect();
    let mut left = budget - (0..counts.len()).map(|k| counts[k] * u64::from(levels[k].samples)).sum::<u64>();
    // Furthest below the share first: ideal / samples descending, the lesser level first.
    let mut order: Vec<usize> = (0..counts.len()).filter(|&k| counts[k] > 0).collect();
    let below = |k: usize| {
        let (num, den) = ideal(k);
        (num, den * u128::from(levels[k].samples))
    };
    order.sort_by(|&a, &b| {
        let ((na, da), (nb, db)) = (below(a), below(b));
        (nb * da).cmp(&(na * db)).then(a.cmp(&b))
    });
    for k in order {
        let samples = u64::from(levels[k].samples);
        if levels[k].samples < max_spp {
            let doubled = counts[k].min(left / samples);
            left -= doubled * samples;
            levels[k].doubled = doubled;
        }
    }
    Ok(levels)
}
