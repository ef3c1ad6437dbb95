//! Migration artifacts (paper 003 §4, Figure 5, Table 3): one object that
//! the user hovers over, selects, drags and releases, following an
//! interaction script. For every FC frame: the object's state on FC
//! (INACTIVE / OVER / SELECTED) and whether the SC image FC composites
//! contains it; whether FC draws it; and whether the frame shows it twice
//! (selection artifact: FC draws it, SC's image still holds it, and it has
//! moved between the two) or not at all (release artifact).
//!
//! Each client sees the script as of its newest delivered tracker sample
//! (master events travel with the sensor data). Two policies:
//! - `plain` (the original system): SC renders the object unless it is
//!   SELECTED; FC draws it only while SELECTED;
//! - `bookkeeping` (the paper's scheme): over-prediction (SC drops the
//!   object already when OVER) and Table 3 — SC reports which objects its
//!   image holds, and FC draws the object unless it is INACTIVE and held.
//!
//! Readings: Figure 5's edges are Intersect (INACTIVE -> OVER), Select
//! (OVER -> SELECTED), Release (SELECTED -> OVER), No Intersect (OVER ->
//! INACTIVE). Table 3's text and columns disagree on which of rows 5 and 6
//! is OVER and which SELECTED; both rows say "draw (possibly as a shadow
//! object)", so the rule does not depend on the choice.

use serde::{Deserialize, Serialize};

use crate::engine::{Duration, Time};

use super::model::FcFrame;

/// A user action.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Action {
    /// The selection ray starts intersecting the object (-> OVER).
    Hover,
    /// The user selects it (-> SELECTED).
    Select,
    /// The user starts moving it (it moves until `release`).
    Drag,
    /// The user releases it (-> OVER).
    Release,
    /// The ray leaves the object (-> INACTIVE).
    Leave,
}

/// One scripted action.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Step {
    /// When, from the start of the run.
    pub at: Duration,
    /// What.
    pub action: Action,
}

/// The object's state on a client.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum State {
    /// Not touched.
    Inactive,
    /// The ray intersects it.
    Over,
    /// Selected (possibly being dragged).
    Selected,
}

/// The script's state at `t`.
pub fn state_at(script: &[Step], t: Time) -> State {
    let mut s = State::Inactive;
    for step in script.iter().filter(|s| s.at.0 <= t.0) {
        s = match step.action {
            Action::Hover | Action::Release => State::Over,
            Action::Select | Action::Drag => State::Selected,
            Action::Leave => State::Inactive,
        };
    }
    s
}

/// Whether the object moved at some time in `[a, b]` (either order).
fn moved_between(script: &[Step], a: Time, b: Time) -> bool {
    let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
    let mut drag_start: Option<u64> = None;
    for s in script {
        match s.action {
            Action::Drag => drag_start = Some(s.at.0),
            Action::Release | Action::Leave => {
                if let Some(d) = drag_start.take()
                    && d < hi.0
                    && s.at.0 > lo.0
                {
                    return true;
                }
            }
            _ => {}
        }
    }
    drag_start.is_some_and(|d| d < hi.0)
}

/// Artifact counts for one policy.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Counts {
    /// FC frames showing the object twice.
    pub doubled_frames: u64,
    /// FC frames showing it not at all.
    pub missing_frames: u64,
}

/// Counts artifacts over the FC frames that end during the script (from its
/// first action to one second after its last), frame by frame as they end.
#[derive(Debug, Clone)]
pub struct Artifacts {
    script: Vec<Step>,
    first: u64,
    last: u64,
    frames: u64,
    plain: Counts,
    book: Counts,
}

/// What [`Artifacts`] found, as the summary's `metrics.migration`.
#[derive(Debug, Clone, Serialize)]
pub struct ArtifactCounts {
    /// FC frames that ended during the script and composited an SC image.
    pub fc_frames: u64,
    /// The original system.
    pub plain: Counts,
    /// The paper's bookkeeping scheme.
    pub bookkeeping: Counts,
}

impl Artifacts {
    /// Counting for `script`.
    pub fn new(script: &[Step]) -> Self {
        Artifacts {
            first: script.iter().map(|s| s.at.0).min().unwrap_or(0),
            last: script
                .iter()
                .map(|s| s.at.0)
                .max()
                .unwrap_or(0)
                .saturating_add(1_000_000_000_000),
            script: script.to_vec(),
            frames: 0,
            plain: Counts::default(),
            book: Counts::default(),
        }
    }

    /// An FC frame ended (`tracker_period` in picoseconds dates the samples).
    pub fn fc_frame_end(&mut self, f: &FcFrame, tracker_period: u64) {
        if f.end.0 < self.first || f.end.0 > self.last {
            return;
        }
        let p = tracker_period.max(1);
        let state_time = |sample: Option<u64>| sample.map(|k| Time(k.saturating_mul(p)));
        let (Some(fc_t), Some((_, sc))) = (state_time(f.sample), f.buffer) else {
            return;
        };
        let Some(sc_t) = state_time(sc.sample) else { return };
        let script = &self.script;
        self.frames += 1;
        let fc_state = state_at(script, fc_t);
        let sc_state = state_at(script, sc_t);
        let moved = moved_between(script, sc_t, fc_t);
        // plain: SC holds it unless SELECTED; FC draws it only when SELECTED.
        let held = sc_state != State::Selected;
        let draws = fc_state == State::Selected;
        count(&mut self.plain, draws, held, moved);
        // bookkeeping: SC drops it when OVER already; FC follows Table 3.
        let held = sc_state == State::Inactive;
        let draws = !(fc_state == State::Inactive && held);
        count(&mut self.book, draws, held, moved);
    }

    /// The counts so far.
    pub fn counts(&self) -> ArtifactCounts {
        ArtifactCounts {
            fc_frames: self.frames,
            plain: self.plain,
            bookkeeping: self.book,
        }
    }
}

fn count(c: &mut Counts, draws: bool, held: bool, moved: bool) {
    if draws && held && moved {
        c.doubled_frames += 1;
    }
    if !draws && !held {
        c.missing_frames += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(ms: u64, action: Action) -> Step {
        Step {
            at: Duration::ms(ms),
            action,
        }
    }

    #[test]
    fn figure5_states() {
        let script = [
            s(10, Action::Hover),
            s(20, Action::Select),
            s(30, Action::Release),
            s(40, Action::Leave),
        ];
        let at = |ms: u64| state_at(&script, Time(Duration::ms(ms).0));
        assert_eq!(at(5), State::Inactive);
        assert_eq!(at(15), State::Over);
        assert_eq!(at(25), State::Selected);
        assert_eq!(at(35), State::Over);
        assert_eq!(at(45), State::Inactive);
    }

    #[test]
    fn movement_only_while_dragging() {
        let script = [s(10, Action::Select), s(20, Action::Drag), s(30, Action::Release)];
        let t = |ms: u64| Time(Duration::ms(ms).0);
        assert!(!moved_between(&script, t(5), t(19)));
        assert!(moved_between(&script, t(15), t(25)));
        assert!(moved_between(&script, t(25), t(26)));
        assert!(!moved_between(&script, t(31), t(40)));
        assert!(moved_between(&script, t(40), t(15)));
    }
}
