//! Paper 000 §6.4's conditional branch, inside the frame's GPU work.
//!
//! The paper: a start token carries numbers tr_1..tr_n, one per level of
//! an object (the designated level first, then coarser ones), each the
//! estimated rendering time of every object still to come in the frame
//! with this object at that level; when the GPU reaches the token it
//! compares each tr_i with the time left until the next vertical retrace
//! and executes the branch of the first tr_i smaller than that time,
//! skipping the others.
//!
//! Here: the frame's switchable objects are drawn last (after the others,
//! in scene order), nearest first. When the GPU reaches an object's token
//! is found by simulating the frame up to that token: the frame pipeline
//! runs the draws before it (with the frame's own seed and start, so the
//! CPU, FIFO, GPU and system-task noise are those of the whole frame up to
//! there, and the branches already taken are in it), and the token is
//! reached when the GPU has done all of their work (that run's last GPU
//! work, less the swap it ends with). The time left is the refresh period
//! less that (every frame starts at a vertical blank, `run.rs`); tr_i is
//! the estimator's cost of the object at level i plus the estimated costs
//! of the draws after it at their current levels plus the GPU's swap. When
//! no tr_i is smaller, the coarsest alternative runs (the paper leaves this
//! case open; drawing something is our choice). The frame is then drawn
//! once more with the levels the branches chose, and that run is its time.
//!
//! What this does not model: a GPU front end that reads the token before
//! the work ahead of it has drained (the paper's "end of pipeline" time
//! stamp is assumed), and the driver's CPU work for the skipped branches
//! (the paper's note that branches should hold only GPU-resident geometry;
//! the CPU cost here is that of the executed branch).

use crate::systems::error::SystemError;

use super::config::LodConfig;
use super::render::Draw;

/// One switchable object: its position in the draw list and its
/// alternatives `(level, estimated cost ps)`, the designated level first,
/// then coarser levels each cheaper than the one before.
#[derive(Debug, Clone, PartialEq)]
pub struct Switchable {
    /// Index into the frame's draws.
    pub draw: usize,
    /// Alternatives, the designated level first.
    pub alternatives: Vec<(u32, f64)>,
}

/// A candidate for a branch token: its estimated cost at the chosen level
/// (ps), its index among the visible objects, its alternatives.
type Candidate = (f64, usize, Vec<(u32, f64)>);

/// Marks a frame's switchable objects and moves them to the end of the
/// draw order. `order` holds the indices of the objects to draw (scene
/// order); `level(vi)` is an object's chosen level, `levels(vi)` its
/// number of levels, `dist(vi)` its distance from the eye (m), and
/// `cost(vi, l)` its estimated cost at level `l` (ps). An object at least
/// `lod.branch_min_distance` away with a coarser level is a candidate; its
/// alternatives are its chosen level and up to `lod.branch_levels` coarser
/// levels, each cheaper than the one before. The `lod.branch_objects`
/// costliest candidates are marked and drawn last, nearest first.
pub fn mark_switchable(
    order: &mut Vec<usize>,
    lod: &LodConfig,
    level: impl Fn(usize) -> usize,
    levels: impl Fn(usize) -> usize,
    dist: impl Fn(usize) -> f64,
    mut cost: impl FnMut(usize, usize) -> f64,
) -> Vec<Switchable> {
    let mut cands: Vec<Candidate> = Vec::new();
    for &vi in order.iter() {
        let l = level(vi);
        let n = levels(vi);
        if dist(vi) < lod.branch_min_distance || l + 1 >= n {
            continue;
        }
        let c0 = cost(vi, l);
        let mut alts = vec![(l as u32, c0)];
        let mut last = c0;
        for m in l + 1..n {
            if alts.len() > lod.branch_levels as usize {
                break;
            }
            let cm = cost(vi, m);
            if cm < last {
                alts.push((m as u32, cm));
                last = cm;
            }
        }
        if alts.len() > 1 {
            cands.push((c0, vi, alts));
        }
    }
    cands.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    cands.truncate(lod.branch_objects as usize);
    cands.sort_by(|a, b| dist(a.1).total_cmp(&dist(b.1)).then(a.1.cmp(&b.1)));
    let marked: Vec<usize> = cands.iter().map(|c| c.1).collect();
    order.retain(|vi| !marked.contains(vi));
    let first = order.len();
    let mut switchable = Vec::with_capacity(cands.len());
    for (k, (_, vi, alts)) in cands.into_iter().enumerate() {
        order.push(vi);
        switchable.push(Switchable {
            draw: first + k,
            alternatives: alts,
        });
    }
    switchable
}

