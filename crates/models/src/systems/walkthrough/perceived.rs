//! Perceived movement speed per displayed refresh around a frame skip, in
//! the manner of paper 000 Figure 6 ("strong variations in perceived
//! movement speed during a frame skip (frame 2 is repeated)"), from a
//! walkthrough's per-frame table (`rendersim perceived-speed`).
//!
//! Each refresh shows the newest frame finished by then (`run.rs`: a frame
//! is shown at the first vertical blank after its rendering time, the
//! refreshes before repeat the frame before). The perceived speed at a
//! refresh is the camera's move between the image shown and the one shown
//! a refresh earlier, over the refresh period: zero while a frame is
//! repeated. Two readings of what the next image shows:
//! - **recorded path** (this simulator's: the path advances one pose per
//!   frame drawn): the next image is one pose further, so speed drops to
//!   zero during the skip and then returns;
//! - **time-based animation** (an application placing the camera at the
//!   time its frame is shown): the next image catches up every pose the
//!   skip missed, so zero is followed by a jump to (skipped + 1) x speed.
//!
//! The second is computed from the first by scaling each new image's move
//! by the refreshes since the image before (the path's speed assumed
//! constant over a skip).

use std::path::Path;

use crate::config::{ModelSource, deserialize};
use crate::plot::{LinePlot, PlotError, Series, line_plot};
use crate::systems::SimError;

use super::config::WalkthroughConfig;
use super::run::run_walkthrough;

/// Errors of drawing the perceived-speed figure.
#[derive(Debug, thiserror::Error)]
pub enum PerceivedError {
    /// The model is not a walkthrough.
    #[error("{model}: system {system:?} has no camera path; perceived-speed needs system = \"walkthrough\"")]
    NotWalkthrough {
        /// The model's name.
        model: String,
        /// Its system.
        system: String,
    },
    /// The walkthrough failed.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The plot could not be written.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// A column is missing from the table.
    #[error("the per-frame table has no column {0:?}")]
    Column(String),
    /// A bad window.
    #[error("{0}")]
    Window(String),
}

/// One displayed refresh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Refresh {
    /// Refresh index (1 = the first vertical blank after the start).
    pub index: u64,
    /// Frame on screen.
    pub frame: u64,
    /// Perceived speed, recorded path, m/s.
    pub recorded: f64,
    /// Perceived speed, time-based animation, m/s.
    pub time_based: f64,
}

/// The refreshes of a walkthrough's per-frame table (`columns`, `rows`),
/// refresh period `period_s` seconds.
pub fn refreshes(columns: &[String], rows: &[Vec<f64>], period_s: f64) -> Result<Vec<Refresh>, PerceivedError> {
    let col = |name: &str| {
        columns
            .iter()
            .position(|c| c == name)
            .ok_or_else(|| PerceivedError::Column(name.to_string()))
    };
    let (shown, moved) = (col("ShownAtRefresh")?, col("MovedM")?);
    let mut out = Vec::new();
    let mut last = 0u64;
    for (f, r) in rows.iter().enumerate() {
        let at = r[shown] as u64;
        for index in last + 1..at {
            out.push(Refresh {
                index,
                frame: f.saturating_sub(1) as u64,
                recorded: 0.0,
                time_based: 0.0,
            });
        }
        let v = r[moved] / period_s;
        out.push(Refresh {
            index: at,
            frame: f as u64,
            recorded: v,
            time_based: v * (at - last).max(1) as f64,
        });
        last = at;
    }
    Ok(out)
}

/// What [`figure6`] drew.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure6 {
    /// The refresh that repeated a frame the figure is centred on (None:
    /// no skip in the run).
    pub first_skip: Option<u64>,
    /// Refreshes drawn (first, last).
    pub range: (u64, u64),
    /// Skips in the whole run.
    pub skips: u64,
}

