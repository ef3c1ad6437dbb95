//! The embedded DejaVu Sans font, registered with plotters once per process,
//! and the pixel sizes the plots draw text at.

use std::sync::OnceLock;

use plotters::style::{FontStyle, register_font};

use super::PlotError;

/// The bundled font file.
static DEJAVU_SANS: &[u8] = include_bytes!("../../../../assets/fonts/DejaVuSans.ttf");

/// The family name under which the embedded font is registered.
pub(crate) const FAMILY: &str = "sans-serif";

// Text sizes in pixels. All even: plotters' ab_glyph renderer puts each
// glyph's top at `size / 2 + top` truncated toward zero, so at an odd size a
// glyph whose top lies above the middle of the line lands a pixel lower than
// one whose top lies below it, and periods and commas float up like middle
// dots (`tests::every_text_size_keeps_periods_on_the_baseline`).

/// Plot titles.
pub(crate) const TITLE_PX: u32 = 24;
/// Axis descriptions.
pub(crate) const AXIS_PX: u32 = 16;
/// Tick labels, legends, text inside bars.
pub(crate) const TICK_PX: u32 = 14;
/// Point labels, marks and notes.
pub(crate) const LABEL_PX: u32 = 12;

/// Register the embedded font (idempotent).
pub(crate) fn ensure_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS).is_ok());
    if ok { Ok(()) } else { Err(PlotError::Font) }
}

#[cfg(test)]
mod tests {
    use plotters::prelude::*;

    use super::*;

    /// The lowest row with any ink when `text` is drawn alone at `px`.
    fn lowest_ink_row(text: &str, px: u32) -> Option<u32> {
        let (w, h) = (40u32, 48u32);
        let mut buf = vec![255u8; (w * h * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            root.draw(&Text::new(text, (4, 4), (FAMILY, px).into_font())).unwrap();
            root.present().unwrap();
        }
        (0..h)
            .rev()
            .find(|&y| (0..w).any(|x| buf[((y * w + x) * 3) as usize] < 250))
    }

    #[test]
    fn every_text_size_keeps_periods_on_the_baseline() {
        ensure_font().unwrap();
        for px in [TITLE_PX, AXIS_PX, TICK_PX, LABEL_PX] {
            let x = lowest_ink_row("x", px);
            assert!(x.is_some(), "no ink for x at {px} px");
            assert_eq!(
                lowest_ink_row(".", px),
                x,
                "a period at {px} px does not sit on the baseline"
            );
        }
        // The check fails at an odd size, where the period floats up.
        assert_ne!(lowest_ink_row(".", 13), lowest_ink_row("x", 13));
    }
}
