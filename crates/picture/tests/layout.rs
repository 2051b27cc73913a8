use picture::font::{GLYPH_H, text_width};
use picture::layout::{Axis, CAPTION_MARGIN, Grid, TITLE_GAP, TITLE_SPACE, caption, difference, heat_map, stack};
use picture::{BACKGROUND, Canvas, INK, TEXT_SCALE};

use crate::bounding_box;

/// A panel of one colour, distinct per panel.
fn panel(w: usize, h: usize, i: u8) -> Canvas {
    Canvas::new(w, h, [200, i * 20, 100])
}

/// Columns as wide as their widest panel, rows as high as their highest panel plus a title
/// line, margins and gaps as set; each panel lands at its cell's top-left corner under its
/// title, and the footer at the bottom left.
#[test]
fn grid_sizes_and_positions() {
    let (margin, gap) = (10, 6);
    let title_line = GLYPH_H * TEXT_SCALE + TITLE_GAP;
    let sizes = [(40, 30), (50, 20), (30, 45), (20, 10), (60, 12)];
    let mut grid = Grid::new(2);
    grid.margin(margin).gap(gap).title("figure");
    for (i, &(w, h)) in sizes.iter().enumerate() {
        grid.add(panel(w, h, i as u8), if i == 4 { "" } else { "t" });
    }
    // Columns: max(40, 30, 60) and max(50, 20); rows: 30, 45, 12 (the last without a title).
    let columns = [60, 50];
    let width = 2 * margin + 60 + gap + 50;
    assert_eq!(grid.width(), width);
    let figure_title = GLYPH_H * TEXT_SCALE + gap;
    let rows = [title_line + 30, title_line + 45, 12];
    let body = 2 * margin + figure_title + rows.iter().sum::<usize>() + 2 * gap;
    let footer = Canvas::new(width + 7, 9, [9, 9, 9]);
    grid.footer(footer.clone());
    let canvas = grid.render();
    assert_eq!((canvas.width, canvas.height), (width + 7, body + 9));
    for (i, &(w, h)) in sizes.iter().enumerate() {
        let (row, column) = (i / 2, i % 2);
        let x = margin + if column == 1 { columns[0] + gap } else { 0 };
        let mut y = margin + figure_title + rows[..row].iter().sum::<usize>() + row * gap;
        if i != 4 {
            y += title_line;
        }
        let colour = panel(1, 1, i as u8).pixel(0, 0).unwrap();
        assert_eq!(bounding_box(&canvas, colour), Some((x, y, x + w, y + h)), "panel {i}");
        if i != 4 {
            let above = (x..x + w).any(|c| (y - title_line..y).any(|r| canvas.pixel(c, r) == Some(INK)));
            assert!(above, "the title of panel {i}");
        }
    }
    assert_eq!(bounding_box(&canvas, [9, 9, 9]), Some((0, body, width + 7, body + 9)));
    // A long panel title widens its column, and where another column follows it keeps
    // TITLE_SPACE beside the gap, free of ink, so that two titles do not read as one line.
    let mut grid = Grid::new(3);
    grid.add(panel(10, 10, 0), "a long title");
    assert_eq!(grid.width(), 2 * 16 + text_width("a long title", TEXT_SCALE));
    let title = text_width("a long title", TEXT_SCALE);
    let mut grid = Grid::new(2);
    grid.margin(0).gap(gap).add(panel(10, 10, 0), "a long title").add(panel(10, 10, 1), "next");
    assert_eq!(grid.width(), title + TITLE_SPACE + gap + text_width("next", TEXT_SCALE));
    let canvas = grid.render();
    let ink = |x: usize| (0..title_line).any(|y| canvas.pixel(x, y) == Some(INK));
    assert!(ink(title - 1) && (title..title + TITLE_SPACE + gap).all(|x| !ink(x)) && ink(title + TITLE_SPACE + gap));
    assert_eq!(Grid::new(0).render().width, 32);
}

/// The heat map keeps the image (enlarged) intact, with ticks at the pixels of their values:
/// x = 0..8 over 8 columns zoomed by 4 (32 pixels): value v at pixel round(v / 8 * 32) (the last
/// for v = 8); y = 1 at the top down to -1 at the bottom (16 pixels).
#[test]
fn heat_map_ticks_and_image() {
    let image = Canvas::from_fn(8, 4, |x, y| [10 + x as u8 * 20, 10 + y as u8 * 40, 250]);
    let x_axis = Axis::new("x", 0.0, 8.0).with_ticks(vec![(0.0, "0".into()), (4.0, "4".into()), (8.0, "8".into())]);
    let y_axis = Axis::new("y up", 1.0, -1.0);
    assert_eq!(y_axis.ticks.iter().map(|t| t.0).collect::<Vec<_>>(), [-1.0, -0.5, 0.0, 0.5, 1.0]);
    let canvas = heat_map(&image, 4, &x_axis, &y_axis);
    // The image's top-left corner: the first pixel of its colour.
    let (left, top, right, bottom) = bounding_box(&canvas, image.pixel(0, 0).unwrap()).unwrap();
    assert_eq!((right - left, bottom - top), (4, 4));
    for y in 0..16 {
        for x in 0..32 {
            assert_eq!(canvas.pixel(left + x, top + y), image.pixel(x / 4, y / 4), "({x}, {y})");
        }
    }
    // The axis lines frame the image on the left and below; ticks stick out from them.
    assert!((top..top + 17).all(|y| canvas.pixel(left - 1, y) == Some(INK)));
    assert!((left - 1..left + 32).all(|x| canvas.pixel(x, top + 16) == Some(INK)));
    let x_ticks: Vec<usize> = (0..canvas.width).filter(|&x| canvas.pixel(x, top + 18) == Some(INK)).collect();
    assert_eq!(x_ticks, [left, left + 16, left + 31]);
    let y_ticks: Vec<usize> = (top - 4..top + 20).filter(|&y| canvas.pixel(left - 3, y) == Some(INK)).collect();
    assert_eq!(y_ticks, [top, top + 4, top + 8, top + 12, top + 15]);
    // Labels and titles are inside the canvas and around the image, not on it.
    let ink = bounding_box(&canvas, INK).unwrap();
    assert!(ink.0 == 0 && ink.1 < top, "the y title at the top left: {ink:?}");
    assert!(ink.3 > top + 16 + 2 * GLYPH_H * TEXT_SCALE, "tick labels and x title below");
    assert_eq!(canvas.pixel(canvas.width - 1, canvas.height - 1), Some(BACKGROUND));
}

