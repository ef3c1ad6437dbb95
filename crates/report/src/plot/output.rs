//! Writing one drawing to both an SVG and a PNG file.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use super::font::ensure_font;
use super::{HEIGHT, PlotError, WIDTH};

/// `<base>.<ext>`, appending rather than replacing any dot in the name.
pub(crate) fn with_ext(base: &Path, ext: &str) -> PathBuf {
    let mut s: OsString = base.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

/// Draw the same picture into `<base>.svg` and `<base>.png`. The two closures
/// are normally the same generic drawing function instantiated per backend.
pub(crate) fn render_both(
    base: &Path,
    svg: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String>,
    png: impl FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), String>,
) -> Result<(), PlotError> {
    ensure_font()?;
    let svg_path = with_ext(base, "svg");
    let png_path = with_ext(base, "png");
    if let Some(dir) = base.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|source| PlotError::Io {
            path: svg_path.clone(),
            source,
        })?;
    }
    let draw_err = |path: &Path| {
        let path = path.to_path_buf();
        move |message: String| PlotError::Draw { path, message }
    };
    {
        let root = SVGBackend::new(&svg_path, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE)
            .map_err(|e| e.to_string())
            .map_err(draw_err(&svg_path))?;
        svg(&root).map_err(draw_err(&svg_path))?;
        root.present().map_err(|e| e.to_string()).map_err(draw_err(&svg_path))?;
    }
    // The PNG is drawn into a buffer and encoded by the `png` crate (not
    // plotters' encoder, which would bring the whole `image` crate into the
    // build).
    let mut rgb = vec![0u8; (WIDTH * HEIGHT * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE)
            .map_err(|e| e.to_string())
            .map_err(draw_err(&png_path))?;
        png(&root).map_err(draw_err(&png_path))?;
        root.present().map_err(|e| e.to_string()).map_err(draw_err(&png_path))?;
    }
    let bytes = encode_png(&rgb, WIDTH, HEIGHT).map_err(|e| draw_err(&png_path)(e.to_string()))?;
    std::fs::write(&png_path, bytes).map_err(|source| PlotError::Io { path: png_path, source })
}

/// Where a picture goes: `<base>.svg` and `<base>.png` beside each other,
/// or one SVG document kept in memory (a page that shows the picture,
/// `rendersim explore`).
pub(crate) enum Sink<'a> {
    /// `<base>.svg` and `<base>.png`.
    Files(&'a Path),
    /// An SVG document, written into the string.
    Svg(&'a mut String),
}

/// The name an in-memory picture goes by in errors.
pub(crate) const IN_MEMORY: &str = "<svg in memory>";

/// Draws one picture into an SVG document held in memory.
pub(crate) fn render_svg(
    out: &mut String,
    svg: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String>,
) -> Result<(), PlotError> {
    ensure_font()?;
    let err = |message: String| PlotError::Draw {
        path: PathBuf::from(IN_MEMORY),
        message,
    };
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
        svg(&root).map_err(err)?;
        root.present().map_err(|e| err(e.to_string()))?;
    }
    *out = s;
    Ok(())
}

/// The SVG document a plot's drawing into a [`Sink`] makes (the `_svg`
/// twins of the plot functions).
pub(crate) fn svg_of(draw: impl FnOnce(Sink<'_>) -> Result<(), PlotError>) -> Result<String, PlotError> {
    let mut out = String::new();
    draw(Sink::Svg(&mut out))?;
    Ok(out)
}

/// [`render_both`] or [`render_svg`], by `sink`.
pub(crate) fn render_to(
    sink: Sink<'_>,
    svg: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String>,
    png: impl FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), String>,
) -> Result<(), PlotError> {
    match sink {
        Sink::Files(base) => render_both(base, svg, png),
        Sink::Svg(out) => render_svg(out, svg),
    }
}

/// An RGB buffer of `width` x `height` pixels as PNG bytes.
pub(crate) fn encode_png(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header()?;
        w.write_image_data(rgb)?;
    }
    Ok(out)
}

/// Draw `notes` as small text lines in the bottom-left corner of `root`.
pub(crate) fn draw_notes<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, notes: &[String]) -> Result<(), String> {
    let (_, h) = root.dim_in_pixel();
    for (i, note) in notes.iter().rev().enumerate() {
        let y = h as i32 - 18 - 16 * i as i32;
        root.draw(&Text::new(
            note.clone(),
            (8, y),
            (super::font::FAMILY, super::font::LABEL_PX)
                .into_font()
                .color(&RGBColor(150, 40, 40)),
        ))
        .map_err(|e| e.to_string())?;
    }
    Ok(())
}

#[cfg(test)]
pub(crate) mod test_support {
    use std::path::Path;

    /// Assert that `<base>.svg` and `<base>.png` exist, are non-empty, and
    /// start with the right magic bytes.
    pub(crate) fn assert_plot_files(base: &Path) {
        let svg = std::fs::read(super::with_ext(base, "svg")).expect("svg written");
        let png = std::fs::read(super::with_ext(base, "png")).expect("png written");
        assert!(!svg.is_empty() && !png.is_empty());
        let head = String::from_utf8_lossy(&svg[..svg.len().min(200)]).to_string();
        assert!(
            head.starts_with("<svg") || head.starts_with("<?xml"),
            "svg head: {head}"
        );
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    }
}