/// Runs the walkthrough `src`/`table` and draws the perceived speed per
/// refresh for `around` refreshes either side of its first skip that has
/// `around` refreshes before it (else its first skip; from the start
/// without a skip) into `out` (its extension is replaced: `.svg`
/// and `.png` are written).
pub fn figure6(src: &ModelSource, table: &toml::Table, around: u64, out: &Path) -> Result<Figure6, PerceivedError> {
    if !(1..=10_000).contains(&around) {
        return Err(PerceivedError::Window(format!(
            "--around must be between 1 and 10000 refreshes, got {around}"
        )));
    }
    let system = match table.get("system") {
        Some(toml::Value::String(s)) => s.clone(),
        Some(other) => other.to_string(),
        None => "frame_pipeline".to_string(),
    };
    if system != "walkthrough" {
        return Err(PerceivedError::NotWalkthrough {
            model: src.name.clone(),
            system,
        });
    }
    let cfg: WalkthroughConfig = deserialize(table, src).map_err(SimError::from)?;
    let period_s = cfg.display.refresh.period.0.max(1) as f64 * 1e-12;
    let run = run_walkthrough(cfg).map_err(|e| SimError::of(src, e))?;
    let all = refreshes(&run.columns, &run.rows, period_s)?;
    let repeated = |i: usize| i > 0 && all[i].frame == all[i - 1].frame;
    // The first skip with `around` refreshes before it, else the first.
    let first = (around as usize..all.len())
        .find(|&i| repeated(i))
        .or_else(|| (0..all.len()).find(|&i| repeated(i)));
    let skips = (0..all.len()).filter(|&i| repeated(i)).count() as u64;
    let centre = first.unwrap_or(around as usize);
    let lo = centre.saturating_sub(around as usize);
    let hi = (centre + around as usize + 1).min(all.len());
    let window = &all[lo..hi];
    let series = |name: &str, v: fn(&Refresh) -> f64| Series {
        name: name.to_string(),
        points: window.iter().map(|r| (r.index as f64, v(r))).collect(),
        ci: None,
        level: None,
        ..Default::default()
    };
    let title = match first {
        Some(i) => format!(
            "Perceived speed per refresh around a frame skip (refresh {}, frame {} repeated)",
            all[i].index, all[i].frame
        ),
        None => "Perceived speed per refresh (no frame skip in this run)".to_string(),
    };
    line_plot(
        &out.with_extension(""),
        &LinePlot {
            title,
            x_label: "displayed refresh".into(),
            y_label: "camera distance moved per refresh / refresh period (m/s)".into(),
            series: vec![
                series("recorded path (one pose per frame drawn)", |r| r.recorded),
                series("time-based animation (catches up after a skip)", |r| r.time_based),
            ],
            log_x: false,
            log_y: false,
            ..Default::default()
        },
    )?;
    Ok(Figure6 {
        first_skip: first.map(|i| all[i].index),
        range: (
            window.first().map_or(0, |r| r.index),
            window.last().map_or(0, |r| r.index),
        ),
        skips,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_shown_two_refreshes_late_repeats_the_one_before() {
        let columns: Vec<String> = ["ShownAtRefresh", "MovedM"].iter().map(|s| s.to_string()).collect();
        // Frames 0-3 move 1 m each; frame 2 takes two refreshes.
        let rows = vec![vec![1.0, 0.0], vec![2.0, 1.0], vec![4.0, 1.0], vec![5.0, 1.0]];
        let r = refreshes(&columns, &rows, 0.5).unwrap();
        let frames: Vec<u64> = r.iter().map(|x| x.frame).collect();
        assert_eq!(frames, vec![0, 1, 1, 2, 3]);
        let rec: Vec<f64> = r.iter().map(|x| x.recorded).collect();
        assert_eq!(rec, vec![0.0, 2.0, 0.0, 2.0, 2.0]);
        let tb: Vec<f64> = r.iter().map(|x| x.time_based).collect();
        assert_eq!(tb, vec![0.0, 2.0, 0.0, 4.0, 2.0]);
    }
}