/// Degenerate axes and images do not panic: a zero-width image, an axis of zero length, ticks
/// outside the axis (left out).
#[test]
fn degenerate_heat_maps() {
    let image = Canvas::new(0, 3, [1, 1, 1]);
    let same = Axis::new("", 2.0, 2.0);
    assert!(same.ticks.is_empty());
    heat_map(&image, 3, &same, &Axis::new("t", 0.0, 1.0));
    let image = Canvas::new(2, 2, [1, 1, 1]);
    let outside = Axis::new("a", 0.0, 1.0).with_ticks(vec![(-5.0, "far".into()), (f64::NAN, "nan".into())]);
    let canvas = heat_map(&image, 0, &outside, &outside);
    assert!(canvas.width > 0);
}

/// A caption is as wide as asked, its text wrapped inside the margins (its ink never in them),
/// one line per wrapped line; a stack puts its parts one under the other at the left edge.
#[test]
fn captions_and_stacks() {
    let text = "the rows nearest the poles read up to 1 / sin theta times more: they take the end colour";
    let width = 300;
    let part = caption(text, width);
    assert_eq!(part.width, width);
    let lines = picture::font::wrap(text, width - 2 * CAPTION_MARGIN, TEXT_SCALE);
    assert!(lines.lines().count() >= 3);
    let (x0, _, x1, _) = bounding_box(&part, INK).unwrap();
    assert!(x0 >= CAPTION_MARGIN && x1 <= width - CAPTION_MARGIN, "ink from {x0} to {x1}");
    for line in lines.lines() {
        assert!(part.find(&Canvas::label(line)).is_some(), "{line:?}");
    }
    let top = Canvas::new(40, 10, [1, 2, 3]);
    let bottom = Canvas::new(60, 5, [4, 5, 6]);
    let both = stack(&[top, bottom]);
    assert_eq!((both.width, both.height), (60, 15));
    assert_eq!(bounding_box(&both, [1, 2, 3]), Some((0, 0, 40, 10)));
    assert_eq!(bounding_box(&both, [4, 5, 6]), Some((0, 10, 60, 15)));
    assert_eq!(stack(&[]).width, 0);
}

/// The difference figure's heat map, drawn independently: `hot` pixels at the top of the scale,
/// every other at its bottom.
fn expected_difference_map(side: usize, hot: &[(usize, usize)]) -> Canvas {
    let image = Canvas::from_fn(side, side, |x, y| {
        if hot.contains(&(x, y)) { picture::colormap::inferno(1.0) } else { picture::colormap::inferno(0.0) }
    });
    let zoom = 256 / side;
    heat_map(&image, zoom, &Axis::new("x, pixels", 0.0, side as f64), &Axis::new("y, pixels", 0.0, side as f64))
}

#[test]
fn a_difference_figure_maps_the_largest_channel_difference_on_its_own_scale() {
    let side = 16;
    let a = vec![100u8; side * side * 3];
    let mut b = a.clone();
    // Pixel (3, 5) differs by 40 levels in green and 7 in blue; pixel (10, 2) by 20 in red.
    let at = |x: usize, y: usize| 3 * (y * side + x);
    b[at(3, 5) + 1] += 40;
    b[at(3, 5) + 2] -= 7;
    b[at(10, 2)] += 20;
    let figure = difference(&a, &b, side, side, "GPU - CPU");
    // The largest difference is the scale's top; the other one sits at half of it.
    let half = picture::colormap::inferno(0.5);
    let mut expected = expected_difference_map(side, &[(3, 5)]);
    let zoom = 256 / side;
    let origin = expected.find(&Canvas::from_fn(zoom, zoom, |_, _| picture::colormap::inferno(1.0))).unwrap();
    expected.fill_rect(
        (origin.0 + (10 - 3) * zoom) as isize,
        (origin.1 as isize) - (3 * zoom) as isize,
        zoom,
        zoom,
        half,
    );
    assert!(figure.find(&expected).is_some(), "the heat map shows (3, 5) at the top and (10, 2) at half the scale");
    // Identical pictures: every pixel at the bottom of a scale of at least one level.
    let same = difference(&a, &a, side, side, "GPU - CPU");
    assert!(same.find(&expected_difference_map(side, &[])).is_some(), "identical pictures map to the scale's bottom");
    assert!(same.find(&expected).is_none());
}
