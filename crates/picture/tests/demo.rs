//! A figure to look at: `cargo test -p picture -- --ignored demo` writes
//! /tmp/picture-demo.png.

use picture::colormap::{Scale, inferno, range_by_percentiles, viridis};
use picture::layout::{Axis, Grid, heat_map};
use picture::legend::Legend;
use picture::{Canvas, format_number};

const CYAN: [u8; 3] = [0, 255, 255];
const GREY: [u8; 3] = [128, 128, 128];

#[test]
#[ignore = "writes /tmp/picture-demo.png to look at"]
fn demo() {
    // A lat-long-like field over theta (rows) and phi (columns) that blows up near the poles
    // (on few texels by solid angle, so the weighted range leaves them out and the legend shows
    // the clipping arrow), with some flat texels and a band at a limit.
    let (w, h) = (64, 32);
    let theta = |y: usize| (y as f64 + 0.5) / h as f64 * std::f64::consts::PI;
    let values: Vec<f64> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let phi = (x as f64 + 0.5) / w as f64 * std::f64::consts::TAU;
            (1.0 + 20.0 * (3.0 * phi).cos().powi(2) * (2.0 * theta(y)).sin().powi(2)) / theta(y).sin().powi(2)
        })
        .collect();
    let weights: Vec<f64> = (0..w * h).map(|i| theta(i / w).sin()).collect();
    let (lo, hi) = range_by_percentiles(&values, Some(&weights), 0.01, 0.99).unwrap();
    let scale = Scale::log(lo, hi).nice();
    let flat = |x: usize, y: usize| (10..16).contains(&x) && (12..20).contains(&y);
    let colour = |x: usize, y: usize| match (flat(x, y), x >= 60) {
        (true, _) => GREY,
        (_, true) => CYAN,
        _ => inferno(scale.position(values[y * w + x])),
    };
    let image = Canvas::from_fn(w, h, colour);
    let degrees = |ticks: &[f64]| ticks.iter().map(|&v| (v, format!("{}\u{b0}", format_number(v)))).collect();
    let x_axis = Axis::new("phi", 0.0, 360.0).with_ticks(degrees(&[0.0, 90.0, 180.0, 270.0, 360.0]));
    let y_axis = Axis::new("theta", 0.0, 180.0).with_ticks(degrees(&[0.0, 90.0, 180.0]));
    let linear = Scale::linear(0.0, 1.0);
    let ramp = Canvas::from_fn(48, 48, |x, y| viridis(linear.position((x + y) as f64 / 94.0)));

    let mut grid = Grid::new(2);
    grid.title("picture demo: a heat map with axes, a plain panel, a legend");
    grid.add(heat_map(&image, 6, &x_axis, &y_axis), "bandwidth (cycles/rad)");
    grid.add(heat_map(&ramp, 4, &Axis::new("u", 0.0, 1.0), &Axis::new("v", 1.0, 0.0)), "viridis ramp");
    let legend = Legend::new(scale, inferno, "local bandwidth, cycles per radian (log scale)")
        .clipped(scale.clipping(&values))
        .swatch(CYAN, "cyan: at the grid's limit")
        .swatch(GREY, "grey: flat");
    grid.footer(legend.render(grid.width()));
    let figure = grid.render();

    let file = std::fs::File::create("/tmp/picture-demo.png").unwrap();
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), figure.width as u32, figure.height as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header().unwrap().write_image_data(&figure.rgb).unwrap();
}
