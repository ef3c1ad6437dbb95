//! The display a capture was taken on, inferred from the whole capture
//! (issue 54, item 2): the panel's refresh period and phase, how many
//! monitors the compositor drove, whether the replayed swap chain's flips
//! sit on that refresh grid, follow a variable refresh, or tear.
//!
//! The evidence is where frames reached the screen (present plus
//! `MsUntilDisplayed`) and which path took them there:
//!
//! - the desktop compositor's own presents (`dwm.exe`, one swap chain per
//!   monitor) flip at vertical blanks, so they are the best grid;
//! - a composed frame (`Composed: Flip`, `Composed: Copy with GPU GDI`)
//!   reaches the screen with a composition, also at a vertical blank;
//! - a hardware flip at sync interval 1 or more waits for one too;
//! - a hardware flip at sync interval 0 that may not tear is shown at a
//!   vertical blank of a fixed refresh, or, on a variable-refresh panel,
//!   when it is ready: off the grid the others give, it can only be the
//!   latter;
//! - a flip that may tear is shown when the GPU is done, on no grid.
//!
//! An application's own frames cannot tell the panel's rate when it shows
//! a frame every few refreshes: a game capped at 30 fps on a 120 Hz panel
//! changes the display every 33.3 ms, which fits 30 Hz as well as 120 Hz.
//! Display changes pooled across every swap chain, and the compositor's
//! presents, can: the period is the longest one that every display change
//! is a whole number of ([`fit_grid`]: a shorter period that explains
//! more changes than chance would must be taken instead). Where even the
//! pooled changes leave the rate below any panel's
//! ([`MIN_PANEL_HZ`]), the panel's rate is taken as the slowest whole
//! multiple at or above it that puts every display change at a vertical
//! blank on its grid (a few composed frames three refreshes apart tell 120
//! Hz from 60), and the inference says it was ambiguous.

use serde::Serialize;

mod compositor;
mod grid;

pub use self::compositor::{CompositorInference, infer_compositor};
use self::grid::intervals;
pub use self::grid::{Grid, fit_grid, tolerance};
use super::presentmon::{Capture, Present};
use rendersim_report::stats::quantile::quantile;

/// The slowest refresh taken as a panel's own (Hz): a grid slower than
/// this is read as a panel refreshing a whole number of times faster,
/// of which the capture saw every few refreshes.
pub const MIN_PANEL_HZ: f64 = 48.0;

/// The share of display changes on a grid for the grid to count.
const ON_GRID: f64 = 0.8;
/// The lower limit of a variable-refresh window, which a capture cannot
/// show (below it a driver repeats frames, and a repeat is no display
/// change): the common floor of adaptive-sync panels' ranges.
pub const ASSUMED_VRR_MIN_HZ: f64 = 48.0;

/// How a present reaches the screen, as far as its timing goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Path {
    /// The compositor's own present (`dwm.exe`): flipped at a vertical blank.
    Compositor,
    /// Composed by the compositor (`Composed: ...`): shown at a vertical blank.
    Composed,
    /// A hardware flip at sync interval 1 or more: at a vertical blank.
    FlipSynced,
    /// A hardware flip at sync interval 0 that may not tear: at a vertical
    /// blank, or when ready on a variable-refresh panel.
    FlipUnsynced,
    /// A hardware flip at sync interval 0 that may tear: when ready.
    FlipTearing,
    /// A present mode PresentMon could not tell (`Other`, `Unknown`).
    Unknown,
}

impl Path {
    /// The path of one present.
    pub fn of(p: &Present) -> Path {
        let mode: &str = &p.present_mode;
        let hardware = mode.starts_with("Hardware");
        let tearing = hardware && p.sync_interval == Some(0) && p.allows_tearing;
        if p.application.eq_ignore_ascii_case("dwm.exe") && !tearing {
            Path::Compositor
        } else if mode.starts_with("Composed") {
            Path::Composed
        } else if !hardware {
            Path::Unknown
        } else if p.sync_interval.unwrap_or(1) != 0 {
            Path::FlipSynced
        } else if p.allows_tearing {
            Path::FlipTearing
        } else {
            Path::FlipUnsynced
        }
    }