/// What the branches of one frame did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BranchStats {
    /// Branch tokens in the frame (switchable objects).
    pub tokens: u32,
    /// Objects switched to a coarser level.
    pub switched: u32,
    /// Prefix runs simulated to find when the GPU reached the tokens.
    pub prefix_runs: u32,
}

/// Evaluates the branches of one frame in draw order. `cost` holds each
/// draw's estimated cost (ps) at its current level and is updated with the
/// branches taken; `deadline` is the time from the frame's start to the
/// next vertical blank, `tail` the estimated GPU work after the last draw
/// (ps); `reached(prefix)` is the time (ps from the frame's start) at which
/// the GPU has done the work of `prefix`.
pub fn evaluate(
    draws: &mut [Draw],
    switchable: &[Switchable],
    cost: &mut [f64],
    deadline: f64,
    tail: f64,
    mut reached: impl FnMut(&[Draw]) -> Result<f64, SystemError>,
) -> Result<BranchStats, SystemError> {
    let mut stats = BranchStats {
        tokens: switchable.len() as u32,
        ..BranchStats::default()
    };
    for s in switchable {
        let Some(&(designated, _)) = s.alternatives.first() else {
            continue;
        };
        let t = reached(&draws[..s.draw])?;
        stats.prefix_runs += 1;
        let left = deadline - t;
        let rest: f64 = cost[s.draw + 1..].iter().sum::<f64>() + tail;
        let pick = s
            .alternatives
            .iter()
            .find(|(_, c)| c + rest < left)
            .or(s.alternatives.last())
            .copied()
            .unwrap_or((designated, cost[s.draw]));
        if pick.0 != draws[s.draw].level {
            draws[s.draw].level = pick.0;
            cost[s.draw] = pick.1;
            stats.switched += 1;
        }
    }
    Ok(stats)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn draw(level: u32) -> Draw {
        Draw {
            proto: 0,
            level,
            pixels: 100.0,
            state: (0, 0, 0),
        }
    }

    /// A GPU that takes exactly each draw's cost at its level: the token
    /// is reached after the sum of the draws before it.
    #[test]
    fn switches_exactly_when_the_rest_would_miss_the_vblank() {
        let level_cost = [4.0, 2.0, 1.0];
        let truth =
            |d: &[Draw]| -> Result<f64, SystemError> { Ok(d.iter().map(|d| level_cost[d.level as usize] * 1.5).sum()) };
        // Three objects at level 0, estimated 4 each, actually 6 each.
        let mut draws = vec![draw(0), draw(0), draw(0)];
        let mut cost = vec![4.0; 3];
        let alts: Vec<(u32, f64)> = vec![(0, 4.0), (1, 2.0), (2, 1.0)];
        let sw: Vec<Switchable> = (1..3)
            .map(|i| Switchable {
                draw: i,
                alternatives: alts.clone(),
            })
            .collect();
        // Deadline 15: at object 1 the GPU is at 6, left 9; tr_0 = 4 + 4 = 8 < 9: keep.
        // At object 2 it is at 12, left 3: tr_0 = 4 no; tr_1 = 2 < 3: level 1.
        let st = evaluate(&mut draws, &sw, &mut cost, 15.0, 0.0, truth).unwrap();
        assert_eq!(
            st,
            BranchStats {
                tokens: 2,
                switched: 1,
                prefix_runs: 2
            }
        );
        assert_eq!(draws.iter().map(|d| d.level).collect::<Vec<_>>(), vec![0, 0, 1]);
        assert_eq!(cost, vec![4.0, 4.0, 2.0]);
        // A generous deadline switches nothing.
        let mut draws = vec![draw(0), draw(0), draw(0)];
        let mut cost = vec![4.0; 3];
        let st = evaluate(&mut draws, &sw, &mut cost, 100.0, 0.0, truth).unwrap();
        assert_eq!(st.switched, 0);
        // No time at all: the coarsest alternative everywhere.
        let mut draws = vec![draw(0), draw(0), draw(0)];
        let mut cost = vec![4.0; 3];
        evaluate(&mut draws, &sw, &mut cost, 0.0, 0.0, truth).unwrap();
        assert_eq!(draws.iter().map(|d| d.level).collect::<Vec<_>>(), vec![0, 2, 2]);
    }
}
