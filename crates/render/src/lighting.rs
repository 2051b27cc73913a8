//! The lighting the estimators read: a bake's mip chain and Phong layers, level 0's importance
//! sampling, and the split of the environment into a smooth part and its peaks that the
//! filtered estimators need (crate documentation, "Small bright sources").

use envmap::{EnvMap, MipChain};
use sampling::LatLong;

use crate::error::Error;

/// A distant environment with what a bake made of it, and what the estimators derive from it
/// once ([`Lighting::new`]).
#[derive(Clone, Debug)]
pub struct Lighting {
    /// The environment's mip chain; level 0 is the map itself.
    pub mips: MipChain,
    /// The map convolved with normalized Phong lobes, one layer per exponent, all the same size.
    pub layers: Vec<EnvMap>,
    /// The exponent of each layer.
    pub exponents: Vec<u32>,
    /// Level 0's importance sampling: texels weighted by [`EnvMap::bilinear_luminance`] (so the
    /// density is positive wherever the bilinear lookup is) times `sin theta`.
    pub environment: LatLong,
    /// The environment's peaks and the smooth rest, for [`crate::Estimator::Fis`] and
    /// [`crate::Estimator::Prefiltered`]; `None` where no texel stands out.
    pub peaks: Option<Peaks>,
}

/// A texel of level 0 whose luminance exceeds this multiple of the map's mean luminance (by solid
/// angle) belongs to the peaks (crate documentation, "Small bright sources").
pub const PEAK_CONTRAST: f64 = 1.0;

/// The split `L = L_smooth + L_peak` of level 0: a texel of luminance `Y` above the threshold
/// `T` gives `L (1 - T / Y)` to the peaks and keeps `L T / Y`, so the smooth part's luminance is
/// `min(Y, T)`. Filtering is linear, so the smooth part's mip chain and layers are the bake's
/// minus the peaks' own (made here with the code that made the bake's: `envmap::MipChain::new`
/// and `prefilter::prefilter`), clamped at 0 where the bake's half floats round below them.
#[derive(Clone, Debug)]
pub struct Peaks {
    /// `T`, in the map's units of luminance.
    pub threshold: f64,
    /// `L_peak` at level 0's size.
    pub map: EnvMap,
    /// `L_peak`'s importance sampling, as [`Lighting::environment`] is level 0's.
    pub sampling: LatLong,
    /// The mip chain of `L_smooth`: the bake's, minus the peaks'.
    pub smooth_mips: MipChain,
    /// The Phong layers of `L_smooth`: the bake's, minus the peaks'.
    pub smooth_layers: Vec<EnvMap>,
}

impl Lighting {
    /// The lighting of a mip chain and its Phong layers (of `exponents`), with level 0's
    /// importance sampling and the split into peaks and the smooth rest, built here, once per
    /// map, rather than baked (a quarter of a second for a 1024 x 512 map with a sun).
    pub fn new(mips: MipChain, layers: Vec<EnvMap>, exponents: Vec<u32>) -> Result<Lighting, Error> {
        let level0 = mips.level(0);
        let environment = LatLong::new(&level0.bilinear_luminance(), level0.width(), level0.height())
            .map_err(|e| Error::Invalid(format!("the environment's importance sampling: {e}")))?;
        let peaks = Peaks::new(&mips, &layers, &exponents)?;
        Ok(Lighting { mips, layers, exponents, environment, peaks })
    }

    /// The mip chain the filtered estimators read: the smooth part's where there are peaks.
    pub fn smooth_mips(&self) -> &MipChain {
        self.peaks.as_ref().map_or(&self.mips, |p| &p.smooth_mips)
    }

    /// The Phong layers the filtered estimators read: the smooth part's where there are peaks.
    pub fn smooth_layers(&self) -> &[EnvMap] {
        self.peaks.as_ref().map_or(&self.layers, |p| &p.smooth_layers)
    }
}

impl Peaks {
    fn new(mips: &MipChain, layers: &[EnvMap], exponents: &[u32]) -> Result<Option<Peaks>, Error> {
        let level0 = mips.level(0);
        let threshold = PEAK_CONTRAST * level0.mean_luminance();
        let luminance = level0.luminance();
        if luminance.iter().all(|&y| f64::from(y) <= threshold) {
            return Ok(None);
        }
        let peak_rgb: Vec<f32> = level0
            .texels()
            .iter()
            .zip(&luminance)
            .flat_map(|(rgb, &y)| {
                let share = if f64::from(y) > threshold { (1.0 - threshold / f64::from(y)) as f32 } else { 0.0 };
                rgb.map(|c| c * share)
            })
            .collect();
        let invalid = |e: String| Error::Invalid(format!("the environment's peaks: {e}"));
        let map = EnvMap::new(level0.width(), level0.height(), peak_rgb).map_err(|e| invalid(e.to_string()))?;
        let sampling =
            LatLong::new(&map.bilinear_luminance(), map.width(), map.height()).map_err(|e| invalid(e.to_string()))?;
        let peak_mips = MipChain::new(&map);
        let smooth_levels: Vec<EnvMap> = mips
            .levels()
            .iter()
            .zip(peak_mips.levels())
            .map(|(baked, peak)| difference(baked, peak))
            .collect::<Result<_, _>>()?;
        let smooth_mips = MipChain::from_levels(smooth_levels).map_err(|e| invalid(e.to_string()))?;
        let smooth_layers = match layers.first() {
            None => Vec::new(),
            Some(first) => {
                let config = prefilter::Config {
                    exponents: exponents.to_vec(),
                    width: first.width(),
                    height: first.height(),
                    ..prefilter::Config::default()
                };
                let peak_layers = prefilter::prefilter(&map, &config).map_err(|e| invalid(e.to_string()))?.layers;
                layers
                    .iter()
                    .zip(&peak_layers)
                    .map(|(baked, peak)| difference(baked, &peak.map))
                    .collect::<Result<_, _>>()?
            }
        };
        Ok(Some(Peaks { threshold, map, sampling, smooth_mips, smooth_layers }))
    }
}

/// `a - b`, texel by texel, clamped at 0; the two must be the same size.
fn difference(a: &EnvMap, b: &EnvMap) -> Result<EnvMap, Error> {
    if (a.width(), a.height()) != (b.width(), b.height()) {
        return Err(Error::Invalid(format!(
            "the peaks' map of {} x {} does not match the bake's of {} x {}",
            b.width(),
            b.height(),
            a.width(),
            a.height()
        )));
    }
    let rgb = a.rgb().iter().zip(b.rgb()).map(|(x, y)| (x - y).max(0.0)).collect();
    EnvMap::new(a.width(), a.height(), rgb).map_err(|e| Error::Invalid(e.to_string()))
}