    /// Whether frames on this path reach the screen at a vertical blank
    /// whatever the panel.
    fn on_blanks(self) -> bool {
        matches!(self, Path::Compositor | Path::Composed | Path::FlipSynced)
    }
}

/// Where the refresh was inferred from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RefreshEvidence {
    /// The compositor's presents on the replayed swap chain's monitor
    /// (with the display changes of the swap chains on its grid).
    Compositor,
    /// Display changes at vertical blanks, pooled across the capture's
    /// swap chains (composed frames, synced flips).
    DisplayChanges,
    /// The replayed swap chain's own flips at sync interval 0 (a fixed
    /// refresh, as nothing else in the capture says otherwise).
    UnsyncedFlips,
}

/// The refresh inferred.
#[derive(Debug, Clone, Serialize)]
pub struct RefreshInference {
    /// The panel's refresh rate, Hz.
    pub hz: f64,
    /// Its period and a vertical blank on the capture's clock.
    pub grid: Grid,
    /// What it was inferred from.
    pub from: RefreshEvidence,
    /// Swap chains whose display changes were pooled (`application
    /// address`).
    pub chains: Vec<String>,
    /// When the evidence fits no rate at or above [`MIN_PANEL_HZ`]: the
    /// slowest rate it fits, Hz (the panel's was taken as its slowest whole
    /// multiple at or above the floor; it may be any other multiple).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ambiguous_below_hz: Option<f64>,
    /// When the swap chain's flips on a variable-refresh panel changed the
    /// display faster than the grid allows: the rate the grid gave, Hz
    /// (a panel's fastest refresh is at least as fast as any display
    /// change it made, so the refresh is the grid's slowest whole multiple
    /// that allows them).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub raised_from_hz: Option<f64>,
}

/// How the replayed swap chain's flips reach the screen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Flips {
    /// At vertical blanks of the inferred refresh.
    OnGrid,
    /// When ready, on no grid, never tearing: a variable-refresh panel.
    VariableRefresh,
    /// When ready, tearing (the present allows it).
    Tearing,
    /// No refresh could be inferred to tell.
    Unknown,
}

/// A variable-refresh window inferred.
#[derive(Debug, Clone, Serialize)]
pub struct VrrInference {
    /// The slowest refresh, Hz: [`ASSUMED_VRR_MIN_HZ`] (a capture cannot
    /// show it), or less than that where the fastest is close to it.
    pub min_hz: f64,
    /// The fastest refresh, Hz: the panel's inferred refresh, or, without
    /// one, the fastest rate of the swap chain's display changes.
    pub max_hz: f64,
    /// Whether `max_hz` is the panel's refresh (`true`) or only the
    /// fastest the swap chain reached (`false`: the panel may be faster).
    pub max_from_refresh: bool,
}

/// One swap chain as the display saw it.
#[derive(Debug, Clone, Serialize)]
pub struct ChainDisplay {
    /// `application address`.
    pub chain: String,
    /// The path most of its frames took.
    pub path: Path,
    /// Its presents the application rendered.
    pub frames: usize,
    /// Of those, displayed.
    pub displayed: usize,
    /// The share of its display changes on the inferred grid.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub on_grid: Option<f64>,
}

/// The display inferred from a whole capture, for one swap chain.
#[derive(Debug, Clone, Serialize)]
pub struct DisplayInference {
    /// The panel's refresh (`None`: nothing in the capture lies on a grid).
    pub refresh: Option<RefreshInference>,
    /// Monitors the compositor drove (its swap chains on distinct grids).
    pub monitors: usize,
    /// How the replayed swap chain's flips reached the screen.
    pub flips: Flips,
    /// The variable-refresh window, when `flips` is `variable_refresh`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vrr: Option<VrrInference>,
    /// Every swap chain of the capture, most frames first.
    pub chains: Vec<ChainDisplay>,
    /// The compositor's timing, inferred from the replayed swap chain's
    /// composed frames (`None` for a hardware flip, or too few frames).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compositor: Option<CompositorInference>,
}

