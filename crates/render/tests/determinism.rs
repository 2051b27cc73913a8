//! Renders are functions of their inputs: the same bytes twice, whatever the number of threads.

use render::converged::converged;
use render::{Estimator, Image, Settings};

use crate::support;

fn bits(image: &Image) -> Vec<u32> {
    image.rgb.iter().map(|v| v.to_bits()).collect()
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a thread pool").install(f)
}

#[test]
fn renders_do_not_depend_on_the_thread_count() {
    let scene = support::sphere_scene(24, 20);
    let lighting = support::sky_lighting();
    let material = support::phong(0);
    for mode in Estimator::ALL {
        let settings = Settings { estimator: mode, spp: 16, frames: 3, seed: 11 };
        let render = || render::render(&scene, material, &lighting, &settings).expect("valid inputs");
        let first = render();
        assert_eq!(bits(&first), bits(&render()), "{mode:?}: two renders differ");
        assert_eq!(bits(&first), bits(&in_pool(1, render)), "{mode:?}: one thread differs");
        assert_eq!(bits(&first), bits(&in_pool(3, render)), "{mode:?}: three threads differ");
        assert_eq!(first.covered, in_pool(1, render).covered);
    }
    let estimate = || converged(&scene, material, &lighting, 8, 5).expect("valid inputs");
    let first = estimate();
    assert_eq!(bits(&first), bits(&estimate()), "converged: two estimates differ");
    assert_eq!(bits(&first), bits(&in_pool(1, estimate)), "converged: one thread differs");
}

#[test]
fn seeds_give_different_renders() {
    // Seeds below the frame count once gave the same set of random words (f ^ seed).
    let scene = support::sphere_scene(24, 20);
    let lighting = support::sky_lighting();
    let material = support::phong(0);
    let render = |seed| {
        let settings = Settings { estimator: Estimator::Reference, spp: 16, frames: 8, seed };
        bits(&render::render(&scene, material, &lighting, &settings).expect("valid inputs"))
    };
    let images: Vec<Vec<u32>> = (0..4).map(render).collect();
    for a in 0..4 {
        for b in a + 1..4 {
            assert_ne!(images[a], images[b], "seeds {a} and {b} render the same image");
        }
    }
}
