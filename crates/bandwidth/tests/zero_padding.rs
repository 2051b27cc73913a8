//! Test 7: zero padding for sources of finite extent (001 section 2.3).

use std::f64::consts::TAU;

use bandwidth::{BandwidthMap, Config, DEFAULT_C, Image, local_bandwidth, local_bandwidth_zero_padded};

const N: usize = 128;

/// An area light whose left half is dark and whose right half holds a sinusoid of period 11
/// (radiance `(1 + cos) / 2`, at 30 degrees): its content touches the right, top and bottom
/// borders but is 64 pixels from the left one.
fn light() -> Image {
    Image::from_fn(N, N, |x, y| {
        if x < N / 2 { 0.0 } else { 0.5 + 0.5 * (TAU / 11.0 * (x as f64 * 0.866 + y as f64 * 0.5)).cos() }
    })
}

fn column_levels(map: &BandwidthMap, x: usize) -> Vec<usize> {
    (0..N).map(|y| map.level_at(x, y).unwrap_or(usize::MAX)).collect()
}

/// Without padding the dark left border meets the lit right border through the periodic seam
/// and reads the jump there as an edge (level 1 or 2 in the first three columns). With padding
/// the left border meets zeros: it only reads, through coarse coefficients, the content 64
/// pixels away (level 5 or coarser: at most `c / 32` cycles per pixel). The light's right border,
/// a real edge of the source, reads level 1 or 2 in both (2 on the rows where the radiance at
/// the edge is near 0, so the jump is small).
#[test]
fn padding_removes_the_wrap_around_and_keeps_real_edges() {
    let config = Config::default();
    let periodic = local_bandwidth(&light(), &config).unwrap();
    let padded = local_bandwidth_zero_padded(&light(), &config).unwrap();
    assert_eq!((padded.width(), padded.height(), padded.levels()), (N, N, 8));
    for x in 0..3 {
        let levels = column_levels(&periodic, x);
        assert!(levels.iter().all(|j| *j <= 2), "periodic column {x}: {levels:?}");
    }
    for x in 0..32 {
        let levels = column_levels(&padded, x);
        assert!(levels.iter().all(|j| *j >= 5), "padded column {x}: {levels:?}");
        assert!((0..N).all(|y| padded.frequency_at(x, y) <= DEFAULT_C / 32.0));
    }
    for map in [&periodic, &padded] {
        assert!(column_levels(map, N - 1).iter().all(|j| *j <= 2), "right border: {:?}", column_levels(map, N - 1));
    }
    println!(
        "zero padding: left border reads {:.4} cycles per pixel padded, {:.4} periodic",
        padded.frequency_at(0, N / 2),
        periodic.frequency_at(0, N / 2)
    );
}

/// Any size works padded: the image is padded to at least twice its size, rounded up to a
/// multiple of `2^J`, and the map has the image's size.
#[test]
fn awkward_sizes_work_padded() {
    let image = Image::from_fn(37, 19, |x, y| ((x * 7 + y * 3) % 5) as f64);
    let map = local_bandwidth_zero_padded(&image, &Config::default()).unwrap();
    assert_eq!((map.width(), map.height(), map.levels()), (37, 19, 5));
    let map = local_bandwidth_zero_padded(&image, &Config { levels: Some(3), ..Config::default() }).unwrap();
    assert_eq!(map.levels(), 3);
}
