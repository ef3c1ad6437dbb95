//! The frame-to-frame selection (paper 001, slide "Inkrementelle Lösung"
//! after the greedy): start from the previous frame's selection; while it
//! is within the frame time, change the one object tuple whose change
//! improves the most and still fits; "analogously" when it is over.
//!
//! The slide measures a change by the difference of the two tuples' values
//! (benefit / cost). That reading is not usable as written: "not drawn" has
//! no value (0/0), and a change to a cheaper level of higher value can lose
//! benefit. This module measures a change by its marginal value, the
//! benefit it adds per cost it adds (the multiple-choice knapsack's
//! incremental efficiency, which is what Funkhouser & Séquin's incremental
//! upgrades and downgrades compare). The rule, exactly:
//!
//! 1. Levels with zero benefit in the previous selection are dropped (not
//!    drawn): they add nothing.
//! 2. **Repair**: while the total cost is over the budget, apply the
//!    downgrade (a move of one object to a cheaper level, or to not drawn)
//!    that loses the least benefit per picosecond saved; ties: the larger
//!    saving, then the lower object index, then not drawn before a level,
//!    then the lower level index.
//! 3. **Improve**: while some upgrade (a move of one object to a level of
//!    higher benefit) keeps the total within budget, apply the one with the
//!    highest benefit added per picosecond added (a move that also saves
//!    cost counts as +infinity); ties: the larger benefit added, then the
//!    lower object index, then the lower level index. At most
//!    `max_upgrades` moves when given (a per-frame limit).
//!
//! Repair ends within budget (not drawing anything costs nothing); improve
//! strictly raises the total benefit with every move, so both end. Zero-
//! benefit levels are never a move's target. From an all-undrawn start the
//! result is a greedy by marginal value, which can differ from the
//! lecture's [`super::greedy`] (that one takes whole tuples by value and
//! never upgrades).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use super::{Instance, LodSelectError, Selection};

/// A candidate move of one object from level `from` to level `to`.
#[derive(Debug, Clone, Copy)]
struct Move {
    /// The ranking key, larger first (the negated loss rate for repairs).
    key: f64,
    /// Second key, larger first (saving for repairs, benefit added for upgrades).
    key2: f64,
    object: u32,
    from: Option<u32>,
    to: Option<u32>,
    /// Cost change in picoseconds.
    dc: i128,
}

impl PartialEq for Move {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Move {}
impl PartialOrd for Move {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Move {
    /// Greater = applied first (BinaryHeap is a max-heap).
    fn cmp(&self, o: &Self) -> Ordering {
        // None (not drawn) sorts before any level: map to -1.
        let lvl = |l: Option<u32>| l.map_or(-1i64, i64::from);
        self.key
            .total_cmp(&o.key)
            .then(self.key2.total_cmp(&o.key2))
            .then(o.object.cmp(&self.object))
            .then(lvl(o.to).cmp(&lvl(self.to)))
    }
}

fn level_of(inst: &Instance, o: usize, l: Option<u32>) -> (i128, f64) {
    match l {
        Some(l) => {
            let x = &inst.objects()[o].levels[l as usize];
            (x.cost.0 as i128, x.benefit)
        }
        None => (0, 0.0),
    }
}

/// Targets of object `o`: not drawn, and every level with positive benefit.
fn targets(inst: &Instance, o: usize) -> impl Iterator<Item = Option<u32>> + '_ {
    std::iter::once(None).chain(
        inst.objects()[o]
            .levels
            .iter()
            .enumerate()
            .filter(|(_, l)| l.benefit > 0.0)
            .map(|(i, _)| Some(i as u32)),
    )
}

fn push_repairs(inst: &Instance, o: usize, cur: Option<u32>, heap: &mut BinaryHeap<Move>) {
    let (c0, b0) = level_of(inst, o, cur);
    for to in targets(inst, o) {
        let (c1, b1) = level_of(inst, o, to);
        if c1 < c0 {
            let saving = (c0 - c1) as f64;
            let loss = b0 - b1;
            heap.push(Move {
                key: -(loss / saving),
                key2: saving,
                object: o as u32,
                from: cur,
                to,
                dc: c1 - c0,
            });
        }
    }
}

fn push_upgrades(inst: &Instance, o: usize, cur: Option<u32>, heap: &mut BinaryHeap<Move>) {
    let (c0, b0) = level_of(inst, o, cur);
    for to in targets(inst, o) {
        let (c1, b1) = level_of(inst, o, to);
        if b1 > b0 {
            let dc = c1 - c0;
            let gain = b1 - b0;
            heap.push(Move {
                key: if dc <= 0 { f64::INFINITY } else { gain / dc as f64 },
                key2: gain,
                object: o as u32,
                from: cur,
                to,
                dc,
            });
        }
    }
}

/// The incremental selection of `inst` from `previous` (one entry per
/// object), with at most `max_upgrades` improving moves when given.
pub fn incremental(
    inst: &Instance,
    previous: &[Option<u32>],
    max_upgrades: Option<usize>,
) -> Result<Selection, LodSelectError> {
    inst.check_selection(previous)?;
    let n = inst.objects().len();
    let budget = inst.budget().0 as i128;
    let mut cur: Vec<Option<u32>> = previous
        .iter()
        .enumerate()
        .map(|(o, &l)| if level_of(inst, o, l).1 > 0.0 { l } else { None })
        .collect();
    let mut total: i128 = (0..n).map(|o| level_of(inst, o, cur[o]).0).sum();

    // Repair.
    if total > budget {
        let mut heap = BinaryHeap::new();
        for (o, &l) in cur.iter().enumerate() {
            push_repairs(inst, o, l, &mut heap);
        }
        while total > budget {
            let Some(m) = heap.pop() else { break };
            let o = m.object as usize;
            if cur[o] != m.from {
                continue;
            }
            cur[o] = m.to;
            total += m.dc;
            push_repairs(inst, o, m.to, &mut heap);
        }
    }

    // Improve.
    let mut heap = BinaryHeap::new();
    for (o, &l) in cur.iter().enumerate() {
        push_upgrades(inst, o, l, &mut heap);
    }
    // Moves that did not fit: tried again when a move frees budget.
    let mut parked: Vec<Move> = Vec::new();
    let mut moves = 0usize;
    while max_upgrades.is_none_or(|m| moves < m) {
        let Some(m) = heap.pop() else { break };
        let o = m.object as usize;
        if cur[o] != m.from {
            continue;
        }
        if total + m.dc > budget {
            parked.push(m);
            continue;
        }
        cur[o] = m.to;
        total += m.dc;
        moves += 1;
        push_upgrades(inst, o, m.to, &mut heap);
        if m.dc < 0 {
            heap.extend(parked.drain(..).filter(|p| cur[p.object as usize] == p.from));
        }
    }
    Ok(Selection::evaluate(inst, cur))
}
