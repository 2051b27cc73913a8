//! Test 4: flat and zero images read flat, in every mode, and the noise floor is what makes
//! them so.

use bandwidth::{Config, Image, latlong_bandwidth, local_bandwidth, local_bandwidth_zero_padded};

/// Constants, including large and negative ones, whose transforms leave rounding noise of order
/// `1e-16` times the value in the details: no pixel may read a frequency.
#[test]
fn flat_images_read_flat_in_every_mode() {
    let config = Config::default();
    for value in [0.0, 0.7, -3.25, 123.456, 1e6] {
        for (w, h) in [(64, 32), (48, 80)] {
            let image = Image::from_fn(w, h, |_, _| value);
            let maps = [
                local_bandwidth(&image, &config).unwrap(),
                local_bandwidth_zero_padded(&image, &config).unwrap(),
                latlong_bandwidth(&image, &config).unwrap().pixels().clone(),
            ];
            // Zero padding makes a constant a finite patch with real edges: only the zero
            // image is flat there.
            for (mode, map) in ["periodic", "zero padded", "lat-long"].iter().zip(&maps) {
                if *mode == "zero padded" && value != 0.0 {
                    continue;
                }
                let read = map.frequency().iter().filter(|f| **f != 0.0).count();
                assert_eq!(read, 0, "{mode} {w}x{h} of {value}: {read} pixels read a frequency");
                assert!(map.level().iter().all(|j| *j == 0) && map.nyquist_count() == 0);
            }
        }
    }
}

/// Without the floor the same constant reads its rounding noise somewhere (this is why the
/// floor exists, and shows the test above can fail); the zero image has no noise to read.
#[test]
fn without_a_floor_rounding_noise_reads_as_signal() {
    let config = Config { noise_floor: 0.0, ..Config::default() };
    let noisy = local_bandwidth(&Image::from_fn(64, 32, |_, _| 0.7), &config).unwrap();
    let read = noisy.frequency().iter().filter(|f| **f != 0.0).count();
    println!("flat 0.7 without a noise floor: {read} of {} pixels read a frequency", 64 * 32);
    assert!(read > 0);
    let zero = local_bandwidth(&Image::zeros(64, 32), &config).unwrap();
    assert!(zero.frequency().iter().all(|f| *f == 0.0));
}
