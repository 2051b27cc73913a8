use picture::Canvas;
use picture::font::{GLYPH_H, glyph, text_width};

use crate::{bounding_box, count};

const BG: [u8; 3] = [1, 2, 3];
const RED: [u8; 3] = [255, 0, 0];

/// Text covers exactly text_width x glyph height: every inked pixel inside, and the ink touches
/// all four sides when the first character has a pixel in its left column, the last in its right
/// column, and some character one in its top and bottom rows ("H" and "M" do).
#[test]
fn text_lands_inside_its_extent() {
    for (text, scale) in [("HM", 1), ("H1.5E-3M", 2), ("MAX: 10 %", 3), ("H\nMWM", 2)] {
        let mut canvas = Canvas::new(200, 100, BG);
        canvas.text(7, 5, text, scale, RED);
        let (x0, y0, x1, y1) = bounding_box(&canvas, RED).unwrap();
        let h = picture::font::text_height(text, scale);
        assert_eq!((x0, y0, x1, y1), (7, 5, 7 + text_width(text, scale), 5 + h), "{text:?} at scale {scale}");
    }
    // Lower case is drawn upper case; a missing character as a box, not as nothing.
    let draw = |text: &str| {
        let mut canvas = Canvas::new(40, 20, BG);
        canvas.text(0, 0, text, 1, RED);
        canvas
    };
    assert_eq!(draw("ab"), draw("AB"));
    assert_eq!(count(&draw("~"), RED), 2 * 5 + 2 * 5);
    assert_eq!(count(&draw("1"), RED), glyph('1').unwrap().iter().map(|r| r.count_ones() as usize).sum::<usize>());
    assert_eq!(GLYPH_H, 7);
}

/// Blitting with up-scaling puts source pixel (sx, sy) in the block at (x + k sx, y + k sy).
#[test]
fn blit_scales_by_nearest() {
    let src = Canvas::from_fn(3, 2, |x, y| [x as u8 * 50, y as u8 * 100, 7]);
    assert_eq!(src.pixel(2, 1), Some([100, 100, 7]));
    let mut canvas = Canvas::new(20, 20, BG);
    canvas.blit(&src, 4, 5, 3);
    for y in 0..20 {
        for x in 0..20 {
            let inside = (4..13).contains(&x) && (5..11).contains(&y);
            let expected = if inside { src.pixel((x - 4) / 3, (y - 5) / 3).unwrap() } else { BG };
            assert_eq!(canvas.pixel(x, y), Some(expected), "({x}, {y})");
        }
    }
    let mut from_buffer = Canvas::new(20, 20, BG);
    from_buffer.blit_rgb8(3, 2, &src.rgb, 4, 5, 3);
    assert_eq!(from_buffer, canvas);
}

/// Lines and rectangles fill exactly their pixels.
#[test]
fn shapes() {
    let mut canvas = Canvas::new(10, 8, BG);
    canvas.fill_rect(2, 3, 4, 2, RED);
    canvas.hline(0, 7, 3, RED);
    canvas.vline(9, 0, 2, RED);
    canvas.put(5, 6, RED);
    for y in 0..8 {
        for x in 0..10 {
            let red = ((2..6).contains(&x) && (3..5).contains(&y))
                || (y == 7 && x < 3)
                || (x == 9 && y < 2)
                || (x, y) == (5, 6);
            assert_eq!(canvas.pixel(x, y), Some(if red { RED } else { BG }), "({x}, {y})");
        }
    }
    assert_eq!(canvas.pixel(10, 0), None);
}

