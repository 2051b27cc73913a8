use picture::font::{GLYPH_H, GLYPH_W, MISSING, glyph, text_height, text_width};

/// Every glyph fits in 5 columns, and no two characters share a glyph, nor with the box drawn
/// for missing characters (a copy-paste slip would make two labels read alike).
#[test]
fn glyphs_are_five_wide_and_distinct() {
    let chars: Vec<char> = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ.,:-+=()/<>%_[]*'!?|;\u{b0}".chars().collect();
    let mut glyphs: Vec<[u8; 7]> = chars.iter().map(|&c| glyph(c).unwrap()).collect();
    for (c, g) in chars.iter().zip(&glyphs) {
        assert!(g.iter().all(|row| row >> GLYPH_W == 0), "{c} is wider than 5");
        assert!(g.iter().any(|row| *row != 0), "{c} is empty");
    }
    glyphs.push(MISSING);
    for i in 0..glyphs.len() {
        for j in i + 1..glyphs.len() {
            assert_ne!(glyphs[i], glyphs[j], "glyphs {i} and {j} look alike");
        }
    }
    assert_eq!(glyph('e'), glyph('E'));
    assert_eq!(glyph('~'), None);
}

/// Width: 6 font pixels per character less the trailing space, of the longest line; height:
/// 7 per line plus 3 between lines.
#[test]
fn text_extent() {
    assert_eq!(text_width("10", 2), 22);
    assert_eq!(text_width("", 3), 0);
    assert_eq!(text_width("ab\nlonger\nc", 1), 35);
    assert_eq!(text_height("x", 2), 2 * GLYPH_H);
    assert_eq!(text_height("a\nb\nc", 1), 27);
}

/// Lines break between words and fit the width (a line of `n` characters is `6 n - 1` font
/// pixels wide); existing breaks stay; a word too long for any line gets one of its own.
#[test]
fn wrapping() {
    use picture::font::wrap;
    // 23 pixels at scale 1 hold 4 characters (23 = 6 x 4 - 1).
    assert_eq!(wrap("ab cd ef", 23, 1), "ab\ncd\nef");
    assert_eq!(wrap("ab c def", 23, 1), "ab c\ndef");
    assert_eq!(wrap("ab c def", 22, 1), "ab\nc\ndef");
    assert_eq!(wrap("ab c def", 46, 2), "ab c\ndef");
    assert_eq!(wrap("x\ny  z", 100, 1), "x\ny z");
    assert_eq!(wrap("a verylongword b", 23, 1), "a\nverylongword\nb");
    for text in ["the rows nearest the poles read up to 1 / sin theta times more", "a b c d e f g h"] {
        // From the longest word's width (7 characters: 41 pixels) up.
        for width in [41, 61, 100, 250] {
            let wrapped = wrap(text, width, 1);
            assert!(text_width(&wrapped, 1) <= width, "{wrapped:?} at {width}");
            assert_eq!(wrapped.split_whitespace().collect::<Vec<_>>(), text.split_whitespace().collect::<Vec<_>>());
        }
    }
}
