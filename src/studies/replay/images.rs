//! How many images the replayed swap chain had, from its render
//! completions (issue 54): a capture does not record a swap chain's image
//! count, and the replay takes three (DXGI's usual flip chain). Behind a
//! back-pressured chain (vsync, `fifo` or composed) the GPU starts a frame
//! only when an image is free, so a chain with more images finishes its
//! frames' GPU work earlier than three would let it. Where the replay as
//! captured finishes them later than the capture measured (render
//! completion's median error above [`LATE_MS`]), the chain had more: the
//! replay takes the smallest count up to [`MAX_IMAGES`] whose replay puts
//! the completions within [`LATE_MS`] of the capture's, and says so
//! (`replay.images`). PresentMon's TrivFlip test app, composed at 60 Hz,
//! finished its frames 11.2 ms before three images allow; four put them
//! where measured. Nothing is inferred when `display.buffers` is assumed,
//! or for flips that never wait (`immediate`).

use serde::Serialize;

use super::compare::median;
use super::setup::{Setup, assumes};
use super::{ReplayError, Simulated, simulate};

/// Render completion later than measured by more than this (median, ms)
/// says the replay's chain has too few images: the accuracy target's bound.
pub const LATE_MS: f64 = 0.5;

/// The most images tried.
pub const MAX_IMAGES: i64 = 8;

/// The image count inferred (`replay.images`, only where one was).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ImagesInference {
    /// The swap chain's images.
    pub buffers: i64,
    /// The count the replay would otherwise take.
    pub instead_of: i64,
    /// How much later than measured the replay with that count finished
    /// the frames' GPU work (median, ms).
    pub late_ms_instead: f64,
}

/// The median of predicted less measured render completion, ms (`None`
/// without a frame that has both).
fn late_ms(sim: &Simulated) -> Option<f64> {
    median(
        sim.frames
            .iter()
            .filter_map(|f| Some(f.render_complete.1? - f.render_complete.0?))
            .collect(),
    )
}

/// The replay as captured with the image count its render completions
/// show (see the module's documentation): `captured` itself when nothing
/// is to infer, else the replay with the count taken, which `s`'s model
/// then holds (so what-ifs keep it).
pub(super) fn infer_images(
    s: &mut Setup,
    assume: &[String],
    captured: Simulated,
) -> Result<(Simulated, Option<ImagesInference>), ReplayError> {
    let late = late_ms(&captured);
    if s.mode == "immediate" || assumes(assume, "display.buffers") || late.is_none_or(|l| l <= LATE_MS) {
        return Ok((captured, None));
    }
    let instead_of = i64::from(captured.model.display.buffers);
    // The replay model always has a `[display]` table.
    let set = |s: &mut Setup, n: i64| {
        if let Some(d) = s.table.get_mut("display").and_then(|d| d.as_table_mut()) {
            d.insert("buffers".into(), toml::Value::Integer(n));
        }
    };
    for n in instead_of + 1..=MAX_IMAGES {
        set(s, n);
        let sim = simulate(s, &[])?;
        if late_ms(&sim).is_some_and(|l| l.abs() <= LATE_MS) {
            let found = ImagesInference {
                buffers: n,
                instead_of,
                late_ms_instead: late.unwrap_or(f64::NAN),
            };
            return Ok((sim, Some(found)));
        }
    }
    set(s, instead_of);
    Ok((captured, None))
}