impl DisplayInference {
    /// One line a person reads: the refresh and what it came from, the
    /// monitors, and how the swap chain's flips reached the screen.
    pub fn describe(&self) -> String {
        let refresh = match &self.refresh {
            None => "no refresh: nothing in the capture lies on a refresh grid".to_string(),
            Some(r) => {
                let from = match r.from {
                    RefreshEvidence::Compositor => "the compositor's presents",
                    RefreshEvidence::DisplayChanges => "display changes at vertical blanks",
                    RefreshEvidence::UnsyncedFlips => "the swap chain's unsynced flips",
                };
                let mut t = format!("{:.3} Hz from {from} ({})", r.hz, r.chains.join(", "));
                if let Some(a) = r.ambiguous_below_hz {
                    let floor = (MIN_PANEL_HZ / a).ceil();
                    if (r.hz / a).round() > floor {
                        t += &format!(
                            "; ambiguous: the capture fits {a:.2} Hz, the multiple of it that its display changes at vertical blanks fit taken"
                        );
                    } else {
                        t += &format!(
                            "; ambiguous: the capture fits {a:.2} Hz, the slowest multiple of at least {MIN_PANEL_HZ} Hz taken"
                        );
                    }
                }
                if let Some(f) = r.raised_from_hz {
                    t += &format!("; raised from {f:.2} Hz by flips faster than it");
                }
                t
            }
        };
        let flips = match (self.flips, &self.vrr) {
            (Flips::VariableRefresh, Some(v)) => format!(
                "a variable refresh, {:.0}-{:.0} Hz ({} the slowest assumed)",
                v.min_hz,
                v.max_hz,
                if v.max_from_refresh {
                    "the fastest the panel's,"
                } else {
                    "the fastest as fast as its flips,"
                }
            ),
            (Flips::OnGrid, _) => "on the refresh grid".to_string(),
            (Flips::Tearing, _) => "when ready, tearing".to_string(),
            (Flips::VariableRefresh, None) | (Flips::Unknown, _) => "unknown".to_string(),
        };
        let monitors = match self.monitors {
            0 => String::new(),
            1 => "; 1 monitor".to_string(),
            n => format!("; {n} monitors"),
        };
        let compositor = self
            .compositor
            .as_ref()
            .map_or(String::new(), |c| format!("; {}", c.describe()));
        format!("{refresh}{monitors}; flips {flips}{compositor}")
    }
}

/// A swap chain's identity within a capture.
type Key<'a> = (&'a str, &'a str, &'a str);

fn label(k: Key<'_>) -> String {
    format!("{} {}", k.0, k.2)
}

/// The capture's swap chains, in order of first appearance, each with its
/// rows: the frames the application rendered and those it did not
/// (generated frames are frames of the display too).
struct Chains<'a> {
    keys: Vec<Key<'a>>,
    rows: Vec<Vec<&'a Present>>,
}