/// Every drawing call clips at the edges: what lies inside is drawn, nothing panics, whatever
/// the position (half outside, far outside, at the limits of isize) or size.
#[test]
fn drawing_clips_at_the_edges() {
    let mut canvas = Canvas::new(30, 20, BG);
    // Text half outside on the left and top: the visible part equals the same text drawn inside
    // a larger canvas and cropped.
    canvas.text(-7, -3, "HELLO", 2, RED);
    let mut big = Canvas::new(60, 40, BG);
    big.text(13, 7, "HELLO", 2, RED);
    for y in 0..20 {
        for x in 0..30 {
            assert_eq!(canvas.pixel(x, y), big.pixel(x + 20, y + 10), "({x}, {y})");
        }
    }
    assert!(count(&canvas, RED) > 0);
    let src = Canvas::new(8, 8, RED);
    let far = [isize::MIN, -1000, -5, 25, 1000, isize::MAX];
    for &x in &far {
        for &y in &far {
            canvas.text(x, y, "CLIPPED 12345\nTWO", 3, RED);
            canvas.fill_rect(x, y, usize::MAX, usize::MAX, RED);
            canvas.hline(x, y, usize::MAX, RED);
            canvas.vline(x, y, 100, RED);
            canvas.put(x, y, RED);
            canvas.blit(&src, x, y, 4);
            canvas.blit(&src, x, y, usize::MAX);
            canvas.blit(&src, x, y, 0);
        }
    }
    // The last fill_rect calls covered the canvas from (-5, -5) on.
    assert_eq!(count(&canvas, RED), 30 * 20);
    let mut empty = Canvas::new(0, 0, BG);
    empty.text(0, 0, "X", 1, RED);
    empty.blit(&src, 0, 0, 1);
    assert!(empty.rgb.is_empty());
}

/// A box filter keeps the mean of every block it reduces (a 6 x 4 pattern to 3 x 2: each new
/// pixel the mean of a 2 x 2 block), averages by shared area at a ratio that is not whole (3
/// columns of 0, 90, 180 to 2: (0 + 45) / 1.5 = 30 and (45 + 180) / 1.5 = 150), and leaves an
/// unchanged size unchanged.
#[test]
fn resizing_averages_by_area() {
    let pattern = Canvas::from_fn(6, 4, |x, y| [(10 * x + 60 * y) as u8, 0, 255]);
    let half = pattern.resized(3, 2);
    for (x, y) in [(0, 0), (2, 1), (1, 1)] {
        let mean: usize =
            [(0, 0), (1, 0), (0, 1), (1, 1)].iter().map(|(dx, dy)| 10 * (2 * x + dx) + 60 * (2 * y + dy)).sum();
        assert_eq!(half.pixel(x, y), Some([(mean as f64 / 4.0).round() as u8, 0, 255]), "({x}, {y})");
    }
    let ramp = Canvas::from_fn(3, 1, |x, _| [(90 * x) as u8; 3]);
    let two = ramp.resized(2, 1);
    assert_eq!((two.pixel(0, 0), two.pixel(1, 0)), (Some([30; 3]), Some([150; 3])));
    assert_eq!(pattern.resized(6, 4), pattern);
    assert_eq!(pattern.resized(0, 4).rgb.len(), 0);
}

/// `find` locates a label drawn into a larger canvas at its exact corner, and nothing that is
/// not there (another text, or the same text at another scale).
#[test]
fn finding_labels() {
    let mut canvas = Canvas::new(300, 80, picture::BACKGROUND);
    canvas.text(37, 21, "theta_o = 30\u{b0}", picture::TEXT_SCALE, picture::INK);
    assert_eq!(canvas.find(&Canvas::label("theta_o = 30\u{b0}")), Some((37, 21)));
    assert_eq!(canvas.find(&Canvas::label("= 30")), Some((37 + 8 * 12, 21)));
    assert_eq!(canvas.find(&Canvas::label("theta_o = 60\u{b0}")), None);
    let mut small = Canvas::new(300, 80, picture::BACKGROUND);
    small.text(37, 21, "theta_o", 1, picture::INK);
    assert_eq!(small.find(&Canvas::label("theta_o")), None);
    assert_eq!(canvas.find(&Canvas::new(0, 0, BG)), None);
    assert_eq!(canvas.find(&Canvas::new(301, 1, picture::BACKGROUND)), None);
}