impl<'a> Chains<'a> {
    fn of(capture: &'a Capture) -> Chains<'a> {
        let mut keys: Vec<Key<'a>> = Vec::new();
        let mut rows: Vec<Vec<&'a Present>> = Vec::new();
        let mut index: std::collections::HashMap<Key<'a>, usize> = std::collections::HashMap::new();
        for p in capture.presents.iter().chain(&capture.generated) {
            let i = *index.entry(p.chain()).or_insert_with(|| {
                keys.push(p.chain());
                rows.push(Vec::new());
                keys.len() - 1
            });
            rows[i].push(p);
        }
        Chains { keys, rows }
    }

    /// The sorted screen times of chain `i`'s frames on the paths `f` takes.
    fn screen(&self, i: usize, f: &dyn Fn(Path) -> bool) -> Vec<f64> {
        let mut v: Vec<f64> = self.rows[i]
            .iter()
            .filter(|p| f(Path::of(p)))
            .filter_map(|p| p.screen_time())
            .filter(|t| t.is_finite())
            .collect();
        v.sort_by(f64::total_cmp);
        v
    }

    fn label(&self, i: usize) -> String {
        label(self.keys[i])
    }
}

/// The fastest panel rate taken: beyond it a finer grid fits too much by
/// chance to be evidence.
pub const MAX_PANEL_HZ: f64 = 360.0;

/// Refresh rates panels are sold with (Hz): a finer grid is taken only at
/// one of them (within 1%), so that a stray interval a grid fits by chance
/// does not make a 150 Hz or 210 Hz panel.
pub const PANEL_RATES_HZ: [f64; 16] = [
    50.0, 60.0, 75.0, 85.0, 90.0, 100.0, 120.0, 144.0, 165.0, 170.0, 180.0, 200.0, 240.0, 280.0, 300.0, 360.0,
];

/// The intervals between display changes at vertical blanks (the
/// compositor's presents, composed frames, synced flips), per swap chain.
fn blank_intervals(chains: &Chains<'_>) -> Vec<f64> {
    (0..chains.keys.len())
        .flat_map(|i| intervals(&chains.screen(i, &Path::on_blanks)))
        .collect()
}

/// How many refreshes of the panel a grid of `period_ms` (slower than
/// [`MIN_PANEL_HZ`]) spans. A game capped at 30 fps on a 120 Hz panel
/// changes the display every 33.3 ms, which 60 Hz fits too; a few composed
/// frames 25 ms apart (three refreshes) can only be 120 Hz. So: the
/// slowest multiple at or above the floor, unless a finer one at a panel's
/// rate ([`PANEL_RATES_HZ`]) puts more of the display changes at vertical blanks
/// (`blank`, within [`tolerance`]) than chance would: more than its share
/// of the misfits left (twice the tolerance over the period) plus half a
/// change.
fn panel_multiple(period_ms: f64, blank: &[f64]) -> f64 {
    let floor = (MIN_PANEL_HZ * period_ms / 1000.0).ceil().max(1.0);
    let misfits = |p: f64| {
        blank
            .iter()
            .filter(|d| (*d - (*d / p).round() * p).abs() > tolerance(p))
            .count() as f64
    };
    let (mut best, mut best_misfits) = (floor, misfits(period_ms / floor));
    let mut k = floor + 1.0;
    while 1000.0 * k / period_ms <= MAX_PANEL_HZ && best_misfits > 0.0 {
        let p = period_ms / k;
        let hz = 1000.0 / p;
        let sold = PANEL_RATES_HZ.iter().any(|r| (hz / r - 1.0).abs() <= 0.01);
        let m = misfits(p);
        if sold && best_misfits - m > best_misfits * 2.0 * tolerance(p) / p + 0.5 {
            (best, best_misfits) = (k, m);
        }
        k += 1.0;
    }
    best
}

/// Whether a grid holds enough of the changes it was fitted to to count.
fn is_grid(g: &Grid) -> bool {
    g.on_grid as f64 >= ON_GRID * g.intervals as f64
}

/// Infers the display of `capture` for the swap chain of `target` (any of
/// its presents names it).
pub fn infer_display(capture: &Capture, target: &Present) -> DisplayInference {
    let chains = Chains::of(capture);
    let ti = chains
        .keys
        .iter()
        .position(|k| *k == target.chain())
        .expect("the target is a present of the capture");
    let monitors = monitor_grids(&chains);
    let mut refresh = refresh_of(&chains, &monitors, ti);
    if let Some(r) = &mut refresh
        && r.hz < MIN_PANEL_HZ
    {
        let k = panel_multiple(r.grid.period_ms, &blank_intervals(&chains));
        r.ambiguous_below_hz = Some(r.hz);
        r.grid.period_ms /= k;
        r.hz = r.grid.hz();
    }
    let (flips, vrr) = flips_of(&chains, ti, &mut refresh);
    let grid = refresh.as_ref().map(|r| r.grid);
    let mut listing: Vec<ChainDisplay> = (0..chains.keys.len())
        .map(|i| {
            let ps = &chains.rows[i];
            ChainDisplay {
                chain: chains.label(i),
                path: dominant_path(ps),
                frames: ps.iter().filter(|p| p.rendered()).count(),
                displayed: ps.iter().filter(|p| p.displayed()).count(),
                on_grid: grid.and_then(|g| g.share(&chains.screen(i, &|_| true))),
            }
        })
        .collect();
    listing.sort_by_key(|c| std::cmp::Reverse(c.frames));
    let compositor = grid
        .filter(|_| dominant_path(&chains.rows[ti]) == Path::Composed)
        .and_then(|g| {
            let own: Vec<&Present> = (0..chains.keys.len())
                .filter(|&i| dominant_path(&chains.rows[i]) == Path::Compositor)
                .flat_map(|i| chains.rows[i].iter().copied())
                .filter(|p| p.screen_time().is_some_and(|t| g.holds(t)))
                .collect();
            infer_compositor(&chains.rows[ti], &g, &own)
        });
    DisplayInference {
        refresh,
        monitors: monitors.len(),
        flips,
        vrr,
        chains: listing,
        compositor,
    }
}

/// One grid per monitor: the compositor's swap chains that show enough,
/// those on one panel's grid together.
fn monitor_grids(chains: &Chains<'_>) -> Vec<(Grid, Vec<usize>)> {
    let mut monitors: Vec<(Grid, Vec<usize>)> = Vec::new();
    for (i, ps) in chains.rows.iter().enumerate() {
        if Path::of(ps[0]) != Path::Compositor {
            continue;
        }
        let Some(g) = fit_grid(&chains.screen(i, &|_| true)).filter(is_grid) else {
            continue;
        };
        match monitors.iter_mut().find(|(m, _)| m.same_panel(&g)) {
            Some((_, members)) => members.push(i),
            None => monitors.push((g, vec![i])),
        }
    }
    monitors
}

/// The refresh of swap chain `ti`'s monitor, from the best evidence there is.
fn refresh_of(chains: &Chains<'_>, monitors: &[(Grid, Vec<usize>)], ti: usize) -> Option<RefreshInference> {
    let inference = |grid: Grid, from, chains| RefreshInference {
        hz: grid.hz(),
        grid,
        from,
        chains,
        ambiguous_below_hz: None,
        raised_from_hz: None,
    };
    let target_blanks = chains.screen(ti, &|p| p.on_blanks());
    if !monitors.is_empty() {
        // The monitor whose grid the target's frames fit best, its
        // compositor's presents pooled with the target's on its grid.
        let all = chains.screen(ti, &|_| true);
        let probe = if target_blanks.is_empty() { &all } else { &target_blanks };
        let (g, members) = monitors
            .iter()
            .max_by(|a, b| {
                let s = |g: &Grid| g.share(probe).unwrap_or(0.0);
                s(&a.0).total_cmp(&s(&b.0))
            })
            .expect("not empty");
        let mut pooled: Vec<f64> = members.iter().flat_map(|&i| chains.screen(i, &|_| true)).collect();
        let mut labels: Vec<String> = members.iter().map(|&i| chains.label(i)).collect();
        let own: Vec<f64> = target_blanks.iter().copied().filter(|&t| g.holds(t)).collect();
        if !own.is_empty() && !members.contains(&ti) {
            pooled.extend(&own);
            labels.push(chains.label(ti));
        }
        if let Some(fine) = fit_grid(&pooled) {
            return Some(inference(fine, RefreshEvidence::Compositor, labels));
        }
    }
    // Every swap chain's display changes at vertical blanks, pooled.
    let mut pooled = Vec::new();
    let mut labels = Vec::new();
    for i in 0..chains.keys.len() {
        let s = chains.screen(i, &|p| p.on_blanks());
        if !s.is_empty() {
            pooled.extend(s);
            labels.push(chains.label(i));
        }
    }
    if let Some(g) = fit_grid(&pooled).filter(is_grid) {
        return Some(inference(g, RefreshEvidence::DisplayChanges, labels));
    }
    // Swap chains on different monitors may not pool: the target's own.
    if let Some(g) = fit_grid(&target_blanks).filter(is_grid) {
        return Some(inference(g, RefreshEvidence::DisplayChanges, vec![chains.label(ti)]));
    }
    let unsynced = chains.screen(ti, &|p| p == Path::FlipUnsynced);
    fit_grid(&unsynced)
        .filter(is_grid)
        .map(|g| inference(g, RefreshEvidence::UnsyncedFlips, vec![chains.label(ti)]))
}

/// How swap chain `ti`'s flips reached the screen, and the variable-refresh
/// window where they followed one (raising the refresh where its flips
/// changed the display faster than the grid allows).
fn flips_of(chains: &Chains<'_>, ti: usize, refresh: &mut Option<RefreshInference>) -> (Flips, Option<VrrInference>) {
    let unsynced = chains.screen(ti, &|p| p == Path::FlipUnsynced);
    match (dominant_path(&chains.rows[ti]), refresh.as_mut()) {
        (Path::FlipTearing, _) => (Flips::Tearing, None),
        (Path::FlipUnsynced, Some(r)) if r.grid.share(&unsynced).unwrap_or(1.0) < ON_GRID => {
            raise_to_fastest_change(r, &unsynced);
            (Flips::VariableRefresh, Some(vrr_window(Some(r.hz), &unsynced)))
        }
        (Path::FlipUnsynced, None) if !unsynced.is_empty() => {
            (Flips::VariableRefresh, Some(vrr_window(None, &unsynced)))
        }
        (_, Some(_)) => (Flips::OnGrid, None),
        (_, None) => (Flips::Unknown, None),
    }
}

/// A variable-refresh panel changes the display no faster than its fastest
/// refresh: a grid slower than the flips' fastest changes (their 2nd
/// percentile interval) was a whole fraction of the panel's rate.
fn raise_to_fastest_change(r: &mut RefreshInference, flips: &[f64]) {
    let mut d = intervals(flips);
    d.sort_by(f64::total_cmp);
    if d.is_empty() {
        return;
    }
    let fastest = quantile(&d, 0.02);
    let p = r.grid.period_ms;
    if fastest < p - tolerance(p) {
        let k = (1..=16)
            .find(|&k| p / k as f64 <= fastest + tolerance(p / k as f64))
            .unwrap_or(16);
        r.raised_from_hz = Some(r.hz);
        r.grid.period_ms = p / k as f64;
        r.hz = r.grid.hz();
    }
}

/// The path most of a swap chain's presents took (ties: the first seen).
fn dominant_path(ps: &[&Present]) -> Path {
    let mut counts: Vec<(Path, usize)> = Vec::new();
    for p in ps {
        let path = Path::of(p);
        match counts.iter_mut().find(|(q, _)| *q == path) {
            Some((_, n)) => *n += 1,
            None => counts.push((path, 1)),
        }
    }
    counts
        .iter()
        .fold(None::<(Path, usize)>, |best, &(p, n)| match best {
            Some((_, m)) if m >= n => best,
            _ => Some((p, n)),
        })
        .map_or(Path::Unknown, |(p, _)| p)
}

/// The window of a variable-refresh panel whose fastest rate is the
/// panel's `refresh_hz` where known, else the fastest the display changes
/// `times` reached (their 2nd percentile interval).
fn vrr_window(refresh_hz: Option<f64>, times: &[f64]) -> VrrInference {
    let (max_hz, max_from_refresh) = match refresh_hz {
        Some(hz) => (hz, true),
        None => {
            let mut d = intervals(times);
            d.sort_by(f64::total_cmp);
            let fastest = if d.is_empty() {
                60.0
            } else {
                1000.0 / quantile(&d, 0.02)
            };
            (fastest, false)
        }
    };
    VrrInference {
        min_hz: ASSUMED_VRR_MIN_HZ.min(max_hz / 2.0),
        max_hz,
        max_from_refresh,
    }
}

#[cfg(test)]
mod tests;
